"""The pressure ramp of a model: the final pressure and how the ramp to it is stepped."""

from __future__ import annotations

from dataclasses import dataclass, field

from pneumorph import checks
from pneumorph.fem import StepSettings
from pneumorph.models.response import FloatArray


@dataclass(frozen=True)
class RampSpec:
    """The pressure ramp and how it is solved.

    Parameters
    ----------
    pressure : float
        Final pressure in MPa (0.045 = 45 kPa).
    steps : StepSettings
        Reported increments (10 by default: 4.5, 9, ..., 45 kPa), substeps, cut-back.
    volume : float, optional
        Volume control: the cavities' relative volume change ``V / V0 - 1`` at the ramp's
        end, reported in equal volume increments, the pressure an output that may pass a
        maximum (:class:`~pneumorph.fem.fast.volume.VolumeControl`, fast backend); ``pressure``
        then only scales the load factor. None: the pressure is ramped.
    """

    pressure: float = 0.045
    steps: StepSettings = field(default_factory=lambda: StepSettings(increments=10, substeps=2))
    volume: float | None = None

    def __post_init__(self) -> None:
        checks.real(self.pressure, "pressure", 0.0, checks.MAX_PRESSURE_KPA / 1e3, low_open=True, unit="MPa",
                    limit="MAX_PRESSURE_KPA")
        if self.volume is not None:
            checks.real(self.volume, "volume change", 0.0, 100.0, low_open=True)

    def pressures(self) -> FloatArray:
        return self.pressure * self.steps.levels()


__all__ = ["RampSpec"]

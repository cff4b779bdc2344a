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


#: what the pressure ramp's monitor (:meth:`~pneumorph.fem.body.PressurisedBody.stepper`: the cavity volume) says
#: when a higher pressure gave a smaller volume
_MONITOR_FELL = "the monitored quantity fell"


def past_the_maximum(cause: str) -> str:
    """A pressure ramp's failure cause, said in the model's terms where the cavity volume fell under more pressure.

    A smaller cavity at a higher pressure marks the approach of a pressure maximum: the walls
    balloon and the pressure an actuator holds levels off or falls as it inflates further (Ellis
    2020, 3.3.4), which no pressure-controlled ramp can pass; a volume-controlled one can. (A 4-unit
    2D actuator of Ecoflex 00-30 stops at 26 kPa; volume-controlled to 5 V0 its pressure creeps
    from 22 to 23.6 kPa over the last 2 V0.)

    Examples
    --------
    >>> print(past_the_maximum("no convergence at load factor 0.58 (the monitored quantity fell from 5976.5 to "
    ...                        "5976.48)"))
    no convergence at load factor 0.58 (the cavity volume fell from 5976.5 to 5976.48 mm^3 under a higher pressure:
    near a pressure maximum, where the walls balloon; a volume-controlled ramp can follow past it: simulate
    --volume-change, or [model] volume_change)
    >>> past_the_maximum("no convergence (det F <= 0)")
    'no convergence (det F <= 0)'
    """
    if _MONITOR_FELL not in cause:
        return cause
    head, _, tail = cause.partition(_MONITOR_FELL)
    numbers, _, rest = tail.partition(")")
    return (f"{head}the cavity volume fell{numbers} mm^3 under a higher pressure: near a pressure maximum, where the "
            f"walls balloon; a volume-controlled ramp can follow past it: simulate --volume-change, or [model] "
            f"volume_change){rest}")


__all__ = ["RampSpec", "past_the_maximum"]

"""The pressure ramp of a model: the final pressure and how the ramp to it is stepped.

The volume-controlled ramp's limits (:data:`~pneumorph.checks.MIN_VOLUME_CHANGE`,
:data:`~pneumorph.checks.MAX_VOLUME_CHANGE`, :data:`~pneumorph.checks.MAX_VOLUME_STEP`) and
:func:`~pneumorph.checks.check_volume_steps` are :mod:`pneumorph.checks`', named here too.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from pneumorph import checks
from pneumorph.checks import MAX_VOLUME_CHANGE, MAX_VOLUME_STEP, MIN_VOLUME_CHANGE, check_volume_steps
from pneumorph.errors import LimitPointError, SimulationFailed
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
            checks.real(self.volume, "volume change", MIN_VOLUME_CHANGE, MAX_VOLUME_CHANGE)
            check_volume_steps(self.volume, self.steps.increments)

    def pressures(self) -> FloatArray:
        return self.pressure * self.steps.levels()


def past_the_maximum(failure: SimulationFailed) -> str:
    """A pressure ramp's failure cause, said in the model's terms where it stopped at a limit point.

    The ramp's monitor is the cavity volume
    (:meth:`~pneumorph.fem.body.PressurisedBody.stepper`); a smaller cavity at a higher pressure
    (:class:`~pneumorph.errors.LimitPointError`) marks the approach of a pressure maximum: the
    walls balloon and the pressure an actuator holds levels off or falls as it inflates further
    (Ellis 2020, 3.3.4), which no pressure-controlled ramp can pass; a volume-controlled one can. (A
    4-unit 2D actuator of Ecoflex 00-30 stops at 26 kPa; volume-controlled to 5 V0 its pressure
    creeps from 22 to 23.6 kPa over the last 2 V0.) Any other failure keeps its cause.

    Examples
    --------
    >>> fell = LimitPointError(0.56, "no convergence", before=5976.5, after=5976.48, tried=0.58, cutbacks=6)
    >>> print(past_the_maximum(fell))
    no convergence at load factor 0.58 after 6 cut-backs (the cavity volume fell from 5976.5 to 5976.48 mm^3 under a
    higher pressure: near a pressure maximum, where the walls balloon; a volume-controlled ramp can follow past it:
    simulate --volume-change, or [model] volume_change)
    >>> past_the_maximum(SimulationFailed(0.3, "no convergence (det F <= 0)"))
    'no convergence (det F <= 0)'
    """
    if not isinstance(failure, LimitPointError):
        return failure.cause
    return (f"no convergence at load factor {failure.tried:.4g} after {failure.cutbacks} cut-backs (the cavity volume "
            f"fell from {failure.before:.6g} to {failure.after:.6g} mm^3 under a higher pressure: near a pressure "
            "maximum, where the walls balloon; a volume-controlled ramp can follow past it: simulate --volume-change, "
            "or [model] volume_change)")


__all__ = ["MAX_VOLUME_CHANGE", "MAX_VOLUME_STEP", "MIN_VOLUME_CHANGE", "RampSpec", "check_volume_steps",
           "past_the_maximum"]

"""The pressure ramp of a model: the final pressure and how the ramp to it is stepped."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from pneumorph import checks
from pneumorph.errors import LimitPointError, SettingsError, SimulationFailed
from pneumorph.fem import StepSettings
from pneumorph.models.response import FloatArray

#: the range of a volume-controlled ramp's relative volume change ``V / V0 - 1``: a smaller change is lost in the
#: cavity volume's rounding and the solver's tolerance (the ramp would report an unloaded actuator ten times); a
#: larger one is a hundredfold inflation no silicone survives
MIN_VOLUME_CHANGE, MAX_VOLUME_CHANGE = 1e-6, 100.0

#: the largest relative volume change of one step of a volume-controlled ramp (``simulate --volume-change`` over
#: its ``--increments``, ``[model] volume_change`` over ``increments``, ``bimodal --volume-change`` over
#: ``--pmax``/``--step``): the bimodal actuator converges at 0.67 V0 a step (the default 8 V0 in 12 steps) and 1.6 V0
#: (two voids, 5 steps) but not at 4 V0 in one step from rest; a 4-unit 2D actuator of Ecoflex 00-30 takes 0.5 V0 in
#: one step and stops at 1 V0 (its first iterate's pressure past the filler law's range), in a few seconds, not a
#: long ramp
MAX_VOLUME_STEP = 2.0


def check_volume_steps(volume: float, increments: int, names: tuple[str, str] = ("volume change", "increments"),
                       error: type[Exception] = SettingsError, advice: Callable[[int], str] | None = None) -> None:
    """Refuse a volume-controlled ramp whose steps change the volume by more than :data:`MAX_VOLUME_STEP`.

    Parameters
    ----------
    volume : float
        The ramp's relative volume change ``V / V0 - 1``.
    increments : int
        Its equal steps.
    names : (str, str)
        How the caller names the two settings (``("--volume-change", "--increments")``).
    error : exception class
        Raised with the one-line message (the caller's kind: a settings error, a usage error).
    advice : callable, optional
        ``advice(least_steps)``: what to do instead, in the caller's terms (default: at least that
        many of ``names[1]``).

    Examples
    --------
    >>> check_volume_steps(4.0, 2)
    >>> check_volume_steps(100.0, 1, ("--volume-change", "--increments"))  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    pneumorph.errors.SettingsError: --volume-change 100 over --increments 1 is 100 V0 per step, more than the 2 V0 a
    step can take from rest (MAX_VOLUME_STEP, pneumorph.models.fe.ramp): give at least 50 --increments
    """
    per = float(volume) / max(1, int(increments))
    if per <= MAX_VOLUME_STEP * (1 + 1e-12):
        return
    least = math.ceil(float(volume) / MAX_VOLUME_STEP * (1 - 1e-12))
    todo = advice(least) if advice is not None else f"give at least {least} {names[1]}"
    raise error(f"{names[0]} {float(volume):g} over {names[1]} {int(increments)} is {per:g} V0 per step, more than "
                f"the {MAX_VOLUME_STEP:g} V0 a step can take from rest (MAX_VOLUME_STEP, pneumorph.models.fe.ramp): "
                f"{todo}")


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

"""The load stepping's step control, on a substep strategy that fails by rule.

The strategy converges or fails by the load factor it is asked for and the size of the
step that leads there, so the sequence of attempts the ramp makes is known exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pytest

from pneumorph.errors import LimitPointError, SimulationFailed
from pneumorph.fem import StepSettings, ramp


@dataclass
class _Field:
    values: np.ndarray = field(default_factory=lambda: np.zeros(1))


@dataclass
class _Fields:
    fields: list[_Field] = field(default_factory=lambda: [_Field()])


class _Hard:
    """Converges unless the step is too large for where it ends: beyond t = 0.7 steps
    over 0.05 fail, beyond t = 0.95 steps over 0.025."""

    def __init__(self) -> None:
        self.t_now = 0.0
        self.t_try = 0.0
        self.attempts: list[tuple[float, float, bool]] = []

    def apply(self, t: float) -> None:
        self.t_try = t

    def __call__(self, fields: Any, settings: StepSettings) -> tuple[int, str | None]:
        size = self.t_try - self.t_now
        eps = 1e-9
        ok = not ((self.t_try > 0.7 + eps and size > 0.05 + eps) or (self.t_try > 0.95 + eps and size > 0.025 + eps))
        self.attempts.append((round(self.t_now, 6), round(self.t_try, 6), ok))
        if ok:
            self.t_now = self.t_try
        return 1, None if ok else "too large a step"


def _attempts(carry: bool) -> tuple[_Hard, Any]:
    hard = _Hard()
    stats = ramp([], _Fields(), hard.apply, np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                 StepSettings(increments=10, substeps=1), substep=hard, carry=carry)
    return hard, stats


def test_cut_back_halves_the_failed_step_and_carries_into_the_next_level() -> None:
    hard, stats = _attempts(carry=True)
    late = [a for a in hard.attempts if a[0] >= 0.7 - 1e-9]
    assert late == [
        (0.7, 0.8, False), (0.7, 0.75, True), (0.75, 0.8, True),  # level 8: one cut-back
        (0.8, 0.85, True), (0.85, 0.9, True),  # level 9 starts at the substep that converged last
        (0.9, 1.0, False), (0.9, 0.95, True),  # level 10 at the nominal substep again
        (0.95, 1.0, False), (0.95, 0.975, True), (0.975, 1.0, True),  # the failed 0.05 step halved
    ]
    assert len(set(hard.attempts)) == len(hard.attempts)  # no trial repeated
    assert (stats.substeps, stats.cutbacks, stats.reached) == (14, 3, 1.0)


def test_without_carry_every_level_starts_at_the_nominal_substep() -> None:
    hard, stats = _attempts(carry=False)
    late = [a for a in hard.attempts if a[0] >= 0.8 - 1e-9]
    assert late[:3] == [(0.8, 0.9, False), (0.8, 0.85, True), (0.85, 0.9, True)]
    assert len(set(hard.attempts)) == len(hard.attempts)
    assert (stats.substeps, stats.cutbacks, stats.reached) == (14, 4, 1.0)


class _Peaked:
    """Converges everywhere; the monitored quantity -(t - 0.53)^2 peaks at t = 0.53, like the cavity volume of a
    body that passes a pressure maximum."""

    def __init__(self) -> None:
        self.t_try = 0.0

    def apply(self, t: float) -> None:
        self.t_try = t

    def monitor(self) -> float:
        return -((self.t_try - 0.53) ** 2)

    def __call__(self, fields: Any, settings: StepSettings) -> tuple[int, str | None]:
        return 1, None


def test_a_monitor_that_falls_past_every_cut_back_stops_the_ramp_as_a_limit_point() -> None:
    """From 0.55 every trial of the level to 0.6, halved six times down to 0.5508, lands past the peak: the ramp
    raises the limit-point kind of failure with the monitored values, the factor tried and the cut-backs."""
    peaked = _Peaked()
    with pytest.raises(LimitPointError) as info:
        ramp([], _Fields(), peaked.apply, np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
             StepSettings(increments=10, substeps=1), substep=peaked, monitor=peaked.monitor)
    failure = info.value
    assert failure.reached == pytest.approx(0.55) and failure.tried == pytest.approx(0.55 + 0.05 / 64)
    assert failure.before == pytest.approx(-0.02**2) and failure.after == pytest.approx(-(0.02 + 0.05 / 64) ** 2)
    assert failure.cutbacks == 6 and failure.after < failure.before


def test_a_substep_that_fails_to_converge_is_not_a_limit_point() -> None:
    """A ramp whose Newton solves fail (the monitor never consulted) stops with the plain failure, not the kind a
    model explains as a pressure maximum."""
    def failing(fields: Any, settings: StepSettings) -> tuple[int, str | None]:
        return 16, "Newton iterations did not reach the tolerance"

    with pytest.raises(SimulationFailed) as info:
        ramp([], _Fields(), lambda t: None, np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
             StepSettings(increments=10, substeps=1), substep=failing, monitor=lambda: 1.0)
    assert not isinstance(info.value, LimitPointError) and info.value.reached == 0.0

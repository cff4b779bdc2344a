"""Eq 4.1 at every level, best level, datum, polar targets, tip goals, failures."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pneumorph.design.objectives.fitness import profile_errors, score, tip_values
from pneumorph.design.objectives.targets import make_objective, profile_target, tip_goal
from pneumorph.models import Response

P = np.array([0.0225, 0.045])


def three_units(offset: float = 0.0) -> Response:
    """Level 0: undeformed; level 1: centres on y = 0.1 x at their current x (x shortened)."""
    ref = np.array([[5.0, offset], [15.0, offset], [25.0, offset]])
    r = Response.empty("010", P, ref, np.array([30.0, offset]))
    r.centres[0] = ref
    r.centres[1] = [[5.0, 0.5 + offset], [14.0, 1.4 + offset], [24.0, 2.4 + offset]]
    r.tip[:] = [[30.0, offset], [29.0, 2.9 + offset]]
    r.curl[:] = [0.0, 5.7]
    return r


def test_eq_4_1_per_level_with_target_at_the_current_x() -> None:
    errors = profile_errors(three_units(), profile_target("y = 0.1*x"))
    # level 0: misses 0.5, 1.5, 2.5; level 1: on the line where the centres now are
    np.testing.assert_allclose(errors, [math.sqrt(0.25 + 2.25 + 6.25), 0.0], atol=1e-12)


def test_best_level_gives_the_pressure() -> None:
    s = score(three_units(), profile_target("y = 0.1*x"))
    assert (s.level, s.pressure, s.failed) == (1, 0.045, False)
    assert s.value == pytest.approx(0.0, abs=1e-12)
    # a target the undeformed actuator matches picks level 0 (22.5 kPa)
    s0 = score(three_units(), profile_target("y = 0"))
    assert (s0.level, s0.pressure) == (0, 0.0225)
    assert s0.value == 0.0 and s0.values[1] == pytest.approx(math.sqrt(0.25 + 1.96 + 5.76))


def test_heights_are_measured_from_the_undeformed_positions() -> None:
    target = profile_target("y = 0.1*x")
    np.testing.assert_allclose(profile_errors(three_units(7.5), target), profile_errors(three_units(), target),
                               atol=1e-12)


def test_polar_target_uses_radius_and_unwrapped_angle() -> None:
    ref = np.array([[5.0, 0.0], [15.0, 0.0], [25.0, 0.0]])
    r = Response.empty("000", P[:1], ref, np.array([30.0, 0.0]))
    angles = np.radians([90.0, 170.0, 190.0])  # the last one is -170 degrees before unwrapping
    r.centres[0] = 10.0 * np.column_stack([np.cos(angles), np.sin(angles)])
    r.tip[0] = [-10.0, 0.0]
    r.curl[0] = 270.0
    assert profile_errors(r, profile_target("r = 10"))[0] == pytest.approx(0.0, abs=1e-12)
    # r = 10 * theta / pi(190 deg) is 10 only at 190 degrees, if theta is unwrapped
    want = 10.0 * (1.0 - angles / angles[2])
    got = profile_errors(r, profile_target(f"r = 10 * theta / {float(angles[2])!r}"))[0]
    assert got == pytest.approx(np.sqrt(np.sum(want**2)), rel=1e-12)


def test_tip_goal_quantities_and_senses() -> None:
    r = three_units(2.0)
    np.testing.assert_allclose(tip_values(r, "max-x"), [30.0, 29.0])
    np.testing.assert_allclose(tip_values(r, "min-y"), [0.0, 2.9])
    np.testing.assert_allclose(tip_values(r, "min-distance"), [30.0, math.hypot(29.0, 2.9)])
    np.testing.assert_allclose(tip_values(r, "reach", (29.0, 0.0)), [1.0, 2.9])
    assert score(r, tip_goal("max-y")).level == 1
    assert score(r, tip_goal("min-y")).level == 0
    assert score(r, tip_goal("max-curl")).value == 5.7
    assert score(r, make_objective("reach", point=(30.0, 0.5))).value == pytest.approx(0.5)


def test_failed_and_nan_responses_get_the_worst_fitness() -> None:
    target, goal = profile_target("sin"), tip_goal("max-x")
    r = three_units()
    failed = Response(**{**r.__dict__, "converged": False, "failure": "diverged", "reached": 0.0225})
    assert score(failed, target).value == math.inf and score(failed, target).failed
    assert score(failed, goal).value == -math.inf and score(failed, goal).level is None
    assert score(None, target, n_levels=2).values.tolist() == [math.inf, math.inf]
    # one missing level: worst there, the other level still counts
    half = three_units()
    half.centres[1] = np.nan
    half.tip[1] = np.nan
    s = score(half, goal)
    assert s.values.tolist() == [30.0, -math.inf] and s.level == 0 and not s.failed
    half.centres[0] = np.nan
    half.tip[0] = np.nan
    assert score(half, goal).failed

"""Target expressions (safe parsing), presets and objective names."""

from __future__ import annotations

import math
import pickle
import time

import numpy as np
import pytest

from pneumorph.design.objectives.expressions import parse_expression
from pneumorph.design.objectives.targets import TIP_GOALS, make_objective, profile_target, tip_goal
from pneumorph.errors import (
    SearchConfigError,
    TargetExpressionError,
    UnknownObjectiveError,
)


def test_expression_values_match_numpy() -> None:
    f = parse_expression("A*exp(-x/L) + sqrt(abs(x - 3)) * log(2 + x) / tan(0.3) - max(x, 1, 2) ** 2 + min(x, e) + pi")
    x = np.array([0.0, 1.5, 4.0, 10.0])
    want = (
        2.0 * np.exp(-x / 50.0)
        + np.sqrt(np.abs(x - 3)) * np.log(2 + x) / np.tan(0.3)
        - np.maximum(np.maximum(x, 1), 2) ** 2
        + np.minimum(x, math.e)
        + math.pi
    )
    np.testing.assert_allclose(f(x=x, L=50.0, A=2.0), want, rtol=1e-15)
    assert f.used == {"x", "L", "A"}


def test_expression_is_picklable_and_broadcasts_constants() -> None:
    f = pickle.loads(pickle.dumps(parse_expression("-2.5")))
    assert f(x=np.zeros(3)).tolist() == [-2.5, -2.5, -2.5]


def test_sin_preset_is_one_period_over_the_length() -> None:
    t = profile_target("sin", amplitude=15.0)
    x = np.array([0.0, 25.0, 50.0, 75.0, 100.0])
    np.testing.assert_allclose(t.curve(x, length=100.0), [0, 15, 0, -15, 0], atol=1e-12)
    two = profile_target("sin", amplitude=15.0, periods=2)
    np.testing.assert_allclose(two.curve([12.5, 37.5], length=100.0), [15, -15], atol=1e-12)


def test_cos_preset_starts_at_the_base_unless_told_otherwise() -> None:
    x = np.array([0.0, 50.0, 100.0])
    np.testing.assert_allclose(profile_target("cos", amplitude=20.0).curve(x, 100.0), [0, -40, 0], atol=1e-12)
    plain = profile_target("cos", amplitude=20.0, anchored=False)
    np.testing.assert_allclose(plain.curve(x, 100.0), [20, -20, 20], atol=1e-12)


def test_polar_and_cartesian_forms() -> None:
    polar = profile_target("r = 30 + 5*theta")
    assert polar.coordinates == "polar"
    np.testing.assert_allclose(polar.curve([0.0, 2.0], length=1.0), [30.0, 40.0])
    assert profile_target("2*theta").coordinates == "polar"
    assert profile_target("Y = 0.5 * x").coordinates == "cartesian"


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("foo * x", "unknown name 'foo'"),
        ("__import__('os')", "unknown function '__import__'"),
        ("x.__class__", "attribute access is not allowed: 'x.__class__'"),
        ("().__class__.__bases__", "attribute access is not allowed"),
        ("gamma(x)", "unknown function 'gamma'"),
        ("(lambda: 1)()", "only the listed functions can be called"),
        ("lambda x: x", "lambda functions are not allowed"),
        ("[x for x in (1, 2)]", "comprehensions are not allowed"),
        ("x[0]", "subscripts are not allowed"),
        ("sin(x=1)", "keyword arguments are not allowed"),
        ("x**1e9", "the exponent 1e+09 is larger than 100"),
        ("x ** -101", "the exponent -101 is larger than 100"),
        ("9**9**9", "exponents of exponents are not allowed"),
        ("2**(x**2)", "exponents of exponents are not allowed"),
        ("x ^ 2", "operator ^ is not allowed (write powers as a ** b)"),
        ("x % 2", "operator % is not allowed"),
        ("'abc'", "only numbers are allowed"),
        ("x if x else 1", "conditional expressions are not allowed"),
        ("x > 1", "comparisons are not allowed"),
        ("sin", "the function sin must be called"),
        ("sin(x, x)", "sin() takes 1 argument, got 2"),
        ("max(x)", "max() takes at least 2 arguments, got 1"),
        ("theta * 2 + x", "theta is the variable of polar targets"),
        ("sin(x", "not valid syntax"),
        ("", "empty"),
        ("x + " * 150 + "x", "characters; at most 400"),
        ("+".join(["x"] * 150), "syntax nodes; at most 200"),
        ("1e999 * x", "too large"),
    ],
)
def test_bad_expressions_are_rejected_with_the_offending_part(text: str, fragment: str) -> None:
    start = time.perf_counter()
    with pytest.raises(TargetExpressionError) as err:
        profile_target(f"y = {text}" if text else text)
    assert fragment in str(err.value), str(err.value)
    assert time.perf_counter() - start < 0.5  # nothing is evaluated while checking


def test_polar_expression_rejects_x() -> None:
    with pytest.raises(TargetExpressionError, match="x is the variable of Cartesian targets"):
        profile_target("r = x + theta")
    with pytest.raises(TargetExpressionError, match=r"left-hand side .* must be y"):
        profile_target("z = x")


def test_tip_goals_senses_and_aliases() -> None:
    assert {k: v[0] for k, v in TIP_GOALS.items()} == {
        "max-x": "max",
        "min-x": "min",
        "max-y": "max",
        "min-y": "min",
        "min-distance": "min",
        "max-curl": "max",
        "reach": "min",
    }
    assert tip_goal("MIN_RADIUS").name == "min-distance"
    assert make_objective("reach", point=(60, 40)).point == (60.0, 40.0)


def test_unknown_objectives_list_the_known_ones() -> None:
    for bad in ("max-z", "maximum", "tan"):
        with pytest.raises(UnknownObjectiveError) as err:
            make_objective(bad)
        message = str(err.value)
        assert f"unknown objective {bad!r}" in message
        assert all(name in message for name in [*TIP_GOALS, "sin", "cos"])


def test_reach_needs_a_point_and_others_refuse_one() -> None:
    with pytest.raises(SearchConfigError, match="needs a tip point"):
        make_objective("reach")
    with pytest.raises(SearchConfigError, match="only used by the objective 'reach'"):
        make_objective("max-x", point=(1.0, 2.0))
    with pytest.raises(SearchConfigError, match="only used by the objective 'reach'"):
        make_objective("sin", point=(1.0, 2.0))


@pytest.mark.parametrize(
    ("curve", "message"),
    [
        ([[0, 0], [True, 1]], "must be a list of"),
        ([["0", "0"], ["100", "5"]], "must be a list of"),
        ([[0, 0], [1e-9, 1]], "the curve spans 1e-09 mm"),
        ([[-100, 0], [-50, 5]], "the curve spans 0 mm"),
    ],
)
def test_curve_configs_that_would_be_read_wrongly_are_refused(curve: list, message: str) -> None:
    from pneumorph.design import DesignConfig
    from pneumorph.errors import SearchConfigError

    with pytest.raises(SearchConfigError, match=message):
        DesignConfig(objective="curve", curve=curve, units=15)
    assert DesignConfig(objective="curve", curve=[[0, 0], [80, 2], [160, 5]]).curve == ((0, 0), (80, 2), (160, 5))


def test_more_periods_than_the_unit_centres_can_show_are_refused() -> None:
    from pneumorph.design import DesignConfig
    from pneumorph.errors import SearchConfigError

    # Eq 4.1 samples the target at the unit centres: n centres show at most n / 2 periods
    assert DesignConfig(units=5, periods=2.5).periods == 2.5
    with pytest.raises(SearchConfigError, match=r"\[design\] periods = 3: a sin target over 5 unit centres shows at "
                                                r"most 2.5 periods"):
        DesignConfig(units=5, periods=3)
    with pytest.raises(SearchConfigError, match=r"\[\[design.stage\]\] 2 periods = 4: a cos target"):
        DesignConfig(units=6, objective="stages", stage=({"pressure_kpa": 18, "objective": "sin"},
                                                         {"pressure_kpa": 45, "objective": "cos", "periods": 4}))
    assert DesignConfig(units=5, objective="y = sin(2*pi*40*x/L)").units == 5  # an expression says what it means
    assert DesignConfig(units=1).periods == 1.0  # one period, the presets' default, whatever the units

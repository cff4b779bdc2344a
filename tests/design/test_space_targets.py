"""Space-curve targets: ``y = f(x), z = g(x)``, helices, drawn (x, y, z) curves and tip points off the plane."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.design import DesignConfig, make_objective, run_exhaustive
from pneumorph.design.certified.search import certified_search, chain_scores
from pneumorph.design.objectives.fitness import profile_errors, tip_values
from pneumorph.design.objectives.targets import profile_target, tip_goal
from pneumorph.errors import SearchConfigError, TargetExpressionError
from pneumorph.models.chain.model import ChainModel, ChainTable, design_strings
from pneumorph.models.chain.sources import shipped_path
from pneumorph.models.response import Response


def _response(centres: np.ndarray, reference: np.ndarray, tip: np.ndarray, reference_tip: np.ndarray) -> Response:
    r = Response.empty("00", np.array([0.01]), reference, reference_tip)
    r.centres[0] = centres
    r.tip[0] = tip
    r.curl[0] = 0.0
    return r


def test_a_helix_is_a_circle_about_an_axis_along_x() -> None:
    L, R = 120.0, 25.0
    x = np.linspace(0.0, L, 13)
    for name, hand in (("helix", -1.0), ("helix-left", 1.0)):
        h = profile_target(name, amplitude=R, periods=1.0)
        y, z = h.curve(x, L), h.curve_z(x, L)
        assert h.spatial and h.coordinates == "cartesian"
        np.testing.assert_allclose((y - R) ** 2 + z**2, R**2, atol=1e-9)  # radius R about (y, z) = (R, 0)
        # turning from -y towards +z is left-handed about +x: the sign of z a quarter turn on
        assert np.sign(h.curve_z([L / 4], L)[0]) == hand
    two = profile_target("helix", amplitude=R, periods=2.0)
    np.testing.assert_allclose(two.curve_z([L / 2], L), [0.0], atol=1e-9)


def test_space_expressions_and_their_refusals() -> None:
    t = make_objective("y = 0.1*x, z = -A*x/L", amplitude=5.0, length=100.0)
    assert t.spatial and t.label == "y = 0.1*x, z = -A*x/L, A = 5 mm"
    np.testing.assert_allclose(t.curve_z([50.0], 100.0), [-2.5])
    assert not make_objective("y = 0.1*x").spatial
    with pytest.raises(TargetExpressionError, match="z = 1/x"):
        make_objective("y = 0, z = 1/x").check(100.0)  # type: ignore[union-attr]
    with pytest.raises(TargetExpressionError, match="polar"):
        profile_target("r = 50").__class__(profile_target("r = 50").expression, "polar",
                                           depth=profile_target("y = x").expression)


def test_eq_4_1_counts_y_and_z_and_keeps_planar_values() -> None:
    ref = np.array([[5.0, 0.0], [15.0, 0.0]])
    planar = _response(np.array([[5.0, 1.0], [15.0, 2.0]]), ref, np.array([20.0, 2.0]), np.array([20.0, 0.0]))
    flat = make_objective("y = 0.1*x")
    space = make_objective("y = 0.1*x, z = 0.2*x")
    # planar response (z = 0): the planar value, and the space curve adds g(x)^2 = 1 and 9
    assert profile_errors(planar, flat)[0] == np.sqrt(0.25 + 0.25)
    assert profile_errors(planar, space)[0] == pytest.approx(np.sqrt(0.5 + 1.0 + 9.0), rel=1e-15)
    # centres off the plane: distance in y and z from the reference centres
    ref3 = np.array([[5.0, 0.0, 7.5], [15.0, 0.0, 7.5]])
    out = _response(np.array([[5.0, 1.0, 8.5], [15.0, 2.0, 10.5]]), ref3, np.array([20.0, 2.0, 10.5]),
                    np.array([20.0, 0.0, 7.5]))
    assert profile_errors(out, space)[0] == pytest.approx(np.sqrt(0.5 + 0.0 + 0.0), rel=1e-15)
    assert profile_errors(out, flat)[0] == pytest.approx(np.sqrt(0.5 + 1.0 + 9.0), rel=1e-15)
    # a tip point off the plane: the distance in space
    assert tip_values(planar, "reach", (20.0, 2.0, -3.0))[0] == 3.0
    assert tip_values(out, "reach", (20.0, 2.0))[0] == 3.0
    assert tip_goal("reach", (1, 2, 3)).label == "reach the tip point (1, 2, 3) mm"


def test_config_takes_points_and_curves_in_space() -> None:
    c = DesignConfig(objective="reach", point=[60, 40, -10])
    assert c.point == (60.0, 40.0, -10.0)
    c = DesignConfig(objective="curve", curve=[[0, 0, 0], [80, 2, 5], [160, 5, 9]])
    target = c.make_objective(157.5)
    assert target.spatial and target.curve_z([80.0], 157.5)[0] == 5.0
    with pytest.raises(SearchConfigError, match=r"all \[x, y, z\]"):
        DesignConfig(objective="curve", curve=[[0, 0, 0], [80, 2]])


N = 6  # the units of the coarse_2d fixture (conftest.py)


@pytest.fixture(scope="module")
def setup(coarse_2d):  # type: ignore[no-untyped-def]
    """The real 2D model (coarse mesh, 25 kPa, 6 units) and its chain (tests/design/conftest.py)."""
    return coarse_2d


@pytest.mark.slow
def test_the_certified_search_for_a_space_curve_equals_the_fe_exhaustive_search(setup) -> None:
    """A planar actuator against a space curve: the certified search (the chain's centres at z = 0, the bound with
    the slope of y and z) returns the FE exhaustive search's optimum, and the FE value adds the z term in full."""
    model, chain, evaluator = setup
    target = make_objective("y = 0.04*x, z = 2 + 0.03*x", length=chain.length)
    truth = run_exhaustive(model, target, evaluator)
    result = certified_search(model, chain, target, evaluator, verify=1, certify=True)
    assert result.certificate["certified"] and result.winner.design == truth.best.design
    assert result.winner.value == pytest.approx(truth.best.value, abs=1e-9)
    fe = result.winner.response
    k = result.winner.level
    x, y = fe.centres[k, :, 0], fe.centres[k, :, 1] - fe.reference_centres[:, 1]
    hand = np.sqrt(np.sum((0.04 * x - y) ** 2 + (2 + 0.03 * x) ** 2))
    assert result.winner.value == pytest.approx(hand, rel=1e-12)
    order = result.scores.order()
    names = design_strings(result.scores.bits[order])
    for design, c in result.verified.items():
        i = order[names.index(design)]
        assert abs(result.scores.cost[i] - c.value) <= result.scores.bound[i] + 1e-9


@pytest.mark.parametrize("target", [profile_target("helix", amplitude=20.0), tip_goal("reach", (120.0, 40.0, 15.0))])
def test_branch_and_bound_in_space_keeps_every_design_that_matters(target, keeps_every_design) -> None:
    """15 units of the shipped 3D table forced past enumeration: every design whose enumerated cost is below the
    threshold is kept, with the same cost, and the same best design."""
    chain = ChainModel(ChainTable.load(shipped_path("3d")), 15)
    every = chain_scores(chain, target)
    grown = chain_scores(chain, target, max_enumerate=10)
    names = keeps_every_design(every, grown)
    # the chain's cost is the objective's own value of the chain's response (the z terms in full)
    from pneumorph.design.objectives.fitness import objective_values

    best = design_strings(every.bits[every.order()[:1]])[0]
    values = objective_values(chain.evaluate(best), target)
    assert names[best] == pytest.approx(float(np.nanmin(values) if target.sense == "min" else np.nanmax(values)),
                                        rel=1e-9)


@pytest.mark.parametrize("target", [profile_target("helix", amplitude=5.0), tip_goal("reach", (20.0, 2.0, 3.0))])
def test_the_profile_figure_of_a_run_in_space_has_the_view_from_above_and_in_space(target, tmp_path) -> None:
    from matplotlib.image import imread

    from pneumorph.design.runs.figures import plot_profile
    from pneumorph.design.search.scoring import Candidate

    ref3 = np.array([[5.0, 0.0, 7.5], [15.0, 0.0, 7.5]])
    r = _response(np.array([[5.0, 1.0, 8.5], [15.0, 2.0, 10.5]]), ref3, np.array([20.0, 2.0, 10.5]),
                  np.array([20.0, 0.0, 7.5]))
    path = plot_profile(Candidate("lL", 1.0, 0, 0.01, None, r), target, tmp_path / "profile.png")
    flat = plot_profile(Candidate("lL", 1.0, 0, 0.01, None, _response(np.array([[5.0, 1.0], [15.0, 2.0]]),
                                                                        ref3[:, :2], np.array([20.0, 2.0]),
                                                                        np.array([20.0, 0.0]))),
                        make_objective("y = 0.1*x"), tmp_path / "flat.png")
    # the side view, the view from above and the view in space: a figure much taller than the planar one's
    assert imread(path).shape[0] > 2 * imread(flat).shape[0]

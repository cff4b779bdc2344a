"""Certified search: equal to FE exhaustive search on the real 2D model, the bound, branch-and-bound."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.design import make_objective, run_exhaustive
from pneumorph.design.certified.headingbox import _cos_range, _sin_range
from pneumorph.design.certified.search import (
    certified_search,
    chain_errors,
    chain_scores,
    grow_designs,
    objective_bounds,
    score_designs,
)
from pneumorph.errors import SearchConfigError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.orientation import mirror
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.model import ChainModel, ChainTable, design_strings
from pneumorph.models.chain.sources import shipped_path
from pneumorph.models.fe import RampSpec, Reduced2D

N = 7


@pytest.fixture(scope="module")
def setup() -> tuple[Reduced2D, ChainModel, CachedEvaluator]:
    """The real 2D model (coarse mesh, 25 kPa, 7 units), every design solved once, and its chain."""
    model = Reduced2D(N, UnitSpec(element_size=3.0), RampSpec(pressure=0.025))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    table = build_table(model, evaluator, heldout=8)
    return model, ChainModel(table, N), evaluator


OBJECTIVES = [
    ("sin", {"amplitude": 5.0}),
    ("cos", {"amplitude": 8.0}),
    ("r = 20 + 15*theta", {}),
    ("max-y", {}),
    ("reach", {"point": (50.0, 30.0)}),
]


@pytest.mark.slow
@pytest.mark.parametrize(("spec", "kw"), OBJECTIVES)
def test_certified_search_equals_fe_exhaustive_search(setup, spec: str, kw: dict) -> None:
    model, chain, evaluator = setup
    objective = make_objective(spec, **kw)
    truth = run_exhaustive(model, objective, evaluator)
    result = certified_search(model, chain, objective, evaluator, verify=1, certify=True)
    assert result.certificate["certified"] and result.certificate["gap"] == 0.0
    assert result.certificate["designs_scored"] == 2**N
    assert result.winner.value == pytest.approx(truth.best.value, abs=1e-6)
    assert result.winner.design in {truth.best.design, mirror(truth.best.design)}
    # far fewer FE solves than designs
    assert len(result.certificate["verified"]) < 2**N / 4
    # every verified design's FE value lies within the bound of its chain value
    sign = 1.0 if objective.sense == "min" else -1.0
    order = result.scores.order()
    names = design_strings(result.scores.bits[order])
    for design, fe in result.verified.items():
        i = order[names.index(design)]
        assert abs(sign * result.scores.cost[i] - fe.value) <= result.scores.bound[i] + 1e-9


def test_without_certify_one_batch_is_verified_and_the_gap_is_reported(setup) -> None:
    model, chain, evaluator = setup
    objective = make_objective("sin", amplitude=5.0)
    result = certified_search(model, chain, objective, evaluator, verify=1)
    c = result.certificate
    assert len(c["verified"]) == 1 and c["verified"][0] == result.hall_of_fame[0].design
    assert c["certified"] == (c["could_beat"] == 0)
    assert c["gap"] >= 0.0


@pytest.mark.slow
def test_a_certificate_within_epsilon_counts_the_ties_and_solves_less(setup) -> None:
    """Within epsilon: no design can beat the winner by more than epsilon, and the truth (every design by FE)
    agrees; the designs that could beat it by less are counted as ties instead of verified."""
    model, chain, evaluator = setup
    objective = make_objective("cos", amplitude=8.0)
    exact = certified_search(model, chain, objective, evaluator, verify=1, certify=True)
    eps = 0.15  # mm: a third of the bound (0.44 mm)
    loose = certified_search(model, chain, objective, evaluator, verify=1, certify=True, epsilon=eps)
    c = loose.certificate
    assert c["certified"] and c["epsilon"] == eps and c["could_beat"] == 0
    assert 0.0 <= c["gap"] <= eps + 1e-12
    assert c["tied"] > 0 and len(c["verified"]) < len(exact.certificate["verified"])
    truth = run_exhaustive(model, objective, evaluator)
    assert loose.winner.value <= truth.best.value + eps + 1e-9
    with pytest.raises(SearchConfigError, match="epsilon"):
        certified_search(model, chain, objective, evaluator, epsilon=-1.0)


def test_the_cartesian_bound_is_the_closed_form() -> None:
    # beta = e sqrt(n (1 + S^2)), S = 2 pi A / L the largest slope of the sin preset
    table = ChainTable.load(shipped_path("2d"))
    chain = ChainModel(table, 15)
    objective = make_objective("sin", amplitude=10.0)
    errors = chain_errors(chain)
    bits = np.zeros((1, 15), dtype=np.uint8)
    centres, _, _ = chain.predict(bits)
    beta = objective_bounds(chain, objective, centres, chain.table.reference(bits)[0], errors)
    length = float(table.reference(bits)[1][0])
    slope = 2 * np.pi * 10.0 / length
    assert np.allclose(beta[0], errors["centre"] * np.sqrt(15 * (1 + slope**2)), rtol=1e-6)
    # a longer actuator than the training one widens the errors in proportion
    assert np.allclose(chain_errors(ChainModel(table, 30))["centre"], 2 * errors["centre"])


@pytest.mark.parametrize("spec", ["sin", "cos", "max-y", "max-curl", "r = 30 + 10*theta"])
def test_growing_designs_unit_by_unit_equals_scoring_them_whole(spec: str) -> None:
    chain = ChainModel(ChainTable.load(shipped_path("2d")), 10)
    objective = make_objective(spec)
    errors = chain_errors(chain)
    grown = grow_designs(chain, objective, errors)
    whole = score_designs(chain, objective, grown.bits, errors)
    assert len(grown.bits) == 2**10
    assert np.allclose(grown.cost, whole.cost, rtol=0, atol=1e-9)
    assert np.allclose(grown.optimistic, whole.optimistic, rtol=0, atol=1e-9)


@pytest.mark.parametrize("spec", ["sin", "cos", "max-y", "min-distance"])
def test_branch_and_bound_finds_every_design_that_matters(spec: str) -> None:
    chain = ChainModel(ChainTable.load(shipped_path("2d")), 14)
    objective = make_objective(spec, amplitude=10.0)
    full = chain_scores(chain, objective)
    bb = chain_scores(chain, objective, max_enumerate=10)
    assert not bb.complete and full.complete
    assert design_strings(bb.bits[bb.order()[:1]]) == design_strings(full.bits[full.order()[:1]])
    # every design outside the branch-and-bound set is no better than its floor (optimistically)
    found = set(design_strings(bb.bits))
    outside = [i for i, d in enumerate(design_strings(full.bits)) if d not in found]
    assert full.optimistic[outside].min() >= bb.floor - 1e-9
    assert len(found) < 2**14 / 4


def test_the_range_of_cos_and_sin_over_an_interval() -> None:
    rng = np.random.default_rng(3)
    lo = rng.uniform(-20.0, 20.0, 400)
    hi = lo + np.concatenate([rng.uniform(0.0, 7.0, 390), np.zeros(10)])
    for span, f in ((_cos_range, np.cos), (_sin_range, np.sin)):
        bottom, top = span(lo, hi)
        for a, b, least, most in zip(lo, hi, bottom, top, strict=False):
            v = f(np.linspace(a, b, 4001))
            assert least <= v.min() + 1e-12 and most >= v.max() - 1e-12  # a valid range
            assert least == pytest.approx(v.min(), abs=1e-5) and most == pytest.approx(v.max(), abs=1e-5)  # tight
    assert _cos_range(np.array([-0.1]), np.array([0.1]))[1][0] == 1.0  # holds the maximum at 0
    assert _sin_range(np.array([3.0]), np.array([3.3]))[0][0] == pytest.approx(np.sin(3.3))


def test_an_fe_model_that_never_converges_is_given_up_early(setup) -> None:
    from pneumorph.errors import SearchConfigError
    from pneumorph.fem import StepSettings

    _model, chain, _ = setup
    starved = Reduced2D(N, UnitSpec(element_size=3.0),
                        RampSpec(pressure=0.025, steps=StepSettings(increments=10, substeps=1, max_iterations=1,
                                                                    max_cutbacks=1)))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    with pytest.raises(SearchConfigError, match="did not converge for the chain's 4 best designs"):
        certified_search(starved, chain, make_objective("sin", amplitude=5.0), evaluator, verify=2)
    assert evaluator.solves == 4
    other = Reduced2D(N, UnitSpec(element_size=3.0), RampSpec(pressure=0.03))
    with pytest.raises(SearchConfigError, match="different pressure levels"):
        certified_search(other, chain, make_objective("sin"), evaluator)


def test_epsilon_is_a_setting_of_the_certified_search_only() -> None:
    from pneumorph.design.config import DesignConfig

    config = DesignConfig(epsilon=0.05)
    assert DesignConfig.from_dict(config.to_dict()).epsilon == 0.05
    assert "epsilon" not in DesignConfig().to_dict()["design"]  # absent by default: run folders of before match
    with pytest.raises(SearchConfigError, match="epsilon"):
        DesignConfig(search="ga", epsilon=0.05)
    with pytest.raises(SearchConfigError, match="epsilon"):
        DesignConfig(epsilon=-1.0)

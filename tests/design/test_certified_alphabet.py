"""Certified search over a unit library : 2k choices per unit, scored exactly, verified by 2D FE."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pneumorph.design import make_objective
from pneumorph.design.certified.search import (
    best_scores,
    certified_search,
    chain_candidate,
    chain_errors,
    chain_scores,
    grow_designs,
    score_designs,
)
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.fe import RampSpec, Reduced2D

N = 6


@pytest.fixture(scope="module")
def setup() -> tuple[Reduced2D, ChainModel, CachedEvaluator]:
    """The real 2D model over bending and near-rigid units (coarse mesh, 25 kPa, 6 units) and its chain."""
    lib = builtin_library()
    coarse = UnitLibrary(("a", "r"), tuple(replace(lib[s], element_size=3.0) for s in "ar"), name="coarse")
    model = Reduced2D(N, library=coarse, ramp_spec=RampSpec(pressure=0.025))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    table = build_table(model, evaluator, window=1, heldout=6)
    return model, ChainModel(table, N), evaluator


@pytest.mark.parametrize("spec", ["sin", "max-y", "max-curl", "r = 30 + 10*theta"])
def test_every_design_over_the_alphabet_is_scored_as_a_whole(setup, spec: str) -> None:
    _, chain, _ = setup
    objective = make_objective(spec, length=chain.length)
    errors = chain_errors(chain)
    grown = grow_designs(chain, objective, errors)
    assert grown.choices == 4 and len(grown.bits) == 4**N
    assert len({tuple(b) for b in grown.bits.tolist()}) == 4**N
    whole = score_designs(chain, objective, grown.bits, errors)
    assert np.allclose(grown.cost, whole.cost, rtol=0, atol=1e-9)
    assert np.allclose(grown.optimistic, whole.optimistic, rtol=0, atol=1e-9)
    # the chain model's own response of the best design gives the same value
    best = grown.order()[0]
    text = chain.table.texts(grown.bits[best : best + 1])[0]
    assert set(text.lower()) <= {"a", "r"} and chain.evaluate(text).orientation == text


def test_branch_and_bound_over_the_alphabet_finds_every_design_that_matters(setup) -> None:
    _, six, _ = setup
    chain = ChainModel(six.table, 8)  # 4^8 = 65,536 designs
    objective = make_objective("sin", amplitude=5.0, length=chain.length)
    full = chain_scores(chain, objective)
    bb = chain_scores(chain, objective, max_enumerate=12)  # 4^8 > 2^12: branch-and-bound
    assert full.complete and not bb.complete and len(full.bits) == 4**8
    texts = chain.table.texts
    assert texts(bb.bits[bb.order()[:1]]) == texts(full.bits[full.order()[:1]])
    found = set(texts(bb.bits))
    outside = [i for i, d in enumerate(texts(full.bits)) if d not in found]
    assert full.optimistic[outside].min() >= bb.floor - 1e-9
    assert len(found) < 4**8 / 4
    top = best_scores(chain, objective)
    assert texts(top.bits[top.order()[:10]]) == texts(full.bits[full.order()[:10]])


@pytest.mark.parametrize(("spec", "kw"), [("sin", {"amplitude": 5.0}), ("max-y", {})])
def test_the_certified_winner_over_the_alphabet_is_verified_by_2d_fe(setup, spec: str, kw: dict) -> None:
    model, chain, evaluator = setup
    objective = make_objective(spec, length=chain.length, **kw)
    result = certified_search(model, chain, objective, evaluator, verify=2, certify=True)
    cert = result.certificate
    assert cert["certified"] and cert["complete"] and cert["designs_scored"] == 4**N
    # the FE value of every verified design lies within the bound of its chain value
    for design, candidate in result.verified.items():
        chained = chain_candidate(chain, objective, design)
        assert chained.response is not None and chained.response.orientation == design
        assert abs(candidate.value - chained.value) <= cert["bound_worst"]
    assert result.winner.design in result.verified and set(result.winner.design.lower()) <= {"a", "r"}

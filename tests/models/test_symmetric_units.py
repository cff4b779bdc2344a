"""Symmetric unit types: a unit whose turned-over body is itself has one orientation, one letter, one set of windows."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.design import make_objective
from pneumorph.design.certified.search import chain_errors, grow_designs
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.model import ChainModel, covering_designs
from pneumorph.models.fe import RampSpec, Reduced2D

N = 6


@pytest.fixture(scope="module")
def setup() -> tuple[Reduced2D, ChainModel]:
    """The real 2D model over bending and extending units (25 kPa, 6 units) and its chain."""
    lib = builtin_library()
    coarse = UnitLibrary(("a", "e"), tuple(lib[s] for s in "ae"), name="coarse-ae")
    model = Reduced2D(N, library=coarse, ramp_spec=RampSpec(pressure=0.025))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    return model, ChainModel(build_table(model, evaluator, window=1, heldout=6), N)


def test_the_extending_unit_turned_over_is_the_same_body(setup) -> None:
    """By FE: a design with E and the same design with e solve to the same centres, tip and curl (to 1e-9 mm)."""
    model, _ = setup
    r1, r2 = model.evaluate("aEaeA"[:N - 1] + "a"), model.evaluate("aeaeA"[:N - 1] + "a")
    assert np.allclose(r1.centres, r2.centres, rtol=0, atol=1e-9)
    assert np.allclose(r1.tip, r2.tip, rtol=0, atol=1e-9)
    assert np.allclose(r1.curl, r2.curl, rtol=0, atol=1e-9)


def test_a_table_over_a_symmetric_type_has_one_orientation_of_it(setup) -> None:
    _, chain = setup
    table = chain.table
    assert table.symmetric == ("e",)
    assert table.unit_codes.tolist() == [0, 1, 2]
    assert not any("E" in t for t in table.to_dict()["windows"])
    assert all("E" not in d for d in table.training)
    # a design written with E is read as e
    assert table.texts(table.designs("aEAEaa")) == ["aeAeaa"]
    assert np.allclose(chain.evaluate("aEAEaa").centres, chain.evaluate("aeAeaa").centres, rtol=0, atol=0)
    # the covering set of three codes per unit is smaller than that of four
    three = covering_designs(N, 1, n_types=2, alphabet=("a", "e"), symmetric=(1,))
    four = covering_designs(N, 1, n_types=2, alphabet=("a", "e"))
    assert len(three) < len(four)
    assert len(three) == len(table.training)


def test_the_search_grows_three_choices_per_unit(setup) -> None:
    _, chain = setup
    objective = make_objective("sin", 5.0, length=chain.length)
    grown = grow_designs(chain, objective, chain_errors(chain))
    assert len(grown.bits) == 3**N
    assert len({tuple(b) for b in grown.bits.tolist()}) == 3**N
    assert not np.isin(grown.bits, [3]).any()

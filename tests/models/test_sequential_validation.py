"""Held-out validation in rounds: a window refuted by its first designs, a table clearly within stopped early."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.errors import LocalityError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import CLEAR_FRACTION, MIN_HELDOUT, build_table, heldout_designs, prediction_errors
from pneumorph.models.chain.plan import build_plan
from pneumorph.models.chain.windows import covering_designs
from pneumorph.models.fe import RampSpec, Reduced2D

MODEL = Reduced2D(9, UnitSpec(element_size=3.0), RampSpec(pressure=0.02))


@pytest.fixture(scope="module")
def evaluator() -> CachedEvaluator:
    return CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))


@pytest.mark.slow
def test_a_table_clearly_within_the_tolerance_stops_after_the_fewest_held_out_designs(evaluator) -> None:
    full = build_table(MODEL, evaluator, window=2, heldout=12)
    early = build_table(MODEL, evaluator, window=2, heldout=12, early=True)
    assert full.validation["heldout_solved"] == 12 and full.validation["stopped_early"] == ""
    worst = max(early.validation["centre_worst_mm"])
    assert worst <= CLEAR_FRACTION * 0.2  # the default tolerance: clearly within
    assert early.validation["heldout_solved"] == MIN_HELDOUT and early.validation["stopped_early"] == "clear"
    # the errors it records are those of the first MIN_HELDOUT held-out designs, nothing else
    first = full.validation["designs"][:MIN_HELDOUT]
    assert early.validation["designs"] == first
    responses = evaluator.evaluate_many(MODEL, first)
    again = prediction_errors(early, [o.response for o in responses])
    assert np.allclose(again["centre_worst_mm"], early.validation["centre_worst_mm"], rtol=0, atol=1e-12)
    # a subset of the full validation: its worst is at most the full worst
    assert worst <= max(full.validation["centre_worst_mm"]) + 1e-12


def test_a_window_refuted_by_its_first_held_out_design_solves_no_more() -> None:
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    tests = heldout_designs(9, 10, exclude=covering_designs(9, 1), seed=1)
    lines: list[str] = []
    with pytest.raises(LocalityError, match=r"window \+-1 the worst held-out unit-centre error"):
        build_table(MODEL, evaluator, window=1, tolerance=1e-4, heldout=10, on_progress=lines.append)
    # a window +-1 is off by more than 0.1 um on the very first held-out design: one round (one design, serial)
    refuted = [ln for ln in lines if ln.startswith("window +-1: worst held-out")]
    assert len(refuted) == 1 and "over 1 held-out design(s) (stopped: above 0.0001 mm already)" in refuted[0]
    assert evaluator.solves == len(covering_designs(9, 1)) + 1
    solved = set(evaluator.cache.designs(MODEL.fingerprint()))
    assert tests[0] in solved and solved.isdisjoint(tests[1:])  # none of the other held-out designs was solved


def test_the_plan_counts_the_fewest_solves_of_an_early_validation() -> None:
    plan = build_plan(MODEL, heldout=20, first_window=2, early=True)
    assert plan.windows == (2, 3)  # from the first window on
    assert plan.fewest == len(covering_designs(9, 2)) + MIN_HELDOUT
    assert f"({MIN_HELDOUT} if they are clearly within)" in plan.text()
    strict = build_plan(MODEL, heldout=20, first_window=2)
    assert strict.fewest == strict.solves[0] and "clearly within" not in strict.text()

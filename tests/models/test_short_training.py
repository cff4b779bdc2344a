"""Short training designs: the end windows learnt from actuators of 2w units predict full-length designs alike."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import build_table, prediction_errors
from pneumorph.models.chain.windows import covering_designs, end_designs, window_codes
from pneumorph.models.fe import RampSpec, Reduced2D


def test_end_designs_show_every_end_window_of_longer_actuators() -> None:
    """Every window holding the base or the tip of 12-unit designs occurs in the 2w-unit designs (or its mirror)."""
    w = 2
    short = end_designs(w)
    assert len(short) == 2 ** (2 * w) // 2 and all(len(d) == 2 * w for d in short)
    bits = np.array([[int(c) for c in d] for d in short], dtype=np.uint8)
    seen = set(window_codes(bits, w).ravel().tolist()) | set(window_codes(1 - bits, w).ravel().tolist())
    every = ((np.arange(2**12)[:, None] >> np.arange(12)[None, ::-1]) & 1).astype(np.uint8)
    codes = window_codes(every, w)
    ends = np.concatenate([codes[:, : w + 1], codes[:, 12 - w + 1 :]], axis=1)
    assert set(ends.ravel().tolist()) <= seen


@pytest.mark.slow
def test_a_table_from_short_designs_predicts_full_length_designs_as_well() -> None:
    """2D FE, 12 units, window +-2: 68 unit solves instead of 96, the same held-out error on 12-unit designs."""
    model = Reduced2D(12, UnitSpec(element_size=3.0), RampSpec(pressure=0.025))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    full = build_table(model, evaluator, window=2, heldout=8)
    short = build_table(model, evaluator, window=2, heldout=8, short=True)
    assert short.training == tuple(covering_designs(12, 2, short=True))
    assert {len(d) for d in short.training} == {4, 12}
    assert sum(map(len, short.training)) < 0.75 * sum(map(len, full.training))
    assert np.array_equal(short.codes, full.codes)  # the same windows, learnt from other actuators
    assert short.validation["designs"] == full.validation["designs"]  # held out: 12-unit designs, as always
    worst_full = max(full.validation["centre_worst_mm"])
    worst_short = max(short.validation["centre_worst_mm"])
    assert worst_short <= 1.25 * worst_full + 0.005
    assert worst_short < 0.2
    # predictions of the two tables agree on the held-out designs within their errors
    responses = [o.response for o in evaluator.evaluate_many(model, full.validation["designs"])]
    again = prediction_errors(short, responses)
    assert np.allclose(again["centre_worst_mm"], short.validation["centre_worst_mm"], rtol=0, atol=1e-12)

"""Chain tables of split terms (every run of 2w units within +-(w + 1)): exact on a chain of such sums once the
training fixes every window's sum, refused or wrong before; written as their terms; on the FE model as close as
the far-field layout."""

from __future__ import annotations

import json

import numpy as np
import pytest

from pneumorph.errors import ChainTableError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import build_table, fit_table
from pneumorph.models.chain.model import ChainTable
from pneumorph.models.chain.terms import end_terms, far_terms, terms_from_dict
from pneumorph.models.chain.training import FIXED, split_designs, unfixed_error
from pneumorph.models.chain.windows import cover_rows, design_pool
from pneumorph.models.fe import RampSpec, Reduced2D
from tests.models.test_far_terms import _law, _response, worst_error

SOURCE = {"fidelity": "toy", "key": "additive"}


def test_the_split_layout_is_every_run_of_2w_units() -> None:
    for w in (1, 2, 3):
        terms = far_terms(w, "split")
        assert all(hi - lo + 1 == 2 * w for lo, hi in terms)
        assert terms[0][0] == -(w + 1) and terms[-1][1] == w + 1 and len(terms) == 4
    assert end_terms(2, "split") == ((-2, 3),) and end_terms(2, "far") == far_terms(2)


@pytest.mark.parametrize(("w", "short"), [(1, False), (2, False), (2, True)])
def test_split_terms_are_exact_on_a_chain_of_such_sums(w: int, short: bool) -> None:
    """Elements that are sums of split terms (and an end turn of its own term) are fitted from split_designs to
    1e-9 mm at other lengths too."""
    law = _law(seed=10 + w, w=w, layout="split")
    n = 2 * w + 7
    train = split_designs(n, w, short=short)
    assert unfixed_error(train, w, (), (), n) < FIXED
    responses = [_response(law, d, w) for d in train]
    split = fit_table(responses, w, {**SOURCE, "n_units": n}, far="split")
    assert split.window == w + 1 and split.terms["layout"] == "split"
    assert worst_error(split, law, w, n) < 1e-9


@pytest.mark.slow
def test_a_cover_of_the_keys_alone_leaves_windows_unfixed() -> None:
    """Two unit types, w = 2: the greedy cover shows every key but not enough chords to tell the four terms apart.
    The check says so without a solve, and a fit to the cover is off at a held-out design by the law's own size;
    split_designs adds random designs until every window is fixed, and its fit is exact."""
    alphabet, n, w = ("a", "r"), 11, 2
    rng = np.random.default_rng(0)
    pool = design_pool(n, 2, (), rng, 4**4)
    from pneumorph.models.chain.training import _split_keys

    cover = split_designs(n, w, alphabet)[: len(cover_rows(_split_keys(pool, w, 2, (), False), rng))]
    assert unfixed_error(cover, w, alphabet, (), n) > 0.1
    full = split_designs(n, w, alphabet)
    assert len(full) > len(cover) and unfixed_error(full, w, alphabet, (), n) < FIXED
    assert unfixed_error(full[:-8], w, alphabet, (), n) > FIXED  # the fewest batches: one batch fewer is not enough


def test_a_table_of_split_terms_is_written_as_its_terms(tmp_path) -> None:
    law = _law(seed=4, w=2, layout="split")
    train = [_response(law, d, 2) for d in split_designs(11, 2)]
    table = fit_table(train, 2, {**SOURCE, "n_units": 11}, far="split")
    path = table.save(tmp_path / "split.json")
    data = json.loads(path.read_text())
    assert data["terms"]["layout"] == "split"
    assert [t["units"] for t in data["terms"]["chord"]] == [[-3, 0], [-2, 1], [-1, 2], [0, 3]]
    assert [t["units"] for t in data["terms"]["end"]] == [[-2, 3]]
    back = ChainTable.load(path)
    assert back.fingerprint() == table.fingerprint() and back.terms["layout"] == "split"
    data["terms"]["layout"] = "far"  # the units are not those of the far-field layout
    with pytest.raises(ChainTableError, match="not those of"):
        terms_from_dict(data["terms"])
    data["terms"]["layout"] = "diagonal"
    with pytest.raises(ChainTableError, match="unknown layout"):
        terms_from_dict(data["terms"])


@pytest.mark.slow
def test_split_terms_on_the_2d_model_are_as_close_as_far_field_terms() -> None:
    """2D FE (coarse mesh, 12 units, 8 held-out designs): window +-2 in split terms against far-field terms, both
    a table of +-3 (the split training: 4 designs of 12 units)."""
    model = Reduced2D(12, UnitSpec(element_size=3.0), RampSpec(pressure=0.025))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    split = build_table(model, evaluator, window=2, far="split", heldout=8)
    far = build_table(model, evaluator, window=2, far=True, heldout=8)
    assert split.metadata["fit"] == "window +-3 from 4-unit terms" and split.window == 3
    assert split.training == tuple(split_designs(12, 2))
    assert split.validation["designs"] == far.validation["designs"]
    worst_split, worst_far = max(split.validation["centre_worst_mm"]), max(far.validation["centre_worst_mm"])
    assert worst_split <= 2 * worst_far + 0.005, (worst_split, worst_far)
    assert worst_split < 0.05

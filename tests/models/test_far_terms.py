"""Chain tables with far-field terms: exact on a chain whose elements are such sums, and on the FE model as
close as the wider window's table from fewer unit solves."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from pneumorph.errors import ChainTableError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import build_table, fit_table
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.tablefile import TABLE_FORMAT, TERMS_FORMAT
from pneumorph.models.chain.terms import end_terms, far_designs, far_terms
from pneumorph.models.chain.validation import heldout_designs
from pneumorph.models.chain.windows import design_array, window_symbols
from pneumorph.models.fe import RampSpec, Reduced2D
from pneumorph.models.response import Response

LEVELS = 3
PITCH = 10.0
HEIGHT = (5.0, 2.0)  # undeformed centre height of a unit in orientation 0 and 1


def _law(seed: int, w: int, layout: str = "far") -> dict[tuple[int, int] | tuple[str, int, int], dict[int, np.ndarray]]:
    """Random additive terms, turned over with their window: turns change sign, lengths do not. With ``split``,
    the end turn's own terms (keys ``("end", lo, hi)``) after the chords'."""
    rng = np.random.default_rng(seed)
    law: dict = {units: _table(rng, units[1] - units[0] + 1) for units in far_terms(w, layout)}
    if layout == "split":
        law.update({("end", lo, hi): _table(rng, hi - lo + 1) for lo, hi in end_terms(w, layout)})
    return law


def _table(rng: np.random.Generator, width: int) -> dict[int, np.ndarray]:
    """One term's values per key of ``width`` symbols, mirror-consistent."""
    table: dict[int, np.ndarray] = {}
    for code in range(4**width):
        digits = [(code // 4**t) % 4 for t in range(width)]
        mirror = sum((d ^ 1 if d < 2 else d) * 4**t for t, d in enumerate(digits))
        if mirror in table:
            turn, length = np.split(table[mirror], 2)
            table[code] = np.concatenate([-turn, length])
        elif mirror == code:  # only base and tip symbols: its own mirror, so no turn
            table[code] = np.concatenate([np.zeros(LEVELS), rng.uniform(-0.2, 0.2, LEVELS)])
        else:
            table[code] = np.concatenate([rng.uniform(-0.08, 0.08, LEVELS), rng.uniform(-0.2, 0.2, LEVELS)])
    return table


def _elements(law: dict, design: str, w: int) -> np.ndarray:
    """Per chord (and the end, last row) the law's turns and lengths, shape (n + 2, 2 levels)."""
    width = w + 1
    sym = window_symbols(design_array(design), width)[0]  # (n + 1, 2 width + 1)
    out = np.zeros((len(sym) + 1, 2 * LEVELS))
    own_end = any(len(units) == 3 for units in law)
    for units, table in law.items():
        lo, hi = units[-2:]
        cols = np.arange(lo + width, hi + width + 1)
        codes = sym[:, cols] @ (4 ** np.arange(len(cols)))
        values = np.array([table[int(c)] for c in codes])
        if len(units) == 3:  # a term of the end turn only
            out[-1] += values[-1]
            continue
        out[:-1] += values
        if not own_end:
            out[-1] += values[-1] * 0.5  # the end turn: another sum of the same terms at the last chord
    out[:-1, LEVELS:] += PITCH
    return out


def _response(law: dict, design: str, w: int) -> Response:
    n = len(design)
    bits = [int(c) for c in design]
    ref = np.array([[(i + 0.5) * PITCH, HEIGHT[b]] for i, b in enumerate(bits)])
    ref_tip = np.array([n * PITCH, 3.5])
    e = _elements(law, design, w)
    turn, length = e[:-1, :LEVELS].T, e[:-1, LEVELS:].T  # (levels, n + 1)
    angle = np.cumsum(turn, axis=1)
    steps = np.stack([length * np.cos(angle), length * np.sin(angle)], -1)
    points = np.array([0.0, ref[0, 1]]) + np.cumsum(steps, axis=1)  # centres 1..n, then the tip
    curl = np.degrees(angle[:, -1] + e[-1, :LEVELS])
    return Response(design, np.linspace(0.01, 0.03, LEVELS), points[:, :n], ref, points[:, n], ref_tip, curl,
                    converged=True, reached=0.03)


def worst_error(table: ChainTable, law: dict, w: int, n: int, centres_only: bool = False) -> float:
    """The worst difference of the table's chain from the law's, centres, tip and curl, over 6 random designs of each
    of 2w + 3, n and n + 6 units."""
    worst = 0.0
    for length in (2 * w + 3, n, n + 6):
        for design in heldout_designs(length, 6, seed=3):
            truth = _response(law, design, w)
            got = ChainModel(table, length).evaluate(design)
            parts = [(got.centres, truth.centres)] + ([] if centres_only else [(got.tip, truth.tip),
                                                                              (got.curl, truth.curl)])
            worst = max(worst, *(float(np.abs(a - b).max()) for a, b in parts))
    return worst


@pytest.mark.parametrize("w", [1, 2])
def test_far_terms_are_exact_on_a_chain_of_such_sums(w: int) -> None:
    """Elements that are a window's term plus the two far-field terms are fitted exactly from far_designs:
    held-out designs of other lengths to 1e-9 mm (the plain table of the same training is not)."""
    law = _law(seed=w, w=w)
    n = 2 * w + 7
    train = [_response(law, d, w) for d in far_designs(n, w)]
    source = {"fidelity": "toy", "key": "additive", "n_units": n}
    far = fit_table(train, w, source, far=True)
    plain = fit_table(train, w, source)
    assert far.window == w + 1 and plain.window == w
    assert worst_error(far, law, w, n) < 1e-9
    assert worst_error(plain, law, w, n, centres_only=True) > 1e-3


def test_a_table_with_far_field_terms_is_written_as_its_terms(tmp_path) -> None:
    """Its file holds the terms (format 3), and reading it writes the same table out (same fingerprint);
    entries changed afterwards are written window by window; an edited term is refused."""
    law = _law(seed=2, w=2)
    train = [_response(law, d, 2) for d in far_designs(11, 2)]
    far = fit_table(train, 2, {"fidelity": "toy", "key": "additive", "n_units": 11}, far=True)
    path = far.save(tmp_path / "far.json")
    data = json.loads(path.read_text())
    assert data["format"] == TERMS_FORMAT and "windows" not in data
    assert [t["units"] for t in data["terms"]["chord"]] == [[-2, 2], [0, 3], [-3, 0]]
    back = ChainTable.load(path)
    assert back.fingerprint() == far.fingerprint() and back.terms["digest"] == far.terms["digest"]
    assert np.array_equal(back.codes, far.codes) and np.array_equal(back.turn, far.turn)
    moved = replace(far, turn=far.turn * 1.01)
    assert moved.to_dict()["format"] == TABLE_FORMAT and "terms" not in moved.to_dict()
    data["terms"]["chord"][0]["values"][0][0] += 1e-6
    path.write_text(json.dumps(data))
    with pytest.raises(ChainTableError, match="fingerprint"):
        ChainTable.load(path)


def test_a_key_no_training_design_shows_is_refused() -> None:
    law = _law(seed=1, w=1)
    train = [_response(law, d, 1) for d in far_designs(9, 1) if len(d) == 9]  # without the end designs
    with pytest.raises(ChainTableError, match="show no"):
        fit_table(train, 1, {"fidelity": "toy", "key": "additive", "n_units": 9}, far=True)


@pytest.mark.slow
def test_far_terms_on_the_2d_model_match_the_wider_window_from_fewer_unit_solves() -> None:
    """2D FE (coarse mesh, 12 units, 8 held-out designs): window +-1 with far-field terms (a table of window +-2)
    against the table of window +-2, both built from short training designs."""
    model = Reduced2D(12, UnitSpec(element_size=3.0), RampSpec(pressure=0.025))
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    far = build_table(model, evaluator, first_window=2, max_window=2, far=True, heldout=8)
    wide = build_table(model, evaluator, window=2, heldout=8, short=True)
    assert far.metadata["fit"] == "window +-1 with far-field terms (+-2)" and far.window == 2
    assert far.training == tuple(far_designs(12, 1))
    assert sum(map(len, far.training)) < 0.75 * sum(map(len, wide.training))
    assert far.validation["designs"] == wide.validation["designs"]
    worst_far, worst_wide = max(far.validation["centre_worst_mm"]), max(wide.validation["centre_worst_mm"])
    assert worst_far <= 2 * worst_wide + 0.005, (worst_far, worst_wide)


@pytest.mark.parametrize(("w", "far", "plain"), [(1, "5d51d6257643f1d9", "8eddc44a541b039e"),
                                                 (2, "ca37ec03af43b844", "2ff74b63a22e8e51")])
def test_planar_tables_are_fitted_bit_for_bit_as_before_the_chain_in_space(w: int, far: str, plain: str) -> None:
    """The fingerprints (every entry's bytes) of the two fits of the same training, recorded with the code before
    tables learnt elements in space: a planar fit has no such columns and must not change by a bit."""
    law = _law(seed=w, w=w)
    n = 2 * w + 7
    train = [_response(law, d, w) for d in far_designs(n, w)]
    source = {"fidelity": "toy", "key": "additive", "n_units": n}
    assert fit_table(train, w, source, far=True).fingerprint() == far
    assert fit_table(train, w, source).fingerprint() == plain

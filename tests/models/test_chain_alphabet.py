"""The chain model over a unit library: windows of types and orientations, tables per type."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import ChainTableError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.models.chain.fit import build_table, fit_table
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import shipped_path
from pneumorph.models.chain.windows import (
    covering_designs,
    design_array,
    design_strings,
    mirror_codes,
    possible_codes,
    window_codes,
)
from pneumorph.models.fe import RampSpec, Reduced2D

RAMP = RampSpec(pressure=0.02)


def coarse(symbols: str) -> UnitLibrary:
    """Built-in unit types meshed coarsely (3 mm elements; the extending unit does not join at that size)."""
    lib = builtin_library()
    return UnitLibrary(tuple(symbols), tuple(replace(lib[s], element_size=3.0) for s in symbols), name="coarse")


@pytest.fixture(scope="module")
def mixed() -> tuple[Reduced2D, ChainTable, CachedEvaluator]:
    """A table of the real 2D model over bending and near-rigid units (coarse mesh, 20 kPa), 7-unit designs."""
    model = Reduced2D(7, library=coarse("ar"), ramp_spec=RAMP)
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    return model, build_table(model, evaluator, heldout=6), evaluator


@pytest.mark.parametrize("n, w, k", [(5, 1, 2), pytest.param(6, 1, 3, marks=pytest.mark.slow), (6, 2, 2)])
def test_the_covering_set_over_an_alphabet_shows_every_window(n: int, w: int, k: int) -> None:
    alphabet = tuple("aers"[:k])
    designs = covering_designs(n, w, n_types=k, alphabet=alphabet)
    assert all(len(d) == n and set(d.lower()) <= set(alphabet) for d in designs)
    codes = window_codes(design_array(designs, alphabet=alphabet), w, n_types=k)
    seen = set(codes.ravel()) | set(mirror_codes(codes, w, k).ravel())
    assert seen >= set(possible_codes(n, w, k).tolist())
    assert covering_designs(n, w, n_types=k, alphabet=alphabet) == designs  # reproducible
    # the base windows "<..< u1 .. u(w+1)" occur once per design: (2k)^(w+1) / 2 designs at least
    assert len(designs) >= (2 * k) ** (w + 1) // 2


def test_codes_of_one_type_are_todays_and_the_alphabet_round_trips() -> None:
    assert possible_codes(7, 2, 1).tolist() == possible_codes(7, 2).tolist()
    bits = design_array(["0110100", "1110001"])
    assert np.array_equal(window_codes(bits, 2, n_types=1), window_codes(bits, 2))
    texts = ["aRrAa", "RRaar"]
    codes = design_array(texts, alphabet=("a", "r"))
    assert design_strings(codes, ("a", "r")) == texts
    assert design_strings(design_array("01r", alphabet=("a", "r")), ("a", "r")) == ["aAr"]
    c = window_codes(codes, 1, n_types=2)
    assert np.array_equal(mirror_codes(mirror_codes(c, 1, 2), 1, 2), c)
    assert np.array_equal(mirror_codes(c, 1, 2), window_codes(design_array(["ArRaA", "rrAAR"], alphabet=("a", "r")),
                                                              1, n_types=2))


def test_the_table_over_an_alphabet_reproduces_held_out_designs_per_type(mixed) -> None:
    _model, table, _ = mixed
    assert table.alphabet == ("a", "r") and table.window == 1 and len(table.training) >= 8
    v = table.validation
    assert len(v["designs"]) == 6 and all(set(d.lower()) <= {"a", "r"} for d in v["designs"])
    assert max(v["centre_worst_mm"]) <= 0.2
    per = v["per_type"]
    assert per["a"]["centres"] + per["r"]["centres"] == 6 * 7
    for symbol in "ar":
        assert per[symbol]["centres"] > 0
        assert max(per[symbol]["centre_worst_mm"]) <= max(v["centre_worst_mm"]) + 1e-12
    assert max(max(per[s]["centre_worst_mm"]) for s in "ar") == pytest.approx(max(v["centre_worst_mm"]))


def test_the_table_over_an_alphabet_serves_other_lengths(mixed) -> None:
    model, table, evaluator = mixed
    longer = model.with_units(9)
    designs = ["aRraAaRrA", "rrAaRaaAr"]
    for outcome in evaluator.evaluate_many(longer, designs):
        fe = outcome.response
        chain = ChainModel(table, 9).evaluate(fe.orientation)
        assert chain.orientation == fe.orientation
        assert np.allclose(chain.reference_centres, fe.reference_centres, atol=1e-9)
        assert np.allclose(chain.reference_tip, fe.reference_tip, atol=1e-9)
        assert np.abs(chain.centres - fe.centres).max() < 0.2
        assert np.abs(chain.curl - fe.curl).max() < 0.5


def test_mixed_pitches_are_placed_like_the_fe_mesh() -> None:
    lib = coarse("as")
    model = Reduced2D(5, library=lib, ramp_spec=RAMP)
    responses = [model.evaluate(d) for d in ("aSsAa", "sAaSs")]
    table = fit_table(responses, 1, {"fidelity": "2d", "key": "k", "n_units": 5}, library=lib)
    assert table.type_pitch == (10.5, 7.0)
    for r in responses:  # the training designs themselves: centres, tip and curl as solved
        chain = ChainModel(table, 5).evaluate(r.orientation)
        assert np.allclose(chain.reference_centres, r.reference_centres, atol=1e-9)
        assert np.allclose(chain.reference_tip, r.reference_tip, atol=1e-9)


def test_the_table_over_an_alphabet_is_saved_and_read(mixed, tmp_path: Path) -> None:
    _model, table, _ = mixed
    path = table.save(tmp_path / "t.json")
    data = json.loads(path.read_text())
    assert data["format"] == 2 and data["alphabet"] == ["a", "r"] and data["windows"][0] == "aaa"
    assert any(w.startswith("<") for w in data["windows"]) and any(w.endswith(">") for w in data["windows"])
    assert data["types"]["r"]["pitch_mm"] == 10.5
    again = ChainTable.load(path)
    assert again.fingerprint() == table.fingerprint() and again.alphabet == ("a", "r")
    bits = again.designs(["aRraAaR", "rrrrrrr"])
    assert np.array_equal(again.predict(bits)[0], table.predict(bits)[0])
    # a format-1 reader's layout with letters, or a repeated type, is refused
    bad = dict(data, format=1)
    with pytest.raises(ChainTableError, match="bad window"):
        ChainTable.from_dict(bad)
    with pytest.raises(ChainTableError, match="distinct symbols"):
        ChainTable.from_dict(dict(data, alphabet=["a", "a"]))


def test_a_unit_type_without_a_table_is_named(mixed) -> None:
    _model, table, _ = mixed
    with pytest.raises(ChainTableError, match="unit type 'e' has no table: the chain table covers the unit types a, r"):
        ChainModel(table, 7).evaluate("aaEaaaa")
    shipped = ChainTable.load(shipped_path("2d"))
    with pytest.raises(ChainTableError, match="unit type 'e' has no table: the chain table is of one unit type"):
        ChainModel(shipped, 15).evaluate("000000e00000000")
    # 0/1 designs are the first type
    assert ChainModel(table, 7).evaluate("0101010").orientation == "aAaAaAa"

"""The unit-chain model: windows, covering sets, tables, shipped tables and bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.design.search.exhaustive import mirror_response
from pneumorph.errors import ChainTableError, LocalityError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.orientation import mirror
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.model import (
    ChainModel,
    ChainTable,
    check_source,
    covering_designs,
    design_array,
    mirror_codes,
    possible_codes,
    window_codes,
)
from pneumorph.models.chain.sources import shipped_path
from pneumorph.models.factory import make_model
from pneumorph.models.fe import RampSpec, Reduced2D

COARSE = UnitSpec(element_size=3.0)
RAMP = RampSpec(pressure=0.02)


@pytest.fixture(scope="module")
def small() -> tuple[Reduced2D, ChainTable, CachedEvaluator]:
    """A table of the real 2D model (coarse mesh, 20 kPa) fitted on 7-unit designs."""
    model = Reduced2D(7, COARSE, RAMP)
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    return model, build_table(model, evaluator, heldout=6), evaluator


@pytest.mark.parametrize("n, w", [(5, 1), (7, 2), (9, 2), (9, 3)])
def test_the_covering_set_shows_every_window_of_the_actuator(n: int, w: int) -> None:
    designs = covering_designs(n, w)
    codes = window_codes(design_array(designs), w)
    seen = set(codes.ravel()) | set(mirror_codes(codes, w).ravel())
    assert seen >= set(possible_codes(n, w).tolist())
    assert covering_designs(n, w) == designs  # reproducible
    # without the mirror a covering set needs about twice as many designs
    assert len(covering_designs(n, w, mirror=False)) >= len(designs)


def test_a_base_window_needs_one_design_per_pattern_of_its_units() -> None:
    # the base windows "B..B u1 .. u_(w+1)" are one per design: 2^(w+1) of them, half up to the mirror
    assert len(covering_designs(15, 2)) == 8
    assert len(covering_designs(15, 1)) == 2


def test_the_table_reproduces_held_out_designs_of_the_real_2d_model(small) -> None:
    _model, table, _ = small
    v = table.validation
    assert table.window >= 1 and len(v["designs"]) == 6
    assert max(v["centre_worst_mm"]) <= 0.2
    # errors grow with pressure: the first level is far better than the last
    assert v["centre_worst_mm"][0] < v["centre_worst_mm"][-1]
    assert table.source["key"] and table.source["n_units"] == 7


def test_the_table_serves_other_lengths(small) -> None:
    _model, table, evaluator = small
    longer = Reduced2D(10, COARSE, RAMP)
    designs = ["0110100111", "1110001010"]
    for outcome in evaluator.evaluate_many(longer, designs):
        fe = outcome.response
        chain = ChainModel(table, 10).evaluate(fe.orientation)
        assert np.allclose(chain.reference_centres, fe.reference_centres, atol=1e-9)
        assert np.allclose(chain.reference_tip, fe.reference_tip, atol=1e-9)
        assert np.abs(chain.centres - fe.centres).max() < 0.2
        assert np.abs(chain.curl - fe.curl).max() < 0.5


def test_a_mirrored_design_gives_the_mirrored_response(small) -> None:
    _, table, _ = small
    chain = ChainModel(table, 9)
    a, b = chain.evaluate("001101110"), chain.evaluate(mirror("001101110"))
    m = mirror_response(a)
    assert np.allclose(m.centres, b.centres, atol=1e-9) and np.allclose(m.curl, b.curl, atol=1e-9)


def test_a_table_survives_its_file_and_refuses_tampering(small, tmp_path: Path) -> None:
    _model, table, _ = small
    path = table.save(tmp_path / "t.json")
    again = ChainTable.load(path)
    assert again.fingerprint() == table.fingerprint()
    bits = design_array(["0101101"])
    assert np.array_equal(again.predict(bits)[0], table.predict(bits)[0])
    data = json.loads(path.read_text())
    data["turn_rad"][3][5] += 0.01
    (tmp_path / "edited.json").write_text(json.dumps(data))
    with pytest.raises(ChainTableError, match="fingerprint"):
        ChainTable.load(tmp_path / "edited.json")
    (tmp_path / "cut.json").write_text(path.read_text()[:500])
    with pytest.raises(ChainTableError, match=r"cut.json: not valid JSON"):
        ChainTable.load(tmp_path / "cut.json")
    del data["length_mm"]
    (tmp_path / "broken.json").write_text(json.dumps(data))
    with pytest.raises(ChainTableError, match="damaged"):
        ChainTable.load(tmp_path / "broken.json")
    (tmp_path / "binary.json").write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff")
    with pytest.raises(ChainTableError):
        ChainTable.load(tmp_path / "binary.json")


def test_a_table_read_again_is_the_one_read_unless_its_file_changed(small, tmp_path: Path) -> None:
    """The last table read is kept (a run checks a given table, then serves it); a rewritten file is read anew."""
    _model, table, _ = small
    path = table.save(tmp_path / "t.json")
    first = ChainTable.load(path)
    assert ChainTable.load(path) is first
    data = json.loads(path.read_text())
    data["turn_rad"][3][5] += 0.01
    path.write_text(json.dumps(data))
    with pytest.raises(ChainTableError, match="fingerprint"):
        ChainTable.load(path)


def test_a_table_of_another_model_or_too_short_an_actuator_is_refused(small) -> None:
    _model, table, _ = small
    check_source(table, Reduced2D(12, COARSE, RAMP))  # same unit, model and ramp: any length
    with pytest.raises(ChainTableError, match="another model"):
        check_source(table, Reduced2D(7, UnitSpec(element_size=3.0, wall=1.4), RAMP))
    with pytest.raises(ChainTableError, match="another model"):
        check_source(table, Reduced2D(7, COARSE, RampSpec(pressure=0.03)))
    with pytest.raises(ChainTableError, match="needs at least"):
        ChainModel(table, 2 * table.window)


def test_gravity_is_refused() -> None:
    model = Reduced2D(5, COARSE, RAMP, gravity="hanging")
    with pytest.raises(LocalityError, match="gravity"):
        build_table(model, SerialEvaluator())


def test_a_window_wider_than_the_training_actuator_is_refused() -> None:
    with pytest.raises(ChainTableError, match="at least 7 units"):
        build_table(Reduced2D(5, COARSE, RAMP), SerialEvaluator(), window=3)


@pytest.mark.parametrize("fidelity", ["2d", "3d"])
def test_the_shipped_tables_fit_the_default_models_and_their_validation_holds(fidelity: str) -> None:
    table = ChainTable.load(shipped_path(fidelity))
    model = make_model(15, {"fidelity": fidelity})
    check_source(table, model)  # the shipped table belongs to the model the CLI builds
    v = table.validation
    assert len(v["designs"]) == 20 and not set(v["designs"]) & set(table.training)
    assert max(v["centre_worst_mm"]) <= 0.2
    assert v["centre_mean_mm"][-1] < 0.05
    assert np.allclose(table.pressures, model.pressures())

"""The size check before any solve: a chain table's centreline carrying rigid units spans what the FE
model's solved shape spans, and a scan typed with another unit count is refused before the first solve."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.correlation import ModelShape, model_shape
from pneumorph.geometry.unit import UnitSpec
from pneumorph.identify import ParameterSet, chain_shape, chain_shapes, precheck_designs
from pneumorph.identify.match import _size
from pneumorph.models.factory import make_model
from tests.identify.conftest import synthetic


def _cloud(shape: ModelShape) -> np.ndarray:
    """The points a scan is compared with."""
    return shape.surface if len(shape.surface) else shape.samples


@pytest.mark.parametrize("design", ["001111010001001", "0101010101", "11111111"])
def test_the_chain_shape_spans_what_the_solved_shape_spans(design: str) -> None:
    """2D, nominal unit, 36 kPa (a level of the shipped table): within 2.5 % (walls do not balloon in it)."""
    model = make_model(len(design), {"fidelity": "2d", "pressure_kpa": 36})
    predicted = chain_shape(model, design)
    assert predicted is not None
    solved = model_shape(model.solve(design))
    ratio = _size(_cloud(predicted)) / _size(_cloud(solved))
    assert 0.975 <= ratio <= 1.0, ratio
    assert np.allclose(predicted.centres, solved.centres, atol=0.1)  # the shipped 2D table's accuracy


def test_no_chain_shape_without_a_table_level_at_the_pressure() -> None:
    assert chain_shape(make_model(15, {"fidelity": "2d", "pressure_kpa": 37}), "0" * 15) is None  # between levels
    assert chain_shape(make_model(4, {"fidelity": "2d", "pressure_kpa": 36}), "0110") is None  # shorter than 2w+1
    assert chain_shape(make_model(9, {"fidelity": "2d", "pressure_kpa": 36, "unit": {"element_size": 3.0}}),
                       "0" * 9) is None  # another model: no table


@pytest.mark.parametrize("design", ["001111010001001", "0101010101", "11111111"])
@pytest.mark.parametrize("kpa", [20, 37])
def test_between_two_levels_the_solved_size_lies_between_the_chain_shapes(design: str, kpa: float) -> None:
    """2D, nominal unit, a pressure between two levels of the shipped table: the solved shape spans between the
    chain shapes at the two levels, up to the 2.5 % the chain shape lacks (measured: 0.53 to 2.7 % above the
    smaller, at most 1.75 % above the larger)."""
    shapes = chain_shapes({"fidelity": "2d", "pressure_kpa": kpa}, design)
    assert len(shapes) == 2
    sizes = [_size(_cloud(s)) for s in shapes]
    solved = _size(_cloud(model_shape(make_model(len(design), {"fidelity": "2d", "pressure_kpa": kpa}).solve(design))))
    assert min(sizes) <= solved <= 1.025 * max(sizes)
    assert chain_shapes({"fidelity": "2d", "pressure_kpa": 3}, design) == []  # below the table's first level


def test_precheck_counts_the_scans_it_could_check(coarse: ParameterSet) -> None:
    params = ParameterSet(UnitSpec())
    right = synthetic(params, params.nominal, "0101010101", "2d", seed=1)
    assert precheck_designs([right], params, {"fidelity": "2d"}) == 1
    other = synthetic(coarse, coarse.nominal, "0110", "2d", seed=1)  # no table: checked after its solve
    assert precheck_designs([other], coarse, {"fidelity": "2d"}) == 0


@pytest.mark.parametrize(("kpa", "said"), [(36, "by its chain table"), (37, "levels around it")])
def test_another_unit_count_is_refused_before_any_solve(kpa: float, said: str, tmp_path: Path,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    """A trace of a 15-unit actuator given as a 10-unit design: one line, exit 2, no cache opened; at a level of
    the table (36 kPa) and between two (37 kPa: the chain shapes at 36 and 40.5 kPa)."""
    params = ParameterSet(UnitSpec())
    obs = synthetic(params, params.nominal, "001111010001001", "2d", seed=3, pressure_kpa=kpa)
    trace = tmp_path / "trace.csv"
    np.savetxt(trace, obs.scan.points, delimiter=",", header="x,y", comments="")
    cache, out = tmp_path / "c.sqlite", tmp_path / "out"
    code = main(["identify", str(trace), "--design", "0011110100", "--pressure", str(kpa), "--model", "2d",
                 "--executor", "serial", "--cache", str(cache), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and said in err[0] and "is it the design scanned" in err[0]
    assert not cache.exists() and not out.exists()

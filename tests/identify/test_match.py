"""A design one or two units off its scan is refused by its units: before any solve where a chain table
predicts its shape, after the nominal solve where none does; the right design, off the nominal model by a
cast's changes, passes."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.correlation import Scan, correlate
from pneumorph.errors import ScanError
from pneumorph.execution import SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.identify import Observation, ParameterSet, ScanSpec, identify, precheck_designs
from pneumorph.identify.extent import chain_shape
from pneumorph.identify.match import MIN_END_SHARE, check_coverage, coverage
from pneumorph.models.factory import make_model
from tests.identify.conftest import synthetic

DESIGN = "001111010001001"
CAST = [0.06, 0.0, 0.0, 0.08, 0.0]  # bulk x1.06, wall +0.08 mm: what a cast may be off by


@pytest.fixture(scope="module")
def cast_2d() -> Observation:
    params = ParameterSet(UnitSpec())
    return synthetic(params, params.nominal + np.array(CAST), DESIGN, "2d", seed=2, points=1500)


@pytest.mark.slow
def test_the_right_design_shows_every_unit(cast_2d: Observation) -> None:
    """Against the chain's shape: no point beyond half a pitch, every unit's share of the scan within 0.2 of
    its share of the model (measured 0.86-1.16 over five casts, docs/identify.md)."""
    shape = chain_shape(make_model(15, {"fidelity": "2d", "pressure_kpa": 36}), DESIGN)
    assert shape is not None
    c = coverage(correlate(cast_2d.scan, shape).aligned, shape)
    assert c.beyond == 0.0 and np.all(np.abs(c.shares - 1) < 0.2) and c.problem() == ""
    assert precheck_designs([cast_2d], ParameterSet(UnitSpec()), {"fidelity": "2d"}) == 1
    # a photo trace against the 3D model: compared with its outline
    assert precheck_designs([cast_2d], ParameterSet(UnitSpec()), {"fidelity": "3d"}) == 1


@pytest.mark.parametrize(("design", "said"), [(DESIGN[:-1], "more units than the design"),
                                              (DESIGN[1:], "more units than the design"),
                                              (DESIGN + "0", "hardly reaches its last unit"),
                                              ("1" + DESIGN, "hardly reaches its first unit")])
def test_a_design_one_unit_off_is_refused_before_any_solve(cast_2d: Observation, design: str, said: str,
                                                           tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """2D trace of a cast 15-unit actuator given with one unit less or more, at either end: one line, exit 2,
    no cache opened, nothing written."""
    trace = tmp_path / "trace.csv"
    np.savetxt(trace, cast_2d.scan.points, delimiter=",", header="x,y", comments="")
    cache, out = tmp_path / "c.sqlite", tmp_path / "out"
    code = main(["identify", str(trace), "--design", design, "--pressure", "36", "--model", "2d",
                 "--executor", "serial", "--cache", str(cache), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "by its chain table" in err[0] and said in err[0], err
    assert not cache.exists() and not out.exists()


@pytest.mark.slow
def test_a_3d_scan_one_unit_off_is_refused_before_any_solve() -> None:
    """3D surface of a cast 8-unit actuator (the shipped 3D table serves 7 units or more): its own design passes,
    one unit more or less is refused, each by what it lacks."""
    params = ParameterSet(UnitSpec())
    cast = synthetic(params, params.nominal + np.array(CAST), "00111100", "3d", seed=4, points=1500)
    assert precheck_designs([cast], params, {"fidelity": "3d"}) == 1
    for design, said in (("001111000", "hardly reaches its last unit"), ("0011110", "more units than the design")):
        with pytest.raises(ScanError, match=said):
            precheck_designs([Observation(replace(cast.spec, design=design), cast.scan)], params, {"fidelity": "3d"})


def test_without_a_table_the_units_are_checked_after_the_nominal_solve(coarse: ParameterSet) -> None:
    """A unit with no chain table (a coarser mesh): a 6-unit trace given as 5 units passes the checks before
    any solve and is refused after its nominal solve, before the fit iterates."""
    cast = synthetic(coarse, coarse.nominal, "011001", "2d", seed=5)
    assert precheck_designs([cast], coarse, {"fidelity": "2d"}) == 0
    with pytest.raises(ScanError, match=r"is not design 01100 \(5 units\) at 36 kPa: .* more units than the design"):
        identify([Observation(replace(cast.spec, design="01100"), cast.scan)], coarse, SerialEvaluator(),
                 {"fidelity": "2d"})


def test_between_two_levels_a_scan_is_checked_against_both() -> None:
    """Between two of a table's levels (37 kPa: 36 and 40.5): an outline with its last unit cut off fails
    against both and is refused; the whole outline passes."""
    shapes = [chain_shape(make_model(8, {"fidelity": "2d", "pressure_kpa": p, "increments": i}), "01100110")
              for p, i in ((36, 8), (40.5, 9))]
    assert all(s is not None for s in shapes)
    own = shapes[1]
    short = own.samples[np.linalg.norm(own.samples - own.centres[-1], axis=1) > 8]  # its last unit cut off
    assert coverage(short, own).shares[-1] < MIN_END_SHARE
    spec = ScanSpec("cut.csv", "01100110", 37.0)
    with pytest.raises(ScanError, match="hardly reaches its last unit"):
        check_coverage(Scan(short, None, "cut"), spec, shapes)
    check_coverage(Scan(own.samples[::10], None, "whole"), spec, shapes)  # the whole outline passes

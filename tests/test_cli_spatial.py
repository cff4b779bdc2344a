"""`--library spatial` on the command line: sideways designs in 3D, refused in 2D and by the chain."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main


def _simulate(design: str, capsys: pytest.CaptureFixture[str]) -> dict:
    args = ["simulate", "-o", design, "--library", "spatial", "--model", "3d", "--pressure", "5", "--increments", "1",
            "--json"]
    assert main(args) == 0
    return json.loads(capsys.readouterr().out)


def test_simulate_solves_a_sideways_design_on_the_full_width(capsys: pytest.CaptureFixture[str]) -> None:
    left, right = _simulate("al", capsys), _simulate("aL", capsys)
    (tip_l,), (tip_r,) = [[level["tip_mm"] for level in r["levels"]] for r in (left, right)]
    assert len(tip_l) == 3 and len(left["levels"][0]["unit_centres_mm"][0]) == 3  # (x, y, z)
    mid = 7.5  # the axis: the mesh's mid-width, where the undeformed tip lies
    assert tip_l[2] > mid + 0.01 and tip_r[2] < mid - 0.01  # towards the side of the layer
    assert tip_l[2] - mid == pytest.approx(mid - tip_r[2], abs=1e-6)  # mirror images
    assert tip_l[1] == pytest.approx(tip_r[1], abs=1e-6)
    twist_l, twist_r = left["levels"][0]["twist_deg"], right["levels"][0]["twist_deg"]
    assert twist_l == pytest.approx(-twist_r, abs=1e-6)  # the end face twists the other way in the mirror image


def test_simulate_prints_the_tip_z_and_the_twist_of_a_full_width_design(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "-o", "al", "--library", "spatial", "--model", "3d", "--pressure", "5",
                 "--increments", "1"]) == 0
    header, row = capsys.readouterr().out.splitlines()[:2]
    assert header.split() == ["p", "[kPa]", "tip", "x", "[mm]", "tip", "y", "[mm]", "tip", "z", "[mm]", "curl", "[deg]",
                              "twist", "[deg]"]
    assert len(row.split()) == 6 and float(row.split()[0]) == pytest.approx(5.0)


@pytest.mark.parametrize(("args", "message"), [
    (["simulate", "-o", "aL", "--library", "spatial"], "unit type 'l' is sideways"),
])
def test_what_cannot_take_sideways_units_refuses_them_in_one_line(args: list[str], message: str, tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    extra = ["--out", str(tmp_path / "t.json"), "--cache", str(tmp_path / "c.sqlite")] if args[0] == "chain" else []
    assert main([*args, *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1
    assert not (tmp_path / "t.json").exists()


def test_what_the_chain_in_space_cannot_score_is_refused_before_any_table(tmp_path: Path,
                                                                          capsys: pytest.CaptureFixture[str]) -> None:
    out, cache = tmp_path / "run", tmp_path / "c.sqlite"
    assert main(["design", "--library", "spatial", "--objective", "max-curl", "--out", str(out),
                 "--cache", str(cache)]) == 2
    err = capsys.readouterr().err.strip()
    assert "scores Cartesian profiles, space curves, paths and tip goals" in err and len(err.splitlines()) == 1
    assert not out.exists() and not (tmp_path / "chain-tables").exists()

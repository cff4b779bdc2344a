"""``pneumorph design``: a tiny run end to end, resume, and bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main

TINY = ["--units", "2", "--search", "ga", "--pop", "4", "--gen", "2", "--pressure", "10", "--executor", "serial"]


def test_tiny_design_run_writes_the_folder_and_resumes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = ["design", *TINY, "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"), "--json"]
    assert main(args) == 0
    first = json.loads(capsys.readouterr().out)
    assert first["status"] == "finished" and first["solves"] >= 1
    assert first["best"]["design"] in {"00", "01", "10", "11"}
    for name in ("config.toml", "generations.csv", "hall_of_fame.json", "report.md", "profile.png",
                 "winner/deformed.png", "winner/vtk/winner.pvd"):
        assert (tmp_path / "run" / name).is_file(), name
    assert main(args) == 0  # the same command again: everything from the cache
    second = json.loads(capsys.readouterr().out)
    assert second["solves"] == 0 and second["best"] == first["best"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--target", "sin", "--objective", "max-x"], "either --target"),
        (["--target", "y = x.__class__"], "attribute"),
        (["--target", "banana"], "banana"),
        (["--pop", "1"], "population"),
        (["--units", "0"], "at least 1 unit"),
    ],
)
def test_design_rejects_bad_input(extra: list[str], message: str, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["design", *TINY, "--out", str(tmp_path / "r"), "--cache", str(tmp_path / "c.sqlite"), *extra])
    assert code == 2
    assert message in capsys.readouterr().err


def test_population_study_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = ["study", "--units", "2", "--pressure", "10", "--populations", "2,4", "--seeds", "2", "--gen", "2",
            "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "st"), "--json"]
    assert main(args) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert [r["population"] for r in rows] == [2, 4]
    for r in rows:
        assert r["lowest"] <= r["mean"] <= r["largest"] and len(r["best"]) == 2
    assert (tmp_path / "st" / "study.png").is_file()
    assert main(["study", "--populations", "2,x", "--out", str(tmp_path / "s2")]) == 2

"""``pneumorph chain build``: a small table end to end, and bad input refused before any solve."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main
from pneumorph.models.chain.model import ChainTable
from pneumorph.models.chain.windows import covering_designs


@pytest.mark.slow
def test_chain_build_writes_a_validated_table(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    unit = tmp_path / "coarse.toml"
    unit.write_text("[unit]\nelement_size = 3.0\n")
    out = tmp_path / "t.json"
    args = ["chain", "build", "--model", "2d", "--unit", str(unit), "--pressure", "20", "--units", "7",
            "--heldout", "4", "--workers", "1", "--cache", str(tmp_path / "c.sqlite"), "--out", str(out), "--json"]
    assert main(args) == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    # progress; the first window is the one the shipped 2D table needed (+-2), not +-1
    assert "window +-2" in captured.err and "window +-1" not in captured.err
    table = ChainTable.load(out)
    # what it builds, and its estimate, before the first solve; the solves it counted are those it made
    plan = captured.err.splitlines()[0]
    assert plan.startswith("building the chain table of the 2d model (unit with element_size 3, 2-20 kPa in 10 "
                           "levels) on 7-unit designs: windows +-2 (")
    fewest, most = (int(x) for x in plan.split(" mm; ")[1].split(" FE solves")[0].split("-"))
    assert fewest == len(covering_designs(7, 2)) + 4 and table.metadata["solves"] in range(fewest, most + 1)
    assert report["window"] == table.window and len(report["validation"]["designs"]) == 4
    assert max(table.validation["centre_worst_mm"]) <= 0.2 and table.source["n_units"] == 7
    assert table.metadata["pneumorph"] and table.metadata["created_utc"]


@pytest.mark.slow
def test_chain_build_short_learns_the_ends_from_short_actuators(tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    unit = tmp_path / "coarse.toml"
    unit.write_text("[unit]\nelement_size = 3.0\n")
    out = tmp_path / "t.json"
    args = ["chain", "build", "--model", "2d", "--unit", str(unit), "--pressure", "20", "--units", "12",
            "--window", "2", "--short", "--heldout", "4", "--workers", "1", "--cache", str(tmp_path / "c.sqlite"),
            "--out", str(out)]
    assert main(args) == 0
    err = capsys.readouterr().err
    table = ChainTable.load(out)
    assert {len(d) for d in table.training} == {4, 12} and table.source["n_units"] == 12
    assert all(len(d) == 12 for d in table.validation["designs"])
    # the plan counted the short designs the build solved
    assert f"window +-2 ({len(table.training)} covering designs)" in err.splitlines()[0]
    assert max(table.validation["centre_worst_mm"]) <= 0.2


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--out", "."], "is a folder"),
        (["--window", "4", "--units", "7", "--out", "t.json"], "--window must be a whole number >= 1 and <= 3, got 4"),
        (["--heldout", "0", "--out", "t.json"], "--heldout"),
        (["--tolerance", "0", "--out", "t.json"], "tolerance"),
    ],
)
def test_chain_build_refuses_bad_input(extra: list[str], message: str, tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["chain", "build", "--model", "2d", "--workers", "1", "--cache", str(tmp_path / "c.sqlite"),
                 *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "t.json").exists()

"""``pneumorph sensitivity`` studies from the command line: what their output says."""

from __future__ import annotations

from pathlib import Path

import pytest

from pneumorph.cli import main


def test_2d_tolerances_say_why_the_side_wall_rows_are_the_reference(capsys: pytest.CaptureFixture[str],
                                                                     tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PNEUMORPH_CACHE", str(tmp_path / "cache.sqlite"))
    assert main(["sensitivity", "tolerances", "--model", "2d", "--units", "2", "--samples", "0",
                 "--executor", "serial"]) == 0
    out = capsys.readouterr().out
    rows = [line for line in out.splitlines() if line.startswith("side_wall")]
    assert rows and all(" 0.000 " in line for line in rows)  # the 2D section has no side walls
    assert "the side walls are not in it" in out



@pytest.mark.parametrize("study", ["simplifications", "temperature"])
def test_3d_only_studies_offer_only_the_3d_model(study: str, capsys: pytest.CaptureFixture[str]) -> None:
    """`sensitivity simplifications --help` offered 2d and then refused it."""
    assert main(["sensitivity", study, "--help"]) == 0
    helptext = " ".join(capsys.readouterr().out.split())
    assert "--model [3d]" in helptext and "2d" not in helptext
    assert main(["sensitivity", study, "--model", "2d"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'2d' is not" in err[0] and "3d" in err[0]

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


@pytest.mark.parametrize("stl", ["X.inp", "X.inp/parts"])
def test_export_refuses_a_deck_where_the_stl_folder_goes(tmp_path: Path, stl: str,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """The deck used to be written, then the STL folder refused: now nothing is written."""
    deck = tmp_path / "X.inp"
    assert main(["export", "0110", "--stl", str(tmp_path / stl), "--inp", str(deck)]) == 2
    assert "collide" in capsys.readouterr().err
    assert not deck.exists()

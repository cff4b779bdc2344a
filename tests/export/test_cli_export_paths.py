"""``pneumorph export``: output paths checked before anything is written."""

from __future__ import annotations

from pathlib import Path

import pytest

from pneumorph.cli import main


@pytest.mark.parametrize("stl", ["X.inp", "X.inp/parts"])
def test_export_refuses_a_deck_where_the_stl_folder_goes(tmp_path: Path, stl: str,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """The deck used to be written, then the STL folder refused: now nothing is written."""
    deck = tmp_path / "X.inp"
    assert main(["export", "0110", "--stl", str(tmp_path / stl), "--inp", str(deck)]) == 2
    assert "collide" in capsys.readouterr().err
    assert not deck.exists()

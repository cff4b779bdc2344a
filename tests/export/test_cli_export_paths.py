"""``pneumorph export``: output paths checked before anything is written."""

from __future__ import annotations

from pathlib import Path

import pytest

from pneumorph.cli import main


@pytest.mark.parametrize("stl", ["X.inp", "X.inp/parts"])
def test_export_refuses_a_deck_where_the_stl_folder_goes(tmp_path: Path, stl: str,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """An STL folder that collides with the deck is refused before anything is written, the deck included."""
    deck = tmp_path / "X.inp"
    assert main(["export", "0110", "--stl", str(tmp_path / stl), "--inp", str(deck)]) == 2
    assert "collide" in capsys.readouterr().err
    assert not deck.exists()

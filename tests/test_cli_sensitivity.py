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


"""`--scan-unit` and `--scale` say the same thing two ways: given together they are refused, not one ignored."""

from __future__ import annotations

from pathlib import Path

import pytest

from pneumorph.cli import main

SCAN = Path(__file__).parents[2] / "examples" / "data" / "scan-0110-30kpa.xyz"


@pytest.mark.parametrize("command", ["correlate", "identify"])
def test_scan_unit_and_scale_together_are_refused_before_any_solve(command: str, tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert main([command, str(SCAN), "--design", "0110", "--pressure", "30", "--scale", "1", "--scan-unit", "cm",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "give --scan-unit or --scale, not both" in err and len(err.splitlines()) == 1
    assert not out.exists()

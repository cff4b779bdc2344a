"""``pneumorph composite transition|coupon``: output, files and exit codes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.cli import run


def test_transition_text(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "composite", "transition", "--crimp-ratio", "0.3", "--amplitude", "1.5",
                       "--length", "176.25")
    assert code == 0
    assert "53.99 %" in out and "34.7500" in out and "56.20 %" in out


def test_transition_json_with_wavelength(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "composite", "transition", "--wavelength", "6", "--json")
    data = json.loads(out)
    assert code == 0
    assert data["crimp_ratio"] == 0.25
    assert data["transition_strain"] == pytest.approx(0.3901, abs=1e-4)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--crimp-ratio", "0"], "--crimp-ratio must be a finite number > 0"),
        (["--crimp-ratio", "0.3", "--amplitude", "-1"], "amplitude"),
        (["--crimp-ratio", "0.2", "--length", "5"], "longer than the coupon"),
        (["--crimp-ratio", "0.2", "--wavelength", "7.5"], "exactly one"),
        ([], "exactly one"),
    ],
)
def test_impossible_crimp_is_a_one_line_error(capsys: pytest.CaptureFixture[str], argv: list[str],
                                               message: str) -> None:
    code, out, err = run(capsys, "composite", "transition", *argv)
    assert code == 2 and out == ""
    assert err.startswith("error: ") and message in err and err.count("\n") == 1


def test_coupon_json_and_files(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, out, _ = run(capsys, "composite", "coupon", "--crimp-ratio", "0.3", "--length", "20", "--per-flute", "1",
                       "--rows", "1", "--levels", "24", "--strain-max", "0.9", "--gauges", "20", "--seed", "3",
                       "--out", str(tmp_path), "--json")
    assert code == 0
    data = json.loads(out)
    assert data["transition_engineering"] == pytest.approx(data["analytical_limit_transition"], abs=0.01)
    assert data["gauges"]["count"] == 20 and data["gauges"]["seed"] == 3
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["coupon-cr0_3-deformed.png", "coupon-cr0_3-load.png", "coupon-cr0_3-surface-strain.png",
                     "coupon-cr0_3.csv", "coupon-cr0_3.json"]
    rows = (tmp_path / "coupon-cr0_3.csv").read_text().splitlines()
    assert rows[0] == "engineering_strain,surface_strain,force_N_per_mm" and len(rows) == 26


def test_coupon_text(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "composite", "coupon", "-c", "0.25", "--length", "24", "--per-flute", "1",
                       "--rows", "1", "--levels", "24", "--strain-max", "0.7", "--gauges", "0")
    assert code == 0
    assert "transition, engineering strain" in out and "virtual strain gauges" not in out


def test_coupon_rejects_a_crimp_too_high_for_the_coupon(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "composite", "coupon", "-c", "0.3", "--thickness", "2.5")
    assert code == 2 and "thickness" in err

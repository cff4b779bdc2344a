"""``pneumorph calibrate``: a tiny run writes its files; a law that cannot be tested is not used."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main


def test_tiny_calibration(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "cal"
    args = ["calibrate", "--units", "1", "--pressures", "5,10", "--runs", "1", "--validate", "0",
            "--cache", str(tmp_path / "c.sqlite"), "--out", str(out), "--json"]
    with pytest.warns(UserWarning, match="cannot test"):
        assert main(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert [round(p["pressure"] * 1e3) for p in data["points"]] == [5, 10]
    # the fitted filler puts the 2D unit centre on the 3D one: Eq 5.1 (sum of squared centre
    # distances) was 5.3e-4 and 2.2e-3 mm^2 when measured, i.e. within 0.05 mm
    assert all(p["gamma"] < 0.01 for p in data["points"])
    assert data["chosen_degree"] is None  # two levels cannot test a law: nothing is used
    assert (out / "calibration.png").is_file() and not (out / "unit.toml").exists()
    assert main(["calibrate", "--pressures", "5,x", "--out", str(out)]) == 2


def test_references_only_fills_the_cache_that_calibration_then_reuses(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from pneumorph.execution import EvaluationCache

    cache = tmp_path / "c.sqlite"
    common = ["--units", "1", "--pressures", "4,8,12", "--runs", "1", "--validate", "1", "--cache", str(cache)]
    assert main(["calibrate", *common, "--references-only"]) == 0
    log = capsys.readouterr().err
    assert "3D reference 1/2 (calibration)" in log and "3D reference 2/2 (validation)" in log
    with EvaluationCache(cache) as store:
        assert store.count() == 2  # one calibration design, one held-out design
    # calibration and validation find their 3D references in the cache: no new 3D solve
    out = tmp_path / "cal"
    with pytest.warns(UserWarning, match="cannot test"):  # three levels cannot test a quadratic
        assert main(["calibrate", *common, "--out", str(out), "--json"]) == 0
    with EvaluationCache(cache) as store:
        assert store.count() == 2
    data = json.loads(capsys.readouterr().out)
    assert data["chosen_degree"] == 1
    (calibrated,) = {p["design"] for p in data["points"]}
    assert data["validation"]["designs"] == [{"0": "1", "1": "0"}[calibrated]]  # held out: the mirror
    # the mirror design deforms as the mirror image in 2D and 3D, so its 2D-3D distance at
    # 12 kPa is the calibration's residual there, sqrt(Eq 5.1), through the fitted law
    # (R^2 = 1 - 2e-7, so the law's E(12 kPa) is the calibrated point's)
    top = next(p for p in data["points"] if round(p["pressure"] * 1e3) == 12)
    assert data["validation"]["max_mm"][-1] == pytest.approx(top["gamma"] ** 0.5, rel=1e-3)
    for name in ("calibration.png", "profiles.png", "filler_paths.png", "unit.toml"):
        assert (out / name).is_file()

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
    assert all(0.0001 <= p["modulus"] <= 1.0 for p in data["points"])
    assert data["chosen_degree"] is None  # two levels cannot test a law: nothing is used
    assert (out / "calibration.png").is_file() and not (out / "unit.toml").exists()
    assert main(["calibrate", "--pressures", "5,x", "--out", str(out)]) == 2


def test_references_only_fills_the_cache_that_calibration_then_reuses(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from pneumorph.execution import EvaluationCache

    cache = tmp_path / "c.sqlite"
    common = ["--units", "1", "--pressures", "5,10", "--runs", "1", "--cache", str(cache)]
    assert main(["calibrate", *common, "--validate", "1", "--references-only"]) == 0
    log = capsys.readouterr().err
    assert "3D reference 1/2 (calibration)" in log and "3D reference 2/2 (validation)" in log
    with EvaluationCache(cache) as store:
        assert store.count() == 2  # one calibration design, one held-out design
    # the calibration finds its 3D reference in the cache: no new entry, no 3D solve
    with pytest.warns(UserWarning, match="cannot test"):
        assert main(["calibrate", *common, "--validate", "0", "--out", str(tmp_path / "cal")]) == 0
    with EvaluationCache(cache) as store:
        assert store.count() == 2

"""``pneumorph calibrate``: a tiny run writes its files; a law that cannot be tested is not used."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

import pytest

from pneumorph.calibration import cached_3d_solver, gamma, open_cache, reference_model, unit_centre_displacements
from pneumorph.cli import main
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.models.fe import RampSpec, Reduced2D
from pneumorph.models.response import Response


def _one_unit_reference(cache: Path, pressures_kpa: Sequence[float], design: str
                        ) -> tuple[Response, Callable[[float, float], Reduced2D]]:
    """A calibration's 3D reference of one unit, from its cache, and its 2D model with a constant
    filler ramped as the calibration ramps it."""
    unit = UnitSpec()
    model3d = reference_model(unit, 1, pressures_kpa)
    with open_cache(cache) as store:
        solves = store.count()
        reference = cached_3d_solver(store)(model3d, design)
        assert store.count() == solves  # found in the cache, not solved again
    steps, p_max = model3d.ramp.steps, model3d.ramp.pressure

    def make_2d(modulus: float, pressure: float) -> Reduced2D:
        ramp = RampSpec(pressure, replace(steps, increments=max(1, round(pressure / p_max * steps.increments))))
        law = FillerLaw("trial", "trial", (modulus,), (0.0, pressure), unit.filler_poisson_ratio)
        return Reduced2D(1, unit, ramp, law)

    return reference, make_2d


def test_tiny_calibration(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "cal"
    args = ["calibrate", "--units", "1", "--pressures", "5,10", "--runs", "1", "--validate", "0",
            "--cache", str(tmp_path / "c.sqlite"), "--out", str(out), "--json"]
    with pytest.warns(UserWarning, match="cannot test"):
        assert main(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert [round(p["pressure"] * 1e3) for p in data["points"]] == [5, 10]
    # each point is the minimum of Eq 5.1 over the filler modulus: the 2D model with the
    # point's modulus gives the Gamma reported, and 20 % more or less modulus a larger one
    # (a bound on Gamma alone would not test this: every modulus of the search range gives
    # Gamma < 0.004 mm^2 at 5 kPa)
    reference, make_2d = _one_unit_reference(tmp_path / "c.sqlite", (5, 10), data["points"][0]["design"])

    def eq_5_1(point: dict, modulus: float) -> float:
        solved = make_2d(modulus, point["pressure"]).evaluate(point["design"])
        target = unit_centre_displacements(reference, reference.level_of(point["pressure"]))
        return gamma(unit_centre_displacements(solved, -1), target)

    for p in data["points"]:
        assert eq_5_1(p, p["modulus"]) == pytest.approx(p["gamma"], rel=1e-9)
        for step in (0.2, -0.2):
            assert eq_5_1(p, p["modulus"] * math.exp(step)) > p["gamma"]
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

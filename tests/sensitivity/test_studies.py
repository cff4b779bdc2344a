"""The studies of appendices D and E on small actuators: variants, measures, evaluators, the CLI."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.errors import MaterialDataError, SettingsError
from pneumorph.execution import CachedEvaluator, EvaluationCache
from pneumorph.execution.evaluators import ProcessPoolEvaluator, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials import get
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D
from pneumorph.models.response import Response
from pneumorph.sensitivity import (
    Tolerance,
    bulk_modulus,
    calibration,
    run_study,
    scaled_bulk_modulus,
    shape_difference,
    simplifications,
    temperature,
    tension_only,
    tolerances,
)
from pneumorph.sensitivity.studies import _matching

LOW = RampSpec(pressure=0.01)  # 10 kPa: small actuators solve in about a second


def _response(points: list[list[float]], tip: list[float], curl: float) -> Response:
    r = Response.empty("0" * len(points), np.array([0.045]), np.array(points), np.array(tip))
    r.centres[0], r.tip[0], r.curl[0] = points, tip, curl
    return r


def test_shape_difference_is_the_largest_point_distance_with_its_components_in_percent() -> None:
    ref = _response([[10.0, 0.0], [20.0, 5.0]], [30.0, 10.0], 20.0)
    other = _response([[10.0, 0.0], [23.0, 9.0]], [30.0, 10.0], 25.0)
    d = shape_difference(ref, other)
    # base (0, 0), centres, tip: the reference spans 30 mm in x and 10 mm in y; the worst point moved (3, 4)
    assert d.distance_mm == pytest.approx(5.0) and d.tip_mm == 0.0
    assert (d.x_error_pct, d.y_error_pct) == (pytest.approx(10.0), pytest.approx(40.0))
    assert (d.curl_deg, d.reference_curl_deg) == (25.0, 20.0)
    same = shape_difference(ref, ref)
    assert same.distance_mm == 0.0 and same.x_error_pct == 0.0


def test_cases_of_different_models_through_every_evaluator_and_the_cache(tmp_path: Path) -> None:
    a, b = Reduced2D(3, ramp_spec=LOW), Reduced2D(3, ramp_spec=replace(LOW, pressure=0.02))
    expected = [a.evaluate("011").curl[-1], b.evaluate("011").curl[-1]]
    assert abs(expected[1]) > abs(expected[0]) > 0
    for evaluator in (SerialEvaluator(), ProcessPoolEvaluator(workers=2)):
        with evaluator:
            got = dict(evaluator.iter_cases([(a, "011"), (b, "011")]))
        assert [got[0].response.curl[-1], got[1].response.curl[-1]] == pytest.approx(expected, abs=1e-6)
    cache = EvaluationCache(tmp_path / "c.sqlite")
    cached = CachedEvaluator(SerialEvaluator(), cache)
    first = dict(cached.iter_cases([(a, "011"), (b, "011"), (a, "011")]))
    assert cached.solves == 2 and first[2].cached  # the repeated case is solved once
    again = dict(CachedEvaluator(SerialEvaluator(), cache).iter_cases([(b, "011"), (a, "011")]))
    assert again[0].cached and again[1].cached and again[0].response.curl[-1] == pytest.approx(expected[1])


@pytest.mark.slow
def test_simplifications_study_on_a_small_actuator(tmp_path: Path) -> None:
    model = Full3D(2, ramp_spec=LOW)
    study = simplifications(model)
    assert study.design == "00" and len({c.model.fingerprint() for c in study.all_cases()}) == 5
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(tmp_path / "c.sqlite"))
    seen: list[int] = []
    result = run_study(study, evaluator, on_case=lambda done, total, r: seen.append(done))
    assert seen == [1, 2, 3, 4, 5]
    d = {c.case.label: c.difference for c in result.cases}
    assert all(x is not None and x.distance_mm > 0 for x in d.values())
    # each variant solved on its own equals the study's case
    alone = Full3D(2, ramp_spec=LOW, passage=1.5).evaluate("00")
    assert d["passages"].curl_deg == pytest.approx(alone.curl[-1], abs=1e-9)
    # the temperature study's variant is the same model: answered from the cache
    again = run_study(temperature(model), evaluator)
    assert again.cases[0].outcome.cached and again.cases[0].difference == d["temperature +10 degC"]
    with pytest.raises(SettingsError, match="3D model"):
        simplifications(Reduced2D(2))


@pytest.mark.slow
def test_tolerance_study_reports_the_spread_and_the_inputs_of_the_extreme_curls(tmp_path: Path) -> None:
    model = Full3D(2, UnitSpec(element_size=3.0), ramp_spec=LOW)  # coarse: the box's meshes keep its cell counts
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(tmp_path / "c.sqlite"))
    study = tolerances(model, "01", Tolerance(0.1), samples=3, seed=4)
    again = tolerances(model, "01", Tolerance(0.1), samples=3, seed=4)
    assert [c.inputs for c in study.cases] == [c.inputs for c in again.cases]  # seeded
    assert [c.inputs for c in study.cases] != [c.inputs for c in tolerances(model, "01", samples=3, seed=5).cases]
    result = run_study(study, evaluator)
    s = result.summary()
    curls = [c.difference.curl_deg for c in result.cases]
    assert s["curl_min_deg"] == min(curls) and s["curl_max_deg"] == max(curls) and s["failed"] == 0
    lo = result.cases[int(np.argmin(curls))].case
    assert s["minimum_curl_inputs"] == lo.inputs and set(lo.inputs) == {"side_wall", "wall", "layer"}
    assert all(abs(v - {"side_wall": 1.5, "wall": 1.5, "layer": 3.0}[k]) <= 0.1 + 1e-12
               for c in study.cases for k, v in c.inputs.items())
    assert 0 <= s["samples_within_extremes"] <= 3 and "samples_within_corners" not in s
    # the corners of the box bracket every sample's curl (monotone in each thickness)
    boxed = run_study(tolerances(model, "01", Tolerance(0.1), samples=3, seed=4, corners=True), evaluator)
    assert boxed.summary()["samples_within_corners"] == 3


@pytest.mark.slow
def test_bulk_modulus_and_calibration_variants() -> None:
    ms = get("mold_star_15")
    assert scaled_bulk_modulus(ms, 1.1).bulk_modulus.value == pytest.approx(1.1 * ms.bulk_modulus.value)
    model = Full3D(2, ramp_spec=LOW)
    result = run_study(bulk_modulus(model), SerialEvaluator())
    curls = [result.reference.outcome.response.curl[-1], *(c.difference.curl_deg for c in result.cases)]
    assert curls[0] > curls[1] > curls[2]  # less compressible silicone: a stiffer actuator
    # the tension-only fit matches the tension branch and departs from the model in compression
    soft, fitted = tension_only(ms)
    lam = np.array([1.5, 2.0, 3.0])
    assert soft.model.uniaxial(lam) == pytest.approx(ms.model.uniaxial(lam), rel=1e-4)
    assert fitted.r2["uniaxial"] > 0.999999
    assert abs(soft.model.uniaxial(np.array([0.6]))[0] - ms.model.uniaxial(np.array([0.6]))[0]) > 0.1
    study = calibration(model, reach=1.5)
    variant = study.cases[0].model
    assert variant.ramp.pressure == pytest.approx(0.015) and variant.pressures()[study.level] == pytest.approx(0.01)


def test_matching_pressure_of_an_identical_model_is_the_reference_pressure() -> None:
    ref = Reduced2D(3, ramp_spec=LOW).evaluate("010")
    longer = Reduced2D(3, ramp_spec=RampSpec(pressure=0.02, steps=replace(LOW.steps, increments=20))).evaluate("010")
    kpa, mm = _matching(ref, longer, ref.n_levels - 1)
    assert kpa == pytest.approx(10.0, abs=0.05) and mm < 1e-3
    # a ramp that failed at 7.5 kPa (levels of 1 kPa): closest at its last converged level, and not close
    for name in ("centres", "tip", "curl"):
        getattr(longer, name)[7:] = np.nan
    kpa, mm = _matching(ref, longer, ref.n_levels - 1)
    assert kpa == pytest.approx(7.0) and mm == shape_difference(ref, longer, -1, 6).distance_mm and mm > 0.1


def test_a_temperature_change_needs_the_expansion_of_every_silicone() -> None:
    plain = replace(get("mold_star_15"), thermal_expansion=None)
    with pytest.raises(MaterialDataError, match="thermal expansion of 'mold_star_15'"):
        Full3D(2, temperature_change=10.0, materials={"mold_star_15": plain})


def test_cli_study_writes_its_results_and_resumes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["sensitivity", "bulk-modulus", "--units", "2", "--pressure", "10", "--executor", "serial",
            "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"), "--factor", "1.1"]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert "[3/2]" not in err and "bulk modulus x1.1: solved" in err and "bulk modulus x1.1" in out
    data = json.loads((tmp_path / "run" / "study.json").read_text())
    assert data["study"] == "bulk-modulus" and data["cases"][0]["difference"]["distance_mm"] > 0
    assert data["provenance"]["fingerprint"] and (tmp_path / "run" / "study.png").stat().st_size > 10_000
    assert main([*argv, "--json"]) == 0
    out, err = capsys.readouterr()
    assert "bulk modulus x1.1: cached" in err and json.loads(out)["cases"][0]["cached"]


def test_the_tolerance_figure_starts_its_bars_at_the_nominal_design_and_explains_its_lines() -> None:
    """Bars of the curl change from the nominal design (zero), not of the curl on an axis from 145 degrees; case
    labels at 8 pt; the grey centrelines and the bar colours named in legends."""
    from pneumorph.plot.sensitivity import plot_study

    result = run_study(tolerances(Reduced2D(2, ramp_spec=LOW), "01", Tolerance(0.1), samples=3, seed=4),
                       SerialEvaluator())
    fig = plot_study(result)
    ax, bx = fig.axes
    lo, hi = bx.get_xlim()
    nominal = float(result.reference.outcome.response.curl[result.study.level])
    changes = [c.difference.curl_deg - nominal for c in result.cases]
    assert lo < 0 < hi and lo <= min(changes) and max(changes) <= hi
    assert [p.get_x() for p in bx.patches] == [0.0] * len(result.cases)  # every bar starts at zero
    assert [p.get_width() for p in bx.patches] == pytest.approx(changes)
    assert "curl change from the nominal design's" in bx.get_xlabel()
    assert all(t.get_fontsize() >= 8 for t in bx.get_yticklabels())
    assert [t.get_text() for t in bx.get_yticklabels()] == [c.case.label for c in result.cases]
    assert {t.get_text() for t in bx.get_legend().get_texts()} == {
        "extremes and corners of the tolerance box", "random samples", "nominal design"}
    assert "the other cases (extremes, corners, random samples)" in [t.get_text() for t in ax.get_legend().get_texts()]


def test_cli_study_of_an_identified_model(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the study's reference is the model file's: its fingerprint, and the study's 2D fidelity from the file
    from pneumorph.models.factory import make_model

    identified = tmp_path / "identified.toml"
    identified.write_text('[model]\nfidelity = "2d"\nbody_shear_scale = 0.9\n[model.unit]\nwall = 1.6\n')
    argv = ["sensitivity", "bulk-modulus", "--units", "2", "--pressure", "10", "--executor", "serial",
            "--cache", str(tmp_path / "c.sqlite"), "--factor", "1.1", "--model-file", str(identified), "--json"]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert "(2d model, 2 units, 10 kPa)" in err
    model = make_model(2, {"fidelity": "2d", "pressure_kpa": 10, "body_shear_scale": 0.9, "unit": {"wall": 1.6}})
    assert json.loads(out)["reference"]["fingerprint"] == model.fingerprint()
    # a study of the 3D model only refuses a 2D model file, naming both
    assert main(["sensitivity", "temperature", "--units", "2", "--model-file", str(identified)]) == 2
    assert "is of the 2d model, which this study does not vary; give --model 3d" in capsys.readouterr().err

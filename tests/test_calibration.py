"""Filler-law calibration: recovers known laws; bad laws are reported, not used."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from pneumorph.calibration import CalibrationWarning, calibrate, fit_law
from pneumorph.fem import StepSettings
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.models.fe import Reduced2D

TRUE = (0.05, -1.0)  # E(P) = 0.05 - 1.0 P (MPa, P in MPa)


def truth(model, design):
    """A 2D model whose filler follows a known law: the calibration must find that law."""
    law = FillerLaw("true", "true", TRUE, (0.0, model.ramp.pressure), 0.3)
    return Reduced2D(model.n_units, model.unit, model.ramp, law).evaluate(design)


def test_calibration_recovers_a_known_law() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationWarning)
        cal = calibrate(UnitSpec(), 2, pressures_kpa=(4, 8, 12), runs=1, seed=3,
                        steps=StepSettings(increments=3, substeps=1), solve_3d=truth)
    for point in cal.points:
        expected = TRUE[0] + TRUE[1] * point.pressure
        assert point.modulus == pytest.approx(expected, rel=0.01)
    assert cal.chosen is cal.linear
    np.testing.assert_allclose(cal.linear.coefficients, TRUE, rtol=0.03)
    # with every point within 1 % (<= 4.6e-4 MPa) of a law spanning 0.046-0.038 MPa over
    # three points, SSE <= 3 (4.6e-4)^2 and SSTO = 2 (0.004)^2, hence R^2 >= 0.98
    assert cal.linear.r_squared > 0.98
    unit = cal.unit_with_law(UnitSpec())
    assert unit.filler_law().modulus(0.008) == pytest.approx(0.042, rel=0.01)
    assert "pneumorph calibrate" in unit.filler_source


def test_bad_laws_are_flagged() -> None:
    p = [0.005, 0.01, 0.02, 0.03, 0.04]
    noisy = fit_law(p, [0.05, 0.01, 0.06, 0.0, 0.05], 1, (0.0, 0.045))
    assert noisy.problems and "R^2" in noisy.problems[0]
    negative = fit_law(p, [0.05, 0.04, 0.02, 0.0, -0.02], 1, (0.0, 0.045))
    assert any("not positive" in x for x in negative.problems)
    too_few = fit_law([0.01, 0.02], [0.04, 0.03], 2, (0.0, 0.02))
    assert "cannot test" in too_few.problems[0]


def test_holdout_designs_are_distinct_and_held_out() -> None:
    from pneumorph.calibration import calibration_designs, holdout_designs
    from pneumorph.errors import SearchConfigError

    cal = calibration_designs(3, 3, seed=1)
    held = holdout_designs(3, 8 - len(set(cal)), seed=1, exclude=cal)
    assert sorted(set(cal) | set(held)) == sorted(f"{i:03b}" for i in range(8))  # the whole space, no overlap
    with pytest.raises(SearchConfigError, match="only 0 designs"):
        holdout_designs(1, 1, exclude=["0", "1"])


def test_relative_weighting_minimises_relative_errors() -> None:
    # a law falling to a small modulus: ordinary least squares misses the small end by
    # far more, relatively, than the relative weighting does
    p = np.array([0.0, 0.01, 0.02, 0.03, 0.04])
    e = np.array([0.050, 0.046, 0.038, 0.026, 0.008])
    rel = fit_law(p, e, 1, (0.0, 0.04), 1.0 / e, "relative")
    uni = fit_law(p, e, 1, (0.0, 0.04))

    def relative_sse(coeffs) -> float:
        return float(np.sum(((np.polynomial.polynomial.polyval(p, coeffs) - e) / e) ** 2))

    # the relative fit is the minimum of the relative squared error: any nudge raises it
    for nudge in ([1e-4, 0.0], [0.0, 1e-3], [-1e-4, 0.0], [0.0, -1e-3]):
        assert relative_sse(np.add(rel.coefficients, nudge)) > relative_sse(rel.coefficients)
    assert relative_sse(rel.coefficients) < relative_sse(uni.coefficients)
    assert rel.weighting == "relative" and uni.weighting == "uniform"
    assert uni.r_squared == pytest.approx(uni.r_squared_unweighted, abs=1e-15)
    # R^2 does not depend on the scale of the weights
    scaled = fit_law(p, e, 1, (0.0, 0.04), 7.0 / e, "relative")
    assert scaled.r_squared == pytest.approx(rel.r_squared, rel=1e-12)
    np.testing.assert_allclose(scaled.coefficients, rel.coefficients, rtol=1e-10)


def test_bad_weights_are_refused() -> None:
    from pneumorph.calibration import FillerPoint, point_weights

    with pytest.raises(ValueError, match="weights"):
        fit_law([0.01, 0.02, 0.03], [0.04, 0.03, 0.02], 1, (0.0, 0.03), [1.0, -1.0, 1.0])
    unmeasured = [FillerPoint(0, 0.01, "00", 0.04, 0.0, 0.04, 1)]
    with pytest.raises(ValueError, match="curvature"):
        point_weights(unmeasured, "sensitivity")
    with pytest.raises(ValueError, match="weighting must be one of"):
        point_weights(unmeasured, "squared")


def test_sensitivity_weighting_measures_the_curvature_of_eq_5_1() -> None:
    """At a zero-residual optimum Gamma = |D(E) - D(E*)|^2, so d2Gamma/d(lnE)^2 = 2 |dD/dlnE|^2."""
    from pneumorph.calibration import unit_centre_displacements
    from pneumorph.models.fe import RampSpec

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationWarning)
        cal = calibrate(UnitSpec(), 2, pressures_kpa=(4, 8, 12), runs=1, seed=3,
                        steps=StepSettings(increments=3, substeps=1), solve_3d=truth, weighting="sensitivity")
    np.testing.assert_allclose(cal.linear.coefficients, TRUE, rtol=0.03)  # points on the law: still found
    assert cal.linear.weighting == "sensitivity"
    point = cal.points[-1]
    assert point.curvature is not None and point.curvature > 0

    def displacements(e: float) -> np.ndarray:
        law = FillerLaw("c", "c", (e,), (0.0, point.pressure), 0.3)
        model = Reduced2D(2, UnitSpec(), RampSpec(point.pressure, StepSettings(increments=3, substeps=1)), law)
        return unit_centre_displacements(model.evaluate(point.design), -1)

    e0, h = TRUE[0] + TRUE[1] * point.pressure, 1e-3
    slope = (displacements(e0 * np.exp(h)) - displacements(e0 * np.exp(-h))) / (2 * h)
    # the point's optimum is within 1 % of the true modulus and its central difference has
    # a step of 5 % in ln E: both shift the curvature by well under 1 %
    assert point.curvature == pytest.approx(2.0 * np.sum(slope**2), rel=0.01)  # measured: 6e-5

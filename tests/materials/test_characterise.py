"""Characterisation functions against closed forms and the dissertation's numbers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats
from scipy.optimize import brentq

from pneumorph.errors import DataFormatError, FitError
from pneumorph.materials.characterisation.analyses import (
    bilinear,
    bulk_modulus,
    characterise_bulk_modulus,
    linear_fit,
    poisson_ratio,
    thermal_expansion,
)
from pneumorph.materials.library import builtin as library

# ---------------------------------------------------------------------------------------
# Poisson's ratio and bulk modulus (Eqs A.4, A.5)
# ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("modulus", ["secant", "tangent"])
@pytest.mark.parametrize(("e", "nu"), [(0.5, 0.3), (2.0, 0.0), (0.1, -0.2), (1.0, 0.49)])
def test_linear_elastic_material_gives_exact_k(e: float, nu: float, modulus: str) -> None:
    eps = np.linspace(0.0, 1.5, 31)
    r = characterise_bulk_modulus(eps, -nu * eps, e * eps, modulus=modulus)
    k = e / (3 * (1 - 2 * nu))
    assert r.n == 30  # eps = 0 skipped
    np.testing.assert_allclose(r.poisson_ratio, nu, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(r.bulk_modulus, k, rtol=1e-9)
    assert r.mean_bulk_modulus == pytest.approx(k, rel=1e-9)
    assert r.strain_average_bulk_modulus == pytest.approx(k, rel=1e-9)
    assert r.mean_youngs_modulus == pytest.approx(e, rel=1e-9)


def test_table_a5_mold_star_15_is_recovered_from_consistent_linear_data() -> None:
    """A linear material with Mold Star 15's mu0 (Table A.4) and K (Table A.5)."""
    m = library.get("mold_star_15")
    mu, k = m.shear_modulus, m.bulk_modulus.value
    nu = (3 * k - 2 * mu) / (2 * (3 * k + mu))
    e = 2 * mu * (1 + nu)
    eps = np.linspace(0.0, 2.0, 81)
    r = characterise_bulk_modulus(eps, -nu * eps, e * eps)  # default range 0-150 %
    assert r.axial_strain.max() == pytest.approx(1.5)
    assert r.mean_bulk_modulus * 1e3 == pytest.approx(119.0, rel=1e-12)


def test_incompressible_engineering_poisson_ratio() -> None:
    """Incompressible uniaxial stretch: eps_y = (1 + eps)^(-1/2) - 1."""
    eps = np.array([0.01, 0.5, 1.0, 1.5])
    nu = poisson_ratio(eps, (1 + eps) ** -0.5 - 1)
    np.testing.assert_allclose(nu, (1 - (1 + eps) ** -0.5) / eps, rtol=1e-14)
    assert nu[0] == pytest.approx(0.5 - 3 * 0.01 / 8, abs=1e-4)  # small-strain limit 1/2
    assert np.isnan(poisson_ratio([0.0], [0.0])[0])


def test_secant_and_tangent_differ_as_expected() -> None:
    """sigma = c eps^2: secant E = c eps, tangent E = 2 c eps (exact for a quadratic)."""
    eps = np.linspace(0.0, 1.0, 21)
    c, nu = 0.3, 0.25
    sec = characterise_bulk_modulus(eps, -nu * eps, c * eps**2, strain_range=(0.0, 1.0))
    tan = characterise_bulk_modulus(eps, -nu * eps, c * eps**2, strain_range=(0.0, 1.0), modulus="tangent")
    np.testing.assert_allclose(sec.youngs_modulus, c * sec.axial_strain, rtol=1e-12)
    np.testing.assert_allclose(tan.youngs_modulus, 2 * c * tan.axial_strain, rtol=1e-9)
    np.testing.assert_allclose(tan.bulk_modulus, 2 * sec.bulk_modulus, rtol=1e-9)


def test_strain_range_selects_points_and_weighted_average() -> None:
    """Outside the range nu is different and must not matter; E linear in eps, uneven spacing."""
    eps = np.array([0.0, 0.1, 0.2, 0.5, 1.0, 1.5, 1.6, 2.0])
    nu = np.where(eps <= 1.5, 0.25, 0.45)
    a, b = 0.2, 0.1
    stress = (a + b * eps) * eps
    r = characterise_bulk_modulus(eps, -nu * eps, stress, strain_range=(0.1, 1.5))
    np.testing.assert_array_equal(r.axial_strain, [0.1, 0.2, 0.5, 1.0, 1.5])
    assert r.mean_poisson_ratio == pytest.approx(0.25)
    k = (a + b * r.axial_strain) / 1.5
    assert r.mean_bulk_modulus == pytest.approx(k.mean(), rel=1e-12)
    # K is linear in eps, so the trapezoidal strain-average is exact: K at the mid-strain 0.8
    assert r.strain_average_bulk_modulus == pytest.approx((a + b * 0.8) / 1.5, rel=1e-12)


def test_nu_at_or_above_half_is_a_clear_error() -> None:
    eps = np.array([0.1, 0.2, 0.3])
    with pytest.raises(FitError, match=r"at axial strain 20 %.*0\.5 >= 0\.5"):
        characterise_bulk_modulus(eps, np.array([-0.04, -0.1, -0.12]), eps)
    with pytest.raises(FitError, match="infinite or negative"):
        bulk_modulus(1.0, 0.6)
    # without stress only nu is computed, which is defined for any value
    assert characterise_bulk_modulus(eps, -0.5 * eps).mean_poisson_ratio == 0.5


def test_empty_range_and_bad_input() -> None:
    eps = np.array([0.0, 0.1, 0.2])
    with pytest.raises(FitError, match="no data point"):
        characterise_bulk_modulus(eps, -0.3 * eps, eps, strain_range=(0.5, 1.0))
    with pytest.raises(FitError, match="no data point"):
        characterise_bulk_modulus([0.0], [0.0], [0.0])
    with pytest.raises(DataFormatError, match="same length"):
        characterise_bulk_modulus(eps, [-0.1, -0.2], eps)
    with pytest.raises(DataFormatError, match="non-finite"):
        characterise_bulk_modulus(eps, [0.0, np.nan, -0.1], eps)
    with pytest.raises(DataFormatError, match="lower < upper"):
        characterise_bulk_modulus(eps, -0.3 * eps, eps, strain_range=(1.0, 0.5))
    with pytest.raises(DataFormatError, match="secant"):
        characterise_bulk_modulus(eps, -0.3 * eps, eps, modulus="chord")  # type: ignore[arg-type]


# ---------------------------------------------------------------------------------------
# thermal expansion (Eq A.6)
# ---------------------------------------------------------------------------------------

TEMPS = np.linspace(85.0, 20.0, 10)  # ten images while cooling, as in Appendix A.2.5


def test_exact_thermal_data() -> None:
    alpha = 245.3e-6  # Mold Star 15, Table A.6
    r = thermal_expansion(TEMPS, 1e-3 + alpha * (TEMPS - 20.0))
    assert r.alpha == pytest.approx(alpha, rel=1e-12)
    assert r.r_squared == pytest.approx(1.0, abs=1e-12)
    assert r.standard_error < 1e-15
    assert r.temperature_range == (20.0, 85.0) and r.n == 10


def test_noisy_thermal_data_recover_slope_within_standard_error() -> None:
    rng = np.random.default_rng(20200301)
    alpha, sigma = 214.2e-6, 3e-4  # Ecoflex 0030, Table A.6; strain noise of DIC size
    eps = alpha * (TEMPS - 20.0) + rng.normal(0.0, sigma, TEMPS.size)
    r = thermal_expansion(TEMPS, eps)
    expected_se = sigma / np.sqrt(np.sum((TEMPS - TEMPS.mean()) ** 2))
    assert abs(r.alpha - alpha) < 3 * r.standard_error
    assert 0.4 < r.standard_error / expected_se < 1.6
    assert 0.0 < r.r_squared < 1.0


def test_standard_error_has_the_right_coverage() -> None:
    """|alpha_hat - alpha| < se in P(|t_8| < 1) = 65.3 % of repeated experiments."""
    rng = np.random.default_rng(7)
    alpha, sigma, reps = 245.3e-6, 3e-4, 2000
    hits = 0
    for _ in range(reps):
        r = thermal_expansion(TEMPS, alpha * TEMPS + rng.normal(0.0, sigma, TEMPS.size))
        hits += abs(r.alpha - alpha) < r.standard_error
    p = 2 * stats.t.cdf(1.0, TEMPS.size - 2) - 1
    assert hits / reps == pytest.approx(p, abs=4 * np.sqrt(p * (1 - p) / reps))


def test_thermal_errors() -> None:
    with pytest.raises(FitError, match="at least 3"):
        thermal_expansion([20.0, 30.0], [0.0, 1e-3])
    with pytest.raises(FitError, match="equal"):
        thermal_expansion([20.0, 20.0, 20.0], [0.0, 1e-3, 2e-3])


def test_linear_fit_r_squared_matches_eq_a1() -> None:
    x = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    y = np.array([0.1, 0.9, 2.2, 2.8, 4.1])
    f = linear_fit(x, y)
    slope, intercept, r, _, se = stats.linregress(x, y)
    assert (f.slope, f.intercept) == pytest.approx((slope, intercept), rel=1e-12)
    assert f.r_squared == pytest.approx(r**2, rel=1e-12)
    assert f.slope_standard_error == pytest.approx(se, rel=1e-12)


# ---------------------------------------------------------------------------------------
# bilinear composite (section 3.2.6, Table 3.2)
# ---------------------------------------------------------------------------------------

TABLE_3_2 = {  # crimp ratio: (primary modulus kPa, transition strain %, secondary modulus MPa)
    0.2: (216.0, 15.2, 25.2),
    0.25: (81.9, 30.0, 20.7),
    0.3: (80.0, 35.6, 16.5),
}


@pytest.mark.parametrize("cr", TABLE_3_2)
def test_bilinear_curve_with_table_3_2_kink_is_recovered(cr: float) -> None:
    e1, x_t, e2 = TABLE_3_2[cr]
    e1, x_t = e1 / 1000.0, x_t / 100.0
    eps = np.linspace(0.0, x_t + 0.2, 121)
    sig = np.where(eps <= x_t, e1 * eps, e1 * x_t + e2 * (eps - x_t))
    r = bilinear(eps, sig)
    assert r.primary_modulus == pytest.approx(e1, rel=1e-9)
    assert r.secondary_modulus == pytest.approx(e2, rel=1e-9)
    assert r.transition_strain == pytest.approx(x_t, rel=1e-9)
    assert r.transition_stress == pytest.approx(e1 * x_t, rel=1e-9)
    assert r.primary.r_squared == pytest.approx(1.0) and r.secondary.r_squared == pytest.approx(1.0)
    assert r.secondary.n == 10 and r.primary.n == int(np.sum(eps <= 0.1))


def test_noisy_bilinear_curve() -> None:
    rng = np.random.default_rng(3)
    e1, x_t, e2 = 0.216, 0.152, 25.2
    eps = np.linspace(0.0, 0.25, 101)
    sig = np.where(eps <= x_t, e1 * eps, e1 * x_t + e2 * (eps - x_t)) + rng.normal(0, 2e-3, eps.size)
    r = bilinear(eps, sig)
    assert abs(r.primary_modulus - e1) < 4 * r.primary.slope_standard_error
    assert abs(r.secondary_modulus - e2) < 4 * r.secondary.slope_standard_error
    assert r.transition_strain == pytest.approx(x_t, abs=0.01)


def test_ogden_crimp_ratio_0_3_transition_matches_section_3_2_7() -> None:
    """Section 3.2.7: the Ogden fit (Table B.1, CR 0.3) has its transition at 39.9 %.

    The two-line method on the model's uniaxial curve, sampled at 200 points up to the
    strain where its last-ten-point slope equals the measured secondary modulus of
    Table 3.2 (16.5 MPa), puts the transition at 40.0 %.
    """
    model = library.get("bilinear_0_3").model

    def curve(end: float) -> tuple[np.ndarray, np.ndarray]:
        eps = np.linspace(0.0, end, 200)
        return eps, model.uniaxial(1.0 + eps)

    end = brentq(lambda x: bilinear(*curve(x)).secondary_modulus - 16.5, 0.3, 0.8)
    r = bilinear(*curve(end))
    assert r.transition_strain * 100 == pytest.approx(39.9, abs=0.5)


def test_bilinear_errors() -> None:
    eps = np.linspace(0.0, 0.5, 26)
    with pytest.raises(FitError, match="not bilinear"):
        bilinear(eps, 0.1 * eps)
    with pytest.raises(FitError, match="only 1 point"):
        bilinear(eps, eps**2, primary_strain_limit=0.01)
    with pytest.raises(FitError, match="last 30 points"):
        bilinear(eps, eps**2, secondary_points=30)
    with pytest.raises(DataFormatError, match="same length"):
        bilinear(eps, eps[:-1])

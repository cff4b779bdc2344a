"""Closed-form hyperelastic models against physics and the dissertation's tables."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from pneumorph.checks import MODES
from pneumorph.materials.laws.hyperelastic import (
    MooneyRivlin,
    NeoHooke,
    Ogden,
    Yeoh,
    drucker_stability,
    mode_stretches,
    ogden_marc_to_felupe,
)

# Table A.4 (MSC Marc convention, N/mm^2)
MOLD_STAR_15 = Ogden(mu=(-6.503e-6, 0.2169, 1.372e-3), alpha=(-21.32, 1.180, 4.884))
SMOOTH_SIL_950 = Ogden(mu=(-0.3062, 0.0283, 6.596e-9), alpha=(-3.059, 4.597, 17.69))
ECOFLEX_0030 = Ogden(mu=(-0.0143, -3.646e-10, 9.594e-8), alpha=(-5.224, -0.1628, 11.38))

MODELS = {
    "neo-hooke": NeoHooke(c10=0.2),
    "mooney-rivlin-2": MooneyRivlin(c10=0.15, c01=0.03),
    "mooney-rivlin-3": MooneyRivlin(c10=0.15, c01=0.03, c11=0.002),
    "yeoh": Yeoh(c=(0.12, -0.004, 3e-4)),
    "ogden-mold-star-15": MOLD_STAR_15,
    "ogden-smooth-sil-950": SMOOTH_SIL_950,
}

# how many loaded directions share the work dW = n P dl along each mode's path
LOADED_DIRECTIONS = {"uniaxial": 1, "equibiaxial": 2, "planar": 1}


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("mode", MODES)
def test_nominal_stress_is_work_conjugate_to_the_energy(name: str, mode: str) -> None:
    """Along an incompressible path, dW/dl = n * P (n loaded directions)."""
    model = MODELS[name]
    lam = np.array([0.6, 0.85, 1.3, 2.0, 3.5]) if mode == "uniaxial" else np.array([1.1, 1.6, 2.5])
    h = 1e-6
    w_plus = model.energy(*mode_stretches(mode, lam + h))
    w_minus = model.energy(*mode_stretches(mode, lam - h))
    dwdl = (w_plus - w_minus) / (2 * h)
    p = model.nominal_stress(mode, lam)
    np.testing.assert_allclose(LOADED_DIRECTIONS[mode] * p, dwdl, rtol=1e-7, atol=1e-10)


@pytest.mark.parametrize("name", MODELS)
def test_small_strain_youngs_modulus_is_three_mu0(name: str) -> None:
    """Incompressible: E = dP/dl at l = 1 equals 3 mu0, in tension and compression."""
    model = MODELS[name]
    h = 1e-6
    e_mod = (model.uniaxial(1 + h) - model.uniaxial(1 - h)) / (2 * h)
    assert e_mod == pytest.approx(3 * model.shear_modulus, rel=1e-8)


@pytest.mark.parametrize("name", MODELS)
def test_unstrained_state_is_stress_free(name: str) -> None:
    for mode in MODES:
        assert abs(float(MODELS[name].nominal_stress(mode, 1.0))) < 1e-12


def test_neo_hooke_closed_forms() -> None:
    c10, lam = 0.25, np.linspace(0.5, 4.0, 8)
    m = NeoHooke(c10)
    np.testing.assert_allclose(m.uniaxial(lam), 2 * c10 * (lam - lam**-2), rtol=1e-14)
    np.testing.assert_allclose(m.equibiaxial(lam), 2 * c10 * (lam - lam**-5), rtol=1e-14)
    np.testing.assert_allclose(m.planar(lam), 2 * c10 * (lam - lam**-3), rtol=1e-14)


def test_mooney_rivlin_closed_form_uniaxial() -> None:
    c10, c01, lam = 0.2, 0.05, np.linspace(0.5, 4.0, 8)
    expected = 2 * (lam - lam**-2) * (c10 + c01 / lam)
    np.testing.assert_allclose(MooneyRivlin(c10, c01).uniaxial(lam), expected, rtol=1e-14)


def test_ogden_reduces_to_mooney_rivlin() -> None:
    """W_MR = C10(I1-3) + C01(I2-3) is Ogden with (mu, alpha) = (2 C10, 2), (-2 C01, -2)."""
    c10, c01 = 0.2, 0.05
    og = Ogden(mu=(2 * c10, -2 * c01), alpha=(2.0, -2.0))
    mr = MooneyRivlin(c10, c01)
    lam = np.linspace(0.4, 5.0, 12)
    for mode in MODES:
        np.testing.assert_allclose(og.nominal_stress(mode, lam), mr.nominal_stress(mode, lam), rtol=1e-12)
    assert og.shear_modulus == pytest.approx(mr.shear_modulus, rel=1e-14)


def test_yeoh_with_one_term_is_neo_hooke() -> None:
    lam = np.linspace(0.4, 5.0, 12)
    for mode in MODES:
        np.testing.assert_allclose(
            Yeoh(c=(0.3,)).nominal_stress(mode, lam), NeoHooke(0.3).nominal_stress(mode, lam), rtol=1e-14
        )


def test_initial_shear_moduli_of_the_dissertation_silicones() -> None:
    """mu0 = sum mu_n alpha_n / 2 from the printed Table A.4 numbers."""
    assert MOLD_STAR_15.shear_modulus == pytest.approx(0.13139, abs=5e-5)
    expected_ms15 = (-6.503e-6 * -21.32 + 0.2169 * 1.180 + 1.372e-3 * 4.884) / 2
    assert MOLD_STAR_15.shear_modulus == pytest.approx(expected_ms15, rel=1e-14)
    assert SMOOTH_SIL_950.shear_modulus == pytest.approx(
        (-0.3062 * -3.059 + 0.0283 * 4.597 + 6.596e-9 * 17.69) / 2, rel=1e-14
    )
    assert SMOOTH_SIL_950.shear_modulus == pytest.approx(0.5334, abs=1e-4)
    assert ECOFLEX_0030.shear_modulus == pytest.approx(0.03735, abs=1e-5)


def test_felupe_convention_sums_to_mu0() -> None:
    mu_f = ogden_marc_to_felupe(MOLD_STAR_15.mu, MOLD_STAR_15.alpha)
    assert sum(mu_f) == pytest.approx(MOLD_STAR_15.shear_modulus, rel=1e-12)
    assert mu_f[1] == pytest.approx(0.2169 * 1.180 / 2, rel=1e-14)


def test_invalid_parameters_are_rejected() -> None:
    with pytest.raises(ValueError, match="as many mu as alpha"):
        Ogden(mu=(1.0, 2.0), alpha=(1.0,))
    with pytest.raises(ValueError, match="non-zero"):
        Ogden(mu=(1.0,), alpha=(0.0,))
    with pytest.raises(ValueError, match="at least one"):
        Yeoh(c=())
    with pytest.raises(ValueError, match="unknown loading mode"):
        NeoHooke(0.1).nominal_stress("shear", 1.2)


def test_models_are_immutable() -> None:
    with pytest.raises(AttributeError):
        NeoHooke(0.1).c10 = 0.2  # type: ignore[misc]


@pytest.mark.parametrize("model", [NeoHooke(0.2), MOLD_STAR_15, SMOOTH_SIL_950, MooneyRivlin(0.2, 0.05)])
def test_drucker_stable_models(model) -> None:
    report = drucker_stability(model, (0.05, 20.0))
    assert report.is_stable
    assert "unstable" not in report.summary()


def test_drucker_detects_negative_c01_mooney_rivlin() -> None:
    """C01 < 0 makes W_2 negative: the model becomes unstable at some stretch, stable near 1."""
    report = drucker_stability(MooneyRivlin(c10=0.3, c01=-0.1), (0.05, 20.0))
    assert not report.is_stable
    limits = report.limits()
    for mode in MODES:
        lo, hi = limits[mode]
        assert lo < 1.0 < hi


def test_drucker_limit_is_no_later_than_loss_of_path_stiffness() -> None:
    """Drucker stability implies d(tau1 - tau3)/d(ln l) > 0 along the uniaxial path.

    For a Yeoh model with a negative second coefficient, the Kirchhoff stress l * P stops
    rising at a stretch l*; the reported stable range must end at or before l*, and the
    model must be stable in tension up to well below it.
    """
    model = Yeoh(c=(0.1, -0.01, 0.0))

    def path_stiffness(lam: float) -> float:
        h = 1e-6
        tau = lambda s: s * float(model.uniaxial(s))  # noqa: E731
        return (tau(lam * (1 + h)) - tau(lam * (1 - h))) / (2 * h)

    lam_star = brentq(path_stiffness, 1.5, 10.0)
    report = drucker_stability(model, (0.2, 10.0), num=2000)
    _, hi = report.limits()["uniaxial"]
    assert hi <= lam_star
    assert hi > 0.5 * (1 + lam_star)  # not absurdly early: the instability is near l*

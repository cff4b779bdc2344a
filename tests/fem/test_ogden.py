"""Hand-coded compressible Ogden kernel against an independent energy and closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.fem.ogden import OgdenCompressible
from pneumorph.materials.laws.hyperelastic import Ogden

# Table A.4 Mold Star 15 (Marc convention) and Table A.5 bulk modulus 119 kPa
MU = (-6.503e-6, 0.2169, 1.372e-3)
ALPHA = (-21.32, 1.180, 4.884)
K = 0.119


def energy(F: np.ndarray) -> np.ndarray:
    """Eq 2.12 from the eigenvalues of C, written independently of the kernel."""
    Ft = np.moveaxis(F, (0, 1), (-2, -1))
    c = np.linalg.eigvalsh(np.einsum("...ki,...kj->...ij", Ft, Ft))
    J = np.sqrt(c.prod(-1))
    lbar = J[..., None] ** (-1 / 3) * np.sqrt(c)
    W = sum(m / a * ((lbar**a).sum(-1) - 3) for m, a in zip(MU, ALPHA, strict=False))
    return W + 4.5 * K * (J ** (1 / 3) - 1) ** 2


def fd_stress(umat: OgdenCompressible, F: np.ndarray, h: float = 1e-6) -> np.ndarray:
    P = np.zeros_like(F)
    for i in range(3):
        for j in range(3):
            d = np.zeros_like(F)
            d[i, j] = h
            P[i, j] = (energy(F + d) - energy(F - d)) / (2 * h)
    return P


def fd_tangent(umat: OgdenCompressible, F: np.ndarray, h: float = 1e-6) -> np.ndarray:
    A = np.zeros((3, 3, 3, 3, *F.shape[2:]))
    for k in range(3):
        for m in range(3):
            d = np.zeros_like(F)
            d[k, m] = h
            A[:, :, k, m] = (umat.gradient([F + d, None])[0] - umat.gradient([F - d, None])[0]) / (2 * h)
    return A


@pytest.fixture
def umat() -> OgdenCompressible:
    return OgdenCompressible(MU, ALPHA, K)


def test_stress_and_tangent_at_random_deformations(umat: OgdenCompressible) -> None:
    rng = np.random.default_rng(42)
    F = np.eye(3)[:, :, None, None] + 0.3 * rng.standard_normal((3, 3, 4, 5))
    assert np.all(np.linalg.det(np.moveaxis(F, (0, 1), (-2, -1))) > 0)
    P = umat.gradient([F, None])[0]
    np.testing.assert_allclose(P, fd_stress(umat, F), atol=1e-7 * abs(P).max())
    A = umat.hessian([F, None])[0]
    np.testing.assert_allclose(A, fd_tangent(umat, F), atol=1e-7 * abs(A).max())
    # a hyperelastic tangent has major symmetry
    np.testing.assert_allclose(A, np.einsum("iJkL...->kLiJ...", A), atol=1e-12 * abs(A).max())


@pytest.mark.parametrize(
    "stretches",
    [(1.0, 1.0, 1.0), (1.3, 0.9, 0.9), (1.2, 1.2, 0.7), (1.1, 1.1, 1.1), (0.8, 1.0, 1.0)],
    ids=["identity", "uniaxial", "equibiaxial", "dilatation", "compression"],
)
def test_tangent_is_exact_at_equal_stretches(umat: OgdenCompressible, stretches: tuple) -> None:
    rot = np.linalg.qr(np.random.default_rng(1).standard_normal((3, 3)))[0]
    F = (rot @ np.diag(stretches))[:, :, None, None]
    A = umat.hessian([F, None])[0]
    assert np.all(np.isfinite(A))
    np.testing.assert_allclose(A, fd_tangent(umat, F), atol=1e-7 * abs(A).max())


def test_small_strain_moduli(umat: OgdenCompressible) -> None:
    """At F = I the tangent is isotropic linear elasticity with mu0 and K."""
    A = umat.hessian([np.eye(3)[:, :, None, None], None])[0][..., 0, 0]
    mu0 = Ogden(MU, ALPHA).shear_modulus
    assert A[0, 1, 0, 1] == pytest.approx(mu0, rel=1e-12)
    assert A[0, 0, 0, 0] == pytest.approx(K + 4 / 3 * mu0, rel=1e-12)
    assert A[0, 0, 1, 1] == pytest.approx(K - 2 / 3 * mu0, rel=1e-12)


def test_incompressible_limit_matches_closed_form_uniaxial() -> None:
    """With K >> mu0 and the lateral stress zeroed, P11 equals the closed form."""
    from scipy.optimize import brentq

    umat = OgdenCompressible(MU, ALPHA, bulk=1e6 * 0.1314)
    lam = 2.0

    def lateral(l2: float) -> float:
        F = np.diag([lam, l2, l2])[:, :, None, None]
        return float(umat.gradient([F, None])[0][1, 1, 0, 0])

    l2 = brentq(lateral, 0.5, 0.9, xtol=1e-15)
    P11 = umat.gradient([np.diag([lam, l2, l2])[:, :, None, None], None])[0][0, 0, 0, 0]
    assert P11 == pytest.approx(float(Ogden(MU, ALPHA).uniaxial(lam)), rel=1e-5)


def test_invalid_parameters() -> None:
    with pytest.raises(ValueError, match="equal length"):
        OgdenCompressible([1.0], [1.0, 2.0], 1.0)
    with pytest.raises(ValueError, match="non-zero"):
        OgdenCompressible([1.0], [0.0], 1.0)
    with pytest.raises(ValueError, match="bulk modulus"):
        OgdenCompressible([1.0], [2.0], 0.0)

"""The crimped-fibre Ogden law against an independent energy, its uniaxial closed form and the fast path."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.bimodal.paper import uniaxial_stress
from pneumorph.fem.fast.kernels import crimp_blend, crimped_fibre_3d
from pneumorph.fem.fast.system import SolidSystem3D
from pneumorph.fem.fibre import CrimpedFibreOgden
from pneumorph.fem.ogden import OgdenCompressible

# Table A.4 Ecoflex 0030 (Marc convention), its library bulk modulus; fibres straight at 10 % stretch
MU = (-0.0143, -3.646e-10, 9.594e-08)
ALPHA = (-5.224, -0.1628, 11.38)
K = 0.0338
STRAIGHT, SLOPE, BLEND = 1.1, 100.0, 0.05
#: the crimp's own stiffness before it straightens (the cast paper's, Table 3.2)
PRIMARY = 0.15


def energy(F: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Eq 2.12 plus the fibres' ``primary (l - 1)^2 / 2 + slope * G(l - straight)``, ``G`` the integral of the
    blend, written anew."""
    Ft = np.moveaxis(F, (0, 1), (-2, -1))
    C = np.einsum("...ki,...kj->...ij", Ft, Ft)
    c = np.linalg.eigvalsh(C)
    J = np.sqrt(c.prod(-1))
    lbar = J[..., None] ** (-1 / 3) * np.sqrt(c)
    W = sum(m / al * ((lbar**al).sum(-1) - 3) for m, al in zip(MU, ALPHA, strict=True))
    W = W + 4.5 * K * (J ** (1 / 3) - 1) ** 2
    stretch = np.sqrt(np.einsum("...i,...ij,...j->...", a, C, a))
    x = stretch - STRAIGHT
    G = np.where(x <= -BLEND, 0.0, np.where(x >= BLEND, x**2 / 2 + BLEND**2 / 6, (x + BLEND) ** 3 / (12 * BLEND)))
    return W + SLOPE * G + PRIMARY * (stretch - 1.0) ** 2 / 2


@pytest.fixture
def law() -> CrimpedFibreOgden:
    """Five elements of four points each, every element with a fibre direction of its own."""
    rng = np.random.default_rng(7)
    return CrimpedFibreOgden(MU, ALPHA, K, direction=rng.standard_normal((5, 3)), straight=STRAIGHT, slope=SLOPE,
                             blend=BLEND, primary=PRIMARY)


def deformations(law: CrimpedFibreOgden) -> np.ndarray:
    """FElupe's layout (3, 3, q = 4, c = 5): random gradients whose fibres are slack, in the blend and taut."""
    rng = np.random.default_rng(3)
    F = np.eye(3)[:, :, None, None] + 0.12 * rng.standard_normal((3, 3, 4, 5))
    a = law.direction.T  # (3, c)
    stretch = np.sqrt(np.einsum("Jc,iJqc,iLqc,Lc->qc", a, F, F, a))
    x = stretch - STRAIGHT
    assert np.any(x < -BLEND) and np.any(abs(x) < BLEND) and np.any(x > BLEND)
    return F


def test_stress_and_tangent_against_finite_differences(law: CrimpedFibreOgden) -> None:
    F = deformations(law)
    a = np.broadcast_to(law.direction[None], (4, 5, 3))  # per point, (q, c, 3)
    h = 1e-6
    P = law.gradient([F, None])[0]
    A = law.hessian([F, None])[0]
    P_fd = np.zeros_like(F)
    A_fd = np.zeros_like(A)
    for k in range(3):
        for m in range(3):
            d = np.zeros_like(F)
            d[k, m] = h
            P_fd[k, m] = (energy(F + d, a) - energy(F - d, a)) / (2 * h)
            A_fd[:, :, k, m] = (law.gradient([F + d, None])[0] - law.gradient([F - d, None])[0]) / (2 * h)
    np.testing.assert_allclose(P, P_fd, atol=1e-7 * abs(P).max())
    np.testing.assert_allclose(A, A_fd, atol=1e-6 * abs(A).max())
    np.testing.assert_allclose(A, np.einsum("iJkL...->kLiJ...", A), atol=1e-12 * abs(A).max())


def test_fast_layout_and_blocks_equal_the_felupe_path(law: CrimpedFibreOgden) -> None:
    """Points ordered by element (the fast assembly's order) with the tangent's blocks (i, k) only."""
    F = deformations(law)
    P, A = law.gradient([F, None])[0], law.hessian([F, None])[0]
    Fp = np.ascontiguousarray(F.transpose(0, 1, 3, 2)).reshape(3, 3, 20)
    pairs = [(0, 0), (0, 1), (1, 2)]
    Pp, Ab, _ = law.kernel(Fp, True, pairs=pairs)
    np.testing.assert_allclose(Pp, P.transpose(0, 1, 3, 2).reshape(3, 3, 20), rtol=1e-13, atol=1e-15)
    full = A.transpose(0, 1, 2, 3, 5, 4).reshape(3, 3, 3, 3, 20)
    for q, (i, k) in enumerate(pairs):
        np.testing.assert_allclose(Ab[q], full[i, :, k, :], rtol=1e-12, atol=1e-14)


def test_uniaxial_closed_form_along_and_across() -> None:
    """Pulled along the fibres, the law is the matrix plus ``primary (l - 1)``, and ``slope (l - straight)`` more
    once straight; pulled across, the ideal crimp (``primary = 0``) leaves the matrix alone at every stretch."""
    matrix = OgdenCompressible(MU, ALPHA, K)
    lam = np.array([0.8, 1.0, 1.02, STRAIGHT - BLEND, STRAIGHT, STRAIGHT + BLEND, 1.3, 1.6])
    fibre = SLOPE * np.array([0, 0, 0, 0, BLEND / 4, BLEND, 1.3 - STRAIGHT, 1.6 - STRAIGHT])
    for primary in (0.0, PRIMARY):
        law = CrimpedFibreOgden(MU, ALPHA, K, [1.0, 0.0, 0.0], STRAIGHT, SLOPE, BLEND, primary=primary)
        extra = uniaxial_stress(law, lam) - uniaxial_stress(matrix, lam)
        np.testing.assert_allclose(extra, fibre + primary * (lam - 1.0), rtol=1e-9, atol=1e-12)
    ideal = CrimpedFibreOgden(MU, ALPHA, K, [1.0, 0.0, 0.0], STRAIGHT, SLOPE, BLEND)
    np.testing.assert_allclose(uniaxial_stress(ideal, lam, axis=1), uniaxial_stress(matrix, lam, axis=1),
                               rtol=1e-12, atol=1e-15)


def test_blend_is_continuous_with_its_slope() -> None:
    x = STRAIGHT + BLEND * np.array([-1 - 1e-12, -1 + 1e-12, 1 - 1e-12, 1 + 1e-12])
    g, dg = crimp_blend(x, STRAIGHT, BLEND)
    np.testing.assert_allclose(g, [0, 0, BLEND, BLEND], atol=1e-11)
    np.testing.assert_allclose(dg, [0, 0, 1, 1], atol=1e-10)


def test_fibre_kernel_alone_is_zero_when_slack() -> None:
    F = np.diag([1.0 + 0.9 * (STRAIGHT - BLEND - 1.0), 0.7, 1.4])[..., None]
    P, A = crimped_fibre_3d(F, np.array([[1.0], [0.0], [0.0]]), STRAIGHT, SLOPE, BLEND)
    assert not np.any(P) and A is not None and not np.any(A)


def test_a_fibre_layer_in_the_fast_3d_assembly() -> None:
    """The fast assembler takes the law as it takes the Ogden matrix: tangent equals the residual's derivative."""
    import felupe as fem

    mesh = fem.Cube(n=2)
    field = fem.FieldContainer([fem.Field(fem.RegionHexahedron(mesh), dim=3)])
    law = CrimpedFibreOgden(MU, ALPHA, K, [1.0, 0.2, 0.0], STRAIGHT, SLOPE, BLEND, primary=PRIMARY)
    solid = fem.SolidBody(law, field)
    dof0, dof1 = fem.dof.partition(field, {"x0": fem.Boundary(field[0], fx=0.0)})
    system = SolidSystem3D([solid], field, dof1, dof0)
    system.single_precision = False
    u = 0.2 * mesh.points.ravel() * np.repeat([[1.0, -0.3, 0.1]], len(mesh.points), axis=0).ravel()
    r, _ = system.residual(u)
    K_ = system.tangent().toarray()  # the full symmetric matrix
    h = 1e-6
    j = int(dof1[5])
    du = np.zeros_like(u)
    du[j] = h
    col = (system.residual(u + du)[0] - system.residual(u - du)[0])[dof1] / (2 * h)
    np.testing.assert_allclose(K_[:, 5], col, atol=1e-6 * abs(col).max())
    # felupe's own assembly of the same law gives the same residual
    field[0].values[:] = u.reshape(-1, 3)
    np.testing.assert_allclose(r[dof1], solid.assemble.vector(field).toarray().ravel()[dof1], rtol=1e-9,
                               atol=1e-12 * abs(r).max())


@pytest.mark.parametrize("kwargs", [dict(direction=[0.0, 0.0, 0.0]), dict(direction=[1.0, 0.0]),
                                    dict(straight=1.01), dict(slope=-1.0), dict(blend=0.0),
                                    dict(primary=-0.1), dict(primary=float("nan"))])
def test_invalid_parameters(kwargs: dict) -> None:
    args = dict(direction=[1.0, 0.0, 0.0], straight=STRAIGHT, slope=SLOPE, blend=BLEND) | kwargs
    with pytest.raises(ValueError):
        CrimpedFibreOgden(MU, ALPHA, K, **args)


def test_the_plane_strain_assembly_refuses_it() -> None:
    """The 2D kernels have no fibres: a fibre law there would silently be its matrix."""
    import felupe as fem

    from pneumorph.fem.fast.system import PlaneStrainSystem

    mesh = fem.Rectangle(n=2)
    field = fem.FieldContainer([fem.FieldPlaneStrain(fem.RegionQuad(mesh), dim=2)])
    solid = fem.SolidBody(CrimpedFibreOgden(MU, ALPHA, K, [1.0, 0.0, 0.0], STRAIGHT, SLOPE, BLEND), field)
    dof0, dof1 = fem.dof.partition(field, {"x0": fem.Boundary(field[0], fx=0.0)})
    with pytest.raises(TypeError, match="crimped-fibre"):
        PlaneStrainSystem([solid], field, dof1, dof0)

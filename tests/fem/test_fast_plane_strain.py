"""The vectorised plane-strain assembly against FElupe's assembly of the same items.

A 2-unit actuator of the 2D model (body and layer Ogden, neo-Hooke filler, follower
pressure on the cavity walls) in a non-trivial deformed state: the residual, the active
block of the tangent, the cavity area and the smallest det F must be FElupe's to rounding.
"""

from __future__ import annotations

import felupe as fem
import numpy as np
import pytest
from felupe.tools._newton import fun_items, jac_items

from pneumorph.fem import OgdenCompressible, cavity_volume
from pneumorph.fem.fast.kernels import neo_hooke_plane_strain, ogden_plane_strain
from pneumorph.fem.fast.system import PlaneStrainSystem
from pneumorph.models.fe import Reduced2D

# Table A.4 Mold Star 15 (Marc convention), Table A.5 bulk modulus
MU = (-6.503e-6, 0.2169, 1.372e-3)
ALPHA = (-21.32, 1.180, 4.884)
K = 0.119


def plane(F2: np.ndarray) -> np.ndarray:
    """(n, 2, 2) in-plane gradients as FElupe's (3, 3, 1, n) with F33 = 1."""
    F = np.zeros((3, 3, 1, len(F2)))
    F[:2, :2, 0] = np.moveaxis(F2, 0, -1)
    F[2, 2] = 1.0
    return F


@pytest.fixture(scope="module")
def gradients() -> np.ndarray:
    rng = np.random.default_rng(3)
    F2 = np.eye(2) + 0.25 * rng.standard_normal((200, 2, 2))
    F2[0] = np.eye(2)  # repeated stretches: undeformed, equibiaxial, one stretch = F33
    F2[1] = 1.2 * np.eye(2)
    F2[2] = np.diag([1.3, 1.0])
    assert np.all(np.linalg.det(F2) > 0)
    return F2


def test_ogden_kernel_is_the_3d_kernel_in_plane_strain(gradients: np.ndarray) -> None:
    umat = OgdenCompressible(MU, ALPHA, K)
    F = plane(gradients)
    P3 = umat.gradient([F, None])[0][:2, :2, 0]
    A3 = umat.hessian([F, None])[0][:2, :2, :2, :2, 0]
    P, A, J = ogden_plane_strain(np.moveaxis(gradients, 0, -1), MU, ALPHA, K)
    np.testing.assert_allclose(P, P3, rtol=0, atol=1e-12 * abs(P3).max())
    np.testing.assert_allclose(A, A3, rtol=0, atol=1e-12 * abs(A3).max())
    np.testing.assert_allclose(J, np.linalg.det(gradients), rtol=1e-14)


def test_neo_hooke_kernel_is_felupes(gradients: np.ndarray) -> None:
    umat = fem.NeoHookeCompressible(mu=0.02, lmbda=0.3)
    F = plane(gradients)
    P, A, _ = neo_hooke_plane_strain(np.moveaxis(gradients, 0, -1), 0.02, 0.3)
    P3 = umat.gradient([F, None])[0][:2, :2, 0]
    A3 = umat.hessian([F, None])[0][:2, :2, :2, :2, 0]
    np.testing.assert_allclose(P, P3, rtol=0, atol=1e-13 * abs(P3).max())
    np.testing.assert_allclose(A, A3, rtol=0, atol=1e-13 * abs(A3).max())


@pytest.fixture(scope="module")
def deformed_actuator():
    model = Reduced2D(2)
    mesh, body, set_pressure = model.build("01")
    field = body.field
    X = field[0].region.mesh.points
    rng = np.random.default_rng(1)
    u = np.column_stack([0.05 * np.sin(X[:, 1] / 3.0) + 0.02 * X[:, 0] / 10, 0.08 * np.cos(X[:, 0] / 7.0)])
    u += 0.004 * rng.standard_normal(u.shape)
    u[mesh.base_points] = 0.0
    field[0].values[:] = u
    set_pressure(0.03)  # 30 kPa, filler at E(30 kPa)
    return mesh, body


def test_residual_and_tangent_equal_felupes(deformed_actuator) -> None:
    mesh, body = deformed_actuator
    field, items, dof1, dof0 = body.field, body.items, body.dof1, body.dof0
    system = PlaneStrainSystem(items, field, dof1, dof0)
    r, jmin = system.residual(field[0].values.ravel().copy())
    K_fast = system.tangent()
    r_fe = fun_items(items, field)
    K_fe = jac_items(items, field).tocsr()[dof1][:, dof1]
    assert np.abs(r_fe).max() > 1e-3  # a real, unbalanced state
    np.testing.assert_allclose(r, r_fe, rtol=0, atol=1e-12 * np.abs(r_fe).max())
    assert abs(K_fast - K_fe).max() <= 1e-12 * abs(K_fe).max()
    K_fe.sort_indices()  # the pattern is FElupe's, entry for entry: none missing, none extra
    assert np.array_equal(system.indptr, K_fe.indptr) and np.array_equal(system.indices, K_fe.indices)
    # each wall element's follower-load stiffness is not symmetric, but the walls of a
    # closed cavity make the load conservative (potential -p V): the sum is symmetric
    K_p = jac_items([body.pressure], field).tocsr()
    walls = body.pressure.field[0].region.mesh.cells[:1]
    one = fem.SolidBodyPressure(fem.FieldContainer([fem.FieldPlaneStrain(
        fem.RegionQuadraticQuadBoundary(fem.Mesh(field[0].region.mesh.points, walls, "quad8"),
                                        mask=mesh.cavity_points, ensure_3d=True), dim=2)]), pressure=0.03)
    one.field.link(field)
    K_one = one.assemble.matrix()
    assert abs(K_one - K_one.T).max() > 1e-3 * abs(K_one).max()
    assert abs(K_p - K_p.T).max() < 1e-12 * abs(K_p).max()
    F = field[0].extract(grad=True, sym=False, add_identity=True)
    assert jmin == pytest.approx(float(np.min(fem.math.det(F))), rel=1e-13)
    area = system.cavity_volume(field[0].values.ravel())
    assert area == pytest.approx(cavity_volume(body.walls), rel=1e-13)


def test_unsupported_items_are_refused() -> None:
    mesh = fem.Rectangle(n=3)
    field = fem.FieldContainer([fem.FieldPlaneStrain(fem.RegionQuad(mesh), dim=2)])
    dof0, dof1 = fem.dof.partition(field, {"x0": fem.Boundary(field[0], fx=0.0)})
    with pytest.raises(TypeError, match="no fast plane-strain kernel for NeoHooke"):
        PlaneStrainSystem([fem.SolidBody(fem.NeoHooke(mu=1.0, bulk=2.0), field)], field, dof1, dof0)
    field3 = fem.FieldContainer([fem.Field(fem.RegionHexahedron(fem.Cube(n=2)), dim=3)])
    with pytest.raises(TypeError, match="needs FieldPlaneStrain fields"):
        PlaneStrainSystem([fem.SolidBody(OgdenCompressible(MU, ALPHA, K), field3)], field3, dof1, dof0)

"""The vectorised 3D assembly against FElupe's assembly of the same items.

A 1-unit half actuator of the 3D model (body and layer Ogden, follower pressure on the
cavity walls, hex20 at 3 mm) in a non-trivial deformed state that satisfies the
boundary conditions: the residual, the active block of the tangent (of which the fast
system assembles the upper triangle), the cavity volume and the smallest det F must be
FElupe's to rounding.
"""

from __future__ import annotations

import felupe as fem
import numpy as np
import pytest
import scipy.sparse as sp
from felupe.tools._newton import fun_items, jac_items

from pneumorph.fem import OgdenCompressible, StepSettings, cavity_volume
from pneumorph.fem.fast.kernels import ogden_3d, principal_3d
from pneumorph.fem.fast.newton import FastSubstep
from pneumorph.fem.fast.system import SolidSystem3D
from pneumorph.fem.linear import PardisoPattern, SuperLUPattern
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D

# Table A.4 Mold Star 15 (Marc convention), Table A.5 bulk modulus
MU = (-6.503e-6, 0.2169, 1.372e-3)
ALPHA = (-21.32, 1.180, 4.884)
K = 0.119


def test_ogden_kernel_is_the_felupe_material() -> None:
    rng = np.random.default_rng(4)
    F = np.eye(3)[..., None] + 0.2 * rng.standard_normal((3, 3, 300))
    F[..., 0] = np.eye(3)  # repeated stretches: undeformed, equibiaxial, uniaxial
    F[..., 1] = np.diag([1.2, 1.2, 0.9])
    F[..., 2] = np.diag([1.3, 1.0, 1.0])
    F = F[..., np.linalg.det(np.moveaxis(F, -1, 0)) > 0.2]
    umat = OgdenCompressible(MU, ALPHA, K)
    P3 = umat.gradient([F[:, :, None], None])[0][:, :, 0]
    A3 = umat.hessian([F[:, :, None], None])[0][..., 0, :]
    P, A, J = ogden_3d(F, MU, ALPHA, K)
    P_only, none, _ = ogden_3d(F, MU, ALPHA, K, tangent=False)
    np.testing.assert_allclose(P, P3, rtol=0, atol=1e-12 * abs(P3).max())
    np.testing.assert_allclose(A, A3, rtol=0, atol=1e-12 * abs(A3).max())
    np.testing.assert_allclose(J, np.linalg.det(np.moveaxis(F, -1, 0)), rtol=1e-13)
    assert none is None and np.array_equal(P_only, P)
    pairs = [(0, 0), (0, 2), (2, 1)]
    _, blocks, _ = ogden_3d(F, MU, ALPHA, K, pairs=pairs)
    for m, (i, k) in enumerate(pairs):
        np.testing.assert_allclose(blocks[m], A[i, :, k], rtol=0, atol=1e-14 * abs(A3).max())


def test_closed_form_eigen_decomposition_of_C() -> None:
    """Closed form where the eigenvalues are apart, LAPACK where they (nearly) coincide."""
    rng = np.random.default_rng(2)
    F = np.eye(3)[..., None] + 0.3 * rng.standard_normal((3, 3, 500))
    F[..., 0] = np.eye(3)
    F[..., 1] = np.diag([1.2, 1.2, 0.9])
    F[..., 2] = np.eye(3) + 1e-7 * rng.standard_normal((3, 3))  # gaps far below 1e-4
    F[..., 3] = np.diag([1.0, 1.0 + 1e-3, 1.3])  # a gap of 2e-3 in the closed form
    C = np.einsum("kIp,kJp->pIJ", F, F)
    c, N = principal_3d(F)  # (a, p), (a, J, p)
    c_ref = np.linalg.eigvalsh(C)
    np.testing.assert_allclose(c.T, c_ref, rtol=0, atol=1e-13 * c_ref.max())
    np.testing.assert_allclose(np.einsum("aip,ap,ajp->pij", N, c, N), C, rtol=0, atol=1e-13 * c_ref.max())
    np.testing.assert_allclose(np.einsum("aip,bip->pab", N, N), np.broadcast_to(np.eye(3), C.shape), atol=1e-14)


@pytest.fixture(scope="module")
def deformed_actuator():
    model = Full3D(1, unit=UnitSpec(element_size=3.0))
    mesh, body, _ = model.build("1")
    field = body.field
    X = field[0].region.mesh.points
    rng = np.random.default_rng(1)
    u = np.column_stack(
        [0.05 * np.sin(X[:, 1] / 3.0), 0.08 * np.cos(X[:, 0] / 7.0), 0.03 * np.sin(X[:, 0] / 5.0)]
    )
    u += 0.004 * rng.standard_normal(u.shape)
    u[mesh.base_points] = 0.0
    u[mesh.symmetry_points, 2] = 0.0  # the state satisfies the boundary conditions
    field[0].values[:] = u
    body.pressure.update(0.03)
    return mesh, body


def test_residual_and_tangent_equal_felupes(deformed_actuator) -> None:
    _, body = deformed_actuator
    field, items, dof1, dof0 = body.field, body.items, body.dof1, body.dof0
    system = SolidSystem3D(items, field, dof1, dof0)
    r, jmin = system.residual(field[0].values.ravel().copy())
    upper = system.tangent_data()
    K_fast = system.tangent()
    r_fe = fun_items(items, field)  # (also updates the kinematics the tangent uses)
    K_fe = jac_items(items, field).tocsr()[dof1][:, dof1]
    assert np.abs(r_fe).max() > 1e-3  # a real, unbalanced state
    np.testing.assert_allclose(r, r_fe, rtol=0, atol=1e-12 * np.abs(r_fe).max())
    assert abs(K_fast - K_fe).max() <= 1e-12 * abs(K_fe).max()
    assert upper.size == system.nnz and system.nnz < 0.6 * K_fe.nnz  # the upper triangle only
    triu = sp.triu(K_fe).tocsr()  # ... of FElupe's pattern, entry for entry: none missing, none extra
    triu.sort_indices()
    assert np.array_equal(system.indptr, triu.indptr) and np.array_equal(system.indices, triu.indices)
    F = field[0].extract(grad=True, sym=False, add_identity=True)
    assert jmin == pytest.approx(float(np.min(fem.math.det(F))), rel=1e-13)
    volume = system.cavity_volume(field[0].values.ravel())
    assert volume == pytest.approx(cavity_volume(body.walls), rel=1e-13)


def test_pressure_stiffness_is_symmetric_on_the_active_dofs(deformed_actuator) -> None:
    """The assumption behind the symmetric solver, checked on FElupe's own matrices.

    One wall face's load stiffness is far from symmetric; the sum over the half cavity,
    restricted to the active dofs of a state with the rim on the symmetry plane, is
    symmetric to rounding.
    """
    mesh, body = deformed_actuator
    field, dof1 = body.field, body.dof1
    pressure = body.pressure
    fun_items([pressure], field)
    K_p = jac_items([pressure], field).tocsr()[dof1][:, dof1]
    assert abs(K_p - K_p.T).max() < 1e-12 * abs(K_p).max()
    walls = pressure.field[0].region
    one = fem.SolidBodyPressure(
        fem.FieldContainer([fem.Field(type(walls)(fem.Mesh(walls.mesh.points, walls.mesh.cells[:1], "hexahedron20"),
                                                  mask=mesh.cavity_points), dim=3)]),
        pressure=0.03,
    )
    one.field.link(field)
    one.assemble.vector(field=one.field)
    K_one = one.assemble.matrix()
    assert abs(K_one - K_one.T).max() > 1e-3 * abs(K_one).max()


@pytest.mark.parametrize("factory", [PardisoPattern, SuperLUPattern])
def test_symmetric_pattern_solvers(factory) -> None:
    import scipy.sparse as sp

    rng = np.random.default_rng(0)
    M = sp.random(40, 40, density=0.1, random_state=1) + sp.eye(40) * 0.5
    A = (M + M.T).tocsr()  # symmetric, indefinite in general
    upper = sp.triu(A, format="csr")
    upper.sort_indices()
    b = rng.standard_normal(40)
    solver = factory(upper.indptr, upper.indices, symmetric=True)
    x = solver(upper.data, b)
    np.testing.assert_allclose(A @ x, b, atol=1e-10)
    solver.factorize(2.0 * upper.data)
    np.testing.assert_allclose(A @ solver.solve(b), b / 2.0, atol=1e-10)
    assert solver.factorisations == 2


def test_single_precision_factorisation() -> None:
    """Single precision: half the factorisation cost, solutions to single-precision accuracy."""
    import scipy.sparse as sp

    rng = np.random.default_rng(1)
    M = sp.random(60, 60, density=0.1, random_state=2)
    A = (M + M.T + 4.0 * sp.eye(60)).tocsr()
    upper = sp.triu(A, format="csr")
    upper.sort_indices()
    b = rng.standard_normal(60)
    x = PardisoPattern(upper.indptr, upper.indices, symmetric=True, single=True)(upper.data, b)
    error = np.linalg.norm(A @ x - b) / np.linalg.norm(b)
    assert x.dtype == np.float64 and 1e-12 < error < 1e-5  # a single-precision solve


def test_kept_tangent_reaches_newtons_equilibrium() -> None:
    """Chord iterations with refresh and Anderson acceleration against Newton's method.

    Both stop at the same criterion from the same start (the undeformed state at 20 kPa);
    the states differ by far less than the displacements times the tolerance allows. The
    kept tangents are factorised in single precision (``SolidSystem3D.single_precision``).
    """
    settings = StepSettings(increments=1, substeps=1, max_iterations=40)
    results = []
    for options in ({}, {"reuse": 0.3, "depth": 4}):
        _, body, set_pressure = Full3D(1, unit=UnitSpec(element_size=3.0)).build("0")
        set_pressure(0.02)
        system = SolidSystem3D(body.items, body.field, body.dof1, body.dof0)
        substep = FastSubstep(system, **options)
        iterations, cause = substep(body.field, settings)
        assert cause is None
        results.append((body.displacement.copy(), iterations, substep.factorisations))
    (u_newton, it_newton, fact_newton), (u_chord, _, fact_chord) = results
    assert fact_newton == it_newton and fact_chord < fact_newton
    assert abs(u_newton).max() > 0.5  # mm: a real inflation
    np.testing.assert_allclose(u_chord, u_newton, rtol=0, atol=1e-6)

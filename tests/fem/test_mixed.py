"""The volumetric term on the element's mean dilatation: its tangent is the derivative of its residual, a
homogeneous deformation gives the displacement form's forces, and a nearly incompressible cantilever bends as
beam theory says where the displacement form locks."""

from __future__ import annotations

import felupe as fem
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from pneumorph.fem import OgdenCompressible
from pneumorph.fem.fast import PlaneStrainSystem, SolidSystem3D
from pneumorph.fem.fast.mixed import MIXED_BULK_RATIO

MU, ALPHA = [0.05, 0.02], [2.5, -1.5]  # shear modulus sum mu alpha / 2 = 0.0475 MPa


def shear_modulus() -> float:
    return sum(m * a for m, a in zip(MU, ALPHA, strict=True)) / 2


def system(dim: int, mesh, bulk: float, mixed: bool, fix: str = "x0"):  # type: ignore[no-untyped-def]
    if dim == 2:
        region = fem.RegionQuadraticQuad(mesh)
        field = fem.FieldContainer([fem.FieldPlaneStrain(region, dim=2)])
        cls = PlaneStrainSystem
    else:
        region = fem.RegionQuadraticHexahedron(mesh)
        field = fem.FieldContainer([fem.Field(region, dim=3)])
        cls = SolidSystem3D
    solid = fem.SolidBody(OgdenCompressible(MU, ALPHA, bulk, mixed=mixed), field)
    boundaries = {"x0": fem.Boundary(field[0], fx=0.0)}
    dof0, dof1 = fem.dof.partition(field, boundaries)
    return cls([solid], field, dof1, dof0), field, dof1


def mesh2d(nx: int = 3, ny: int = 2, length: float = 2.0):  # type: ignore[no-untyped-def]
    return fem.Rectangle(b=(length, 1.0), n=(nx + 1, ny + 1)).add_midpoints_edges()


def mesh3d(nx: int = 2, length: float = 2.0):  # type: ignore[no-untyped-def]
    return fem.Cube(b=(length, 1.0, 1.0), n=(nx + 1, 2, 2)).add_midpoints_edges()


@pytest.mark.parametrize("dim", [2, 3])
def test_the_tangent_is_the_derivative_of_the_residual(dim: int) -> None:
    """Central differences of the residual along random directions equal the tangent's products: the rank-one
    element term and the pressure's geometric term are those of the mean-dilatation energy."""
    mesh = mesh2d() if dim == 2 else mesh3d()
    sys_, field, dof1 = system(dim, mesh, bulk=50 * shear_modulus(), mixed=True)
    rng = np.random.default_rng(7)
    u = 0.03 * rng.normal(size=field[0].values.size)
    u[np.setdiff1d(np.arange(u.size), dof1)] = 0.0
    sys_.residual(u)
    K = sys_.tangent()
    h = 1e-6
    for _ in range(3):
        v = np.zeros_like(u)
        v[dof1] = rng.normal(size=dof1.size)
        rp, _ = sys_.residual(u + h * v)
        rm, _ = sys_.residual(u - h * v)
        fd = (rp - rm)[dof1] / (2 * h)
        assert np.allclose(K @ v[dof1], fd, rtol=1e-6, atol=1e-7 * np.abs(fd).max())


@pytest.mark.parametrize("dim", [2, 3])
def test_a_homogeneous_deformation_gives_the_displacement_forms_forces(dim: int) -> None:
    """Where J is the same at every point the element's dilatation is J: the residuals are the same."""
    mesh = mesh2d() if dim == 2 else mesh3d()
    F = np.array([[1.1, 0.05, 0.0], [0.02, 0.95, 0.0], [0.0, 0.0, 1.0]])[:dim, :dim]
    u = (mesh.points[:, :dim] @ (F - np.eye(dim)).T).ravel()
    forces = []
    for mixed in (False, True):
        sys_, _, _ = system(dim, mesh, bulk=50 * shear_modulus(), mixed=mixed)
        forces.append(sys_.residual(u)[0])
    assert np.abs(forces[0]).max() > 1e-3
    assert np.allclose(forces[1], forces[0], rtol=0, atol=1e-12 * np.abs(forces[0]).max())


def cantilever_tip(dim: int, nu: float, mixed: bool, nx: int, ny: int) -> float:
    """Tip deflection (mm) of a clamped 10 x 1 (x 1) mm beam of ``nx`` x ``ny`` (x ``ny``) quadratic elements under a
    small end shear (linear: one solve of the tangent at rest)."""
    G = shear_modulus()
    length = 10.0
    if dim == 2:
        mesh = fem.Rectangle(b=(length, 1.0), n=(nx + 1, ny + 1)).add_midpoints_edges()
    else:
        mesh = fem.Cube(b=(length, 1.0, 1.0), n=(nx + 1, ny + 1, ny + 1)).add_midpoints_edges()
    sys_, field, dof1 = system(dim, mesh, 2 * G * (1 + nu) / (3 * (1 - 2 * nu)), mixed)
    sys_.residual(np.zeros(field[0].values.size))
    end = np.isclose(mesh.points[:, 0], length)
    f = np.zeros(field[0].values.size)
    f[dim * np.flatnonzero(end) + 1] = 1e-6 / end.sum()  # 1 uN over the end face's nodes
    u = np.zeros_like(f)
    u[dof1] = spla.spsolve(sys_.tangent().tocsc(), f[dof1])
    return float(u.reshape(-1, dim)[end, 1].mean())


@pytest.mark.parametrize(("dim", "coarse", "fine"), [(2, (20, 2), (80, 16)), (3, (10, 1), (20, 4))])
def test_a_nearly_incompressible_cantilever_does_not_lock(dim: int, coarse: tuple[int, int],
                                                          fine: tuple[int, int]) -> None:
    """nu = 0.499 (K = 500 G): on a coarse mesh (in 3D one element through the thickness, as the actuator's walls)
    the mixed form is within 2 % of the refined answer, where the displacement form is stiffer; refined, both forms
    reach the same beam (in 2D: the displacement form converges slowly; measured: 2D 0.02073 against 0.02096 mm,
    displacement 0.02034; 3D 0.02777 against 0.02758 mm, displacement 0.02567)."""
    refined = cantilever_tip(dim, 0.499, True, *fine)
    if dim == 2:
        assert cantilever_tip(dim, 0.499, False, *fine) == pytest.approx(refined, rel=0.01)
    mixed = cantilever_tip(dim, 0.499, True, *coarse)
    displacement = cantilever_tip(dim, 0.499, False, *coarse)
    assert mixed == pytest.approx(refined, rel=0.02)
    assert abs(displacement / refined - 1) > 1.5 * abs(mixed / refined - 1)


def test_the_default_threshold_is_a_poissons_ratio_of_045() -> None:
    nu = (3 * MIXED_BULK_RATIO - 2) / (2 * (3 * MIXED_BULK_RATIO + 1))
    assert nu == pytest.approx(0.45, abs=1e-12)


def test_felupes_path_refuses_the_mixed_form() -> None:
    with pytest.raises(NotImplementedError, match="fast assemblers only"):
        OgdenCompressible(MU, ALPHA, 1.0, mixed=True).gradient([np.eye(3).reshape(3, 3, 1, 1), None])

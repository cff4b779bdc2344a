"""A homogeneously stretched unit block in FElupe, for checking materials against closed forms.

3D: the cube ``[0, 1]^3`` (hex8) has symmetry conditions on the faces ``x = 0``, ``y = 0``,
``z = 0`` (normal displacement zero) and a prescribed normal displacement on the loaded
face(s); all other faces are traction free:

============  =============================================================
mode          loaded faces
============  =============================================================
uniaxial      ``x = 1``: ``u_x = l - 1``
equibiaxial   ``x = 1``: ``u_x = l - 1`` and ``y = 1``: ``u_y = l - 1``
planar        ``x = 1``: ``u_x = l - 1`` and ``y = 1``: ``u_y = 0`` (stretch 1)
============  =============================================================

2D (``plane_strain=True``, mode "planar" only): the square ``[0, 1]^2`` (quad4) in plane
strain, symmetric on ``x = 0`` and ``y = 0``, ``u_x = l - 1`` on ``x = 1``, ``y = 1`` free;
the out-of-plane stretch is 1, so this is planar tension with the free direction in-plane.

The exact solution is homogeneous, so it lies in the finite-element space and the FE
solution reproduces the material law exactly (up to the solver tolerance). The nominal
stress is the reaction force on the face ``x = 1`` in ``x`` divided by its undeformed
area (1; per unit thickness in 2D).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import felupe as fem
import numpy as np

from pneumorph.materials.laws.hyperelastic import mode_stretches


@dataclass(frozen=True)
class BlockResult:
    """The block at each requested stretch.

    Attributes
    ----------
    stretch : ndarray
        The requested stretches of the loaded direction.
    nominal_stress : ndarray
        Reaction force on ``x = 1`` over the undeformed area.
    lateral_stretch : ndarray
        Stretch of the traction-free direction (``z``; ``y`` in plane strain).
    volume_change : ndarray
        Largest ``|det F - 1|`` over the quadrature points.
    iterations : int
        Newton iterations of the whole path.
    """

    stretch: np.ndarray
    nominal_stress: np.ndarray
    lateral_stretch: np.ndarray
    volume_change: np.ndarray
    iterations: int


def _ramp(stretches: tuple[float, ...], step: float) -> list[float]:
    """Stretches from 1 through all targets, increments at most ``step`` in log-stretch."""
    ramp: list[float] = []
    last = 1.0
    for target in sorted(stretches, key=lambda s: abs(np.log(s))):
        n = max(1, int(np.ceil(abs(np.log(target / last)) / step)))
        ramp.extend((last * np.exp(np.linspace(0, np.log(target / last), n + 1)[1:])).tolist())
        ramp[-1] = target
        last = target
    return ramp


def _convergence_check(
    xtol: float, ftol: float, ndisplacement: int
) -> Callable[..., tuple[float, float, bool]]:
    """Newton convergence on the size of the correction (for ``newtonraphson(check=)``).

    A nearly incompressible block has a residual floor: a displacement is stored to
    ~1e-16 (relative), so J to ~1e-16 and the pressure ``K (J - 1)`` to ~1e-16 K. With
    K ~ 1e7 times the stress that is ~1e-8 of the reactions, and FElupe's default
    criterion (free residual over reactions below ~1.5e-8) may never be met. The
    corrections themselves go down to ~1e-13 and converge quadratically: after a
    correction ``dx`` the error is ~ (K / mu) dx^2, so ``xtol = 1e-10`` leaves ~1e-13.
    The residual is only required to be below the loose ``ftol``. Only the displacement
    dofs (the first ``ndisplacement``) count for the correction: the pressure dofs of the
    mixed form are in stress units.
    """

    def check(
        dx: np.ndarray, f: np.ndarray, dof1: np.ndarray, dof0: np.ndarray, **_: object
    ) -> tuple[float, float, bool]:
        # FElupe also passes its own xtol/ftol keywords; they are ignored (``**_``)
        xnorm = float(np.linalg.norm(dx[dof1[dof1 < ndisplacement]]))
        fnorm = float(np.linalg.norm(f[dof1]) / (1e-12 + np.linalg.norm(f[dof0])))
        return xnorm, fnorm, bool(xnorm < xtol and fnorm < ftol)

    return check


def solve_block(
    umat: object | Callable[[float], object],
    mode: str,
    stretches: tuple[float, ...],
    *,
    mixed: bool = False,
    plane_strain: bool = False,
    n: int = 2,
    step: float = 0.4,
    xtol: float = 1e-10,
    ftol: float = 1e-5,
    predictor: bool = False,
) -> BlockResult:
    """Stretch the unit block along one mode and return the nominal stress.

    Parameters
    ----------
    umat : FElupe constitutive material, or callable of the stretch returning one
        ``Hyperelastic`` for displacement elements, ``NearlyIncompressible`` with
        ``mixed=True``. A callable is asked for the material of every increment (to
        keep a penalty bulk modulus in proportion to a stress that changes by orders
        of magnitude along the path).
    mode : {"uniaxial", "equibiaxial", "planar"}
    stretches : tuple of float
        Stretches at which the stress is reported, all on one side of 1.
    mixed : bool
        Use the u/p/J fields (``FieldsMixed``, cell-constant p and J).
    plane_strain : bool
        2D quad4 block in plane strain (mode "planar" only).
    n : int
        Points per edge (``n - 1`` cells per edge).
    step : float
        Largest increment of log-stretch.
    xtol, ftol : float
        Newton converges when the norm of the last displacement correction is below
        ``xtol`` (mm; the block is 1 mm) and the free-dof residual, relative to the
        reactions, below ``ftol``; see :func:`_convergence_check`.
    predictor : bool
        Start each increment from the affine incompressible deformation of the mode
        (``mode_stretches``) instead of the last converged state. Only the starting
        point changes, not the equations nor the convergence check; near the
        incompressible limit it saves the iterations that otherwise fight a
        volumetric residual of ``K`` times the squared increment.
    """
    if mode not in ("uniaxial", "equibiaxial", "planar"):
        raise ValueError(f"unknown mode {mode!r}")
    if plane_strain:
        if mode != "planar":
            raise ValueError("the plane-strain block is planar tension only")
        mesh = fem.Rectangle(n=n)
        region = fem.RegionQuad(mesh)
        if mixed:
            field = fem.FieldsMixed(region, n=3, planestrain=True)
        else:
            field = fem.FieldContainer([fem.FieldPlaneStrain(region, dim=2)])
    else:
        mesh = fem.Cube(n=n)
        region = fem.RegionHexahedron(mesh)
        if mixed:
            field = fem.FieldsMixed(region, n=3)
        else:
            field = fem.FieldContainer([fem.Field(region, dim=3)])
    u = field[0]
    dim = mesh.dim

    def normal(axis: int, at: float) -> fem.Boundary:
        coordinate = {"fx": at} if axis == 0 else {"fy": at} if axis == 1 else {"fz": at}
        skip = tuple(int(i != axis) for i in range(dim))
        return fem.Boundary(u, skip=skip, **coordinate)

    boundaries = {f"sym{axis}": normal(axis, 0.0) for axis in range(dim)}
    boundaries["x1"] = normal(0, 1.0)
    if mode in ("equibiaxial", "planar") and not plane_strain:
        boundaries["y1"] = normal(1, 1.0)

    dof0, dof1 = fem.dof.partition(field, boundaries)
    material_at = umat if callable(umat) and not hasattr(umat, "gradient") else (lambda _: umat)
    solid = fem.SolidBody(material_at(1.0), field)
    loaded = np.isclose(mesh.points[:, 0], 1.0)
    free_axis = 1 if plane_strain else 2
    free_face = np.isclose(mesh.points[:, free_axis], 1.0)

    out: dict[float, tuple[float, float, float]] = {}
    iterations = 0
    for lam in _ramp(tuple(stretches), step):
        solid.umat = material_at(lam)
        boundaries["x1"].update(lam - 1.0)
        if mode == "equibiaxial":
            boundaries["y1"].update(lam - 1.0)
        if predictor:
            stretch = [float(x) for x in mode_stretches(mode, lam)]
            if plane_strain:  # in-plane (l, 1/l), out-of-plane 1
                stretch = [stretch[0], stretch[2]]
            u.values[:] = mesh.points * (np.array(stretch) - 1.0)
            if mixed:
                field[2].values[:] = 1.0  # the volume-ratio field: det F of the predictor
        res = fem.newtonraphson(
            field,
            items=[solid],
            dof1=dof1,
            dof0=dof0,
            ext0=fem.dof.apply(field, boundaries, dof0),
            check=_convergence_check(xtol, ftol, u.values.size),
            maxiter=40,
            verbose=0,
        )
        iterations += res.iterations
        field.link(res.x)
        if lam in stretches:
            forces = res.fun[: u.values.size].reshape(-1, dim)
            lateral = 1.0 + float(np.mean(u.values[free_face, free_axis]))
            F = field.extract()[0]
            out[lam] = (
                float(forces[loaded, 0].sum()),
                lateral,
                float(np.max(np.abs(fem.math.det(F) - 1.0))),
            )
    p, lat, dv = (np.array([out[s][i] for s in stretches]) for i in range(3))
    return BlockResult(
        stretch=np.asarray(stretches, dtype=float),
        nominal_stress=p,
        lateral_stretch=lat,
        volume_change=dv,
        iterations=iterations,
    )

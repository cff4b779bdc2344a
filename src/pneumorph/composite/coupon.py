"""Finite-element tensile test of a crimped paper-silicone coupon (section 3.2.3).

Plane strain, unit depth. The Ecoflex 0030 matrix is a compressible Ogden solid (Table
A.4, Eq 2.12, linear 4-node quadrilaterals); the paper is a chain of two-node truss
elements, linear elastic in the Biot strain, sharing the nodes of the mesh row that
follows the crimp (:mod:`pneumorph.composite.mesh`) - tied to the matrix without
contact, the role MSC Marc's rebar elements play in the dissertation. As there, the
load is an enforced displacement of the paper's end node at ``x = L0`` (``u_y = 0``
there) and the paper's other end node is fixed; the matrix is held only through the
paper.

Recorded per load level: the engineering strain (end displacement / ``L0``), the
reaction force (N per mm of coupon width), the averaged surface strain (the mean axial
strain of the top surface, i.e. the change of its length over its initial length) and
the deformed top surface (for strain profiles and virtual strain gauges).

Examples
--------
>>> spec = CouponSpec.from_ratio(0.3, length=40.0, per_flute=1, rows=1)
>>> r = simulate_coupon(spec, strain_max=0.65, levels=26)
>>> bool(r.force[-1] > 100 * r.force[len(r.force) // 2])  # stiff once the paper is straight
True
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache, partial
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from pneumorph.composite.crimp import Crimp
from pneumorph.composite.mesh import CouponMesh, coupon_mesh
from pneumorph.errors import CrimpError
from pneumorph.fem.stepping import StepSettings, newton_check, ramp

FloatArray = NDArray[np.float64]
StrainKind = Literal["engineering", "surface"]

#: Coupon of the dissertation: crimped length (Fig 3.4), thickness (Appendix B.1.1), amplitude (3.2.1).
LENGTH = 176.25
THICKNESS = 5.0
AMPLITUDE = 1.5
#: CPU seconds of one load level per node of the coupon's mesh (one thread; the cost grows about linearly with the
#: nodes of this banded 2D mesh): the dissertation's coupons (176.25 mm by 5 mm, 4 cells a flute and 4 rows, 100
#: levels to 10 % past the straight paper) took 12.1 s (CR 0.2, 1,701 nodes), 15.5 s (CR 0.25, 2,133) and 20.7 s
#: (CR 0.3, 2,547 nodes, two cut-backs)
LEVEL_SECONDS = 7.5e-5


@lru_cache(maxsize=8)
def meshed(crimp: Crimp, thickness: float, per_flute: int, rows: int) -> CouponMesh:
    """The coupon's mesh (:func:`~pneumorph.composite.mesh.coupon_mesh`), built once per set of parameters.

    A coupon command names the mesh's nodes in its plan, estimates its levels from them and solves on it: one
    mesh, shared, so its arrays are read-only.

    >>> from pneumorph.composite.crimp import Crimp
    >>> m = meshed(Crimp.from_ratio(0.25, 1.5, 176.25), 5.0, 4, 4)
    >>> len(m.points), m.points.flags.writeable
    (2133, False)
    """
    mesh = coupon_mesh(crimp, thickness, per_flute, rows)
    for array in (mesh.points, mesh.quads, mesh.lines, mesh.grid, mesh.kinks):
        array.flags.writeable = False
    return mesh


@dataclass(frozen=True)
class CouponSpec:
    """A composite coupon: crimp, thickness, materials and mesh density.

    Parameters
    ----------
    crimp : Crimp
        Amplitude, wavelength and crimped length ``L0`` (mm).
    thickness : float
        Coupon thickness (mm), 5 mm in the dissertation.
    matrix : str
        Library name of the hyperelastic matrix (Ogden, Marc convention).
    paper : str
        Library name of the linear-elastic strain limiter (Young's modulus, thickness).
    bulk_modulus : float, optional
        Matrix bulk modulus ``K`` (MPa) instead of the library value.
    per_flute, rows : int
        Cells per flute along the coupon; cell rows between paper and each surface.

    Examples
    --------
    >>> s = CouponSpec.from_ratio(0.25)
    >>> s.crimp.wavelength, s.crimp.length, s.thickness
    (6.0, 176.25, 5.0)
    """

    crimp: Crimp
    thickness: float = THICKNESS
    matrix: str = "ecoflex_0030"
    paper: str = "paper_purco_80gsm"
    bulk_modulus: float | None = None
    per_flute: int = 4
    rows: int = 4

    def __post_init__(self) -> None:
        t = float(self.thickness)
        if not (math.isfinite(t) and t > 2.0 * self.crimp.amplitude):
            raise CrimpError(
                f"the coupon thickness must exceed the crimp height 2A = {2 * self.crimp.amplitude:g} mm, "
                f"got {self.thickness!r} mm"
            )
        if self.bulk_modulus is not None and not self.bulk_modulus > 0:
            raise CrimpError(f"the bulk modulus must be positive, got {self.bulk_modulus!r} MPa")
        if int(self.per_flute) < 1 or int(self.rows) < 1:
            raise CrimpError(f"per_flute and rows must be at least 1, got {self.per_flute} and {self.rows}")

    @classmethod
    def from_ratio(
        cls,
        crimp_ratio: float,
        amplitude: float = AMPLITUDE,
        length: float = LENGTH,
        **kwargs: Any,
    ) -> CouponSpec:
        """Coupon with the crimp of ratio ``CR = A / lambda`` (defaults: the dissertation's)."""
        return cls(crimp=Crimp.from_ratio(crimp_ratio, amplitude, length), **kwargs)

    def mesh(self) -> CouponMesh:
        """The structured mesh of this coupon, built once for its parameters (:func:`meshed`).

        >>> s = CouponSpec.from_ratio(0.25)
        >>> s.mesh() is CouponSpec.from_ratio(0.25).mesh()
        True
        """
        return meshed(self.crimp, float(self.thickness), int(self.per_flute), int(self.rows))

    def level_seconds(self) -> float:
        """Estimated CPU seconds of one load level of :func:`simulate_coupon` (:data:`LEVEL_SECONDS` per node).

        >>> round(CouponSpec.from_ratio(0.25).level_seconds(), 3)  # 2,133 nodes
        0.16
        """
        return LEVEL_SECONDS * len(self.mesh().points)

    def to_dict(self) -> dict[str, Any]:
        """Plain data."""
        return {
            "crimp": self.crimp.to_dict(),
            "thickness": self.thickness,
            "matrix": self.matrix,
            "paper": self.paper,
            "bulk_modulus": self.bulk_modulus,
            "per_flute": self.per_flute,
            "rows": self.rows,
        }


@dataclass(frozen=True)
class CouponResult:
    """Load-strain response of a simulated coupon.

    Attributes
    ----------
    spec : CouponSpec
    engineering_strain, surface_strain, force : ndarray, shape (n,)
        Per load level, the first level being the unloaded state: end displacement /
        ``L0``; mean axial strain of the top surface; reaction force at the loaded paper
        end (N per mm of width).
    paper_force : ndarray, shape (n, 2)
        Smallest and largest truss force (N per mm of width) per level.
    surface_x0 : ndarray, shape (m,)
        Initial ``x`` of the top-surface nodes.
    surface : ndarray, shape (n, m, 2)
        Deformed top-surface node positions per level.
    points : ndarray, shape (p, 2)
        Initial node positions; ``snapshots`` maps a level index to the displacements of
        all nodes there; ``quads`` and ``paper_nodes`` give the cells and the paper row.
    seconds, newton_iterations, cutbacks
        Cost of the solve.
    """

    spec: CouponSpec
    engineering_strain: FloatArray
    surface_strain: FloatArray
    force: FloatArray
    paper_force: FloatArray
    surface_x0: FloatArray
    surface: FloatArray
    points: FloatArray
    quads: NDArray[np.int64]
    paper_nodes: NDArray[np.int64]
    snapshots: dict[int, FloatArray] = field(default_factory=dict)
    seconds: float = 0.0
    newton_iterations: int = 0
    cutbacks: int = 0

    def strain(self, kind: StrainKind = "engineering") -> FloatArray:
        """The strain measure ``"engineering"`` or ``"surface"`` per level."""
        if kind == "engineering":
            return self.engineering_strain
        if kind == "surface":
            return self.surface_strain
        raise ValueError(f"strain kind must be 'engineering' or 'surface', got {kind!r}")

    def transition(self, kind: StrainKind = "engineering", secondary_points: int = 10) -> Any:
        """Two-line characterisation (section 3.2.6) of force against the chosen strain.

        Primary line: points up to 10 % strain; secondary: the last ``secondary_points``
        levels. Returns :class:`pneumorph.materials.characterisation.analyses.BilinearResult`.
        """
        from pneumorph.materials.characterisation.analyses import bilinear

        return bilinear(self.strain(kind), self.force, secondary_points=secondary_points)

    def surface_profile(self, level: int = -1) -> tuple[FloatArray, FloatArray]:
        """Local axial strain of the top surface at a level: (mid-point ``x0``, strain).

        The strain of each surface segment is its deformed length over its initial length
        minus one.
        """
        dx0 = np.diff(self.surface_x0)
        seg = np.linalg.norm(np.diff(self.surface[level], axis=0), axis=1)
        return 0.5 * (self.surface_x0[1:] + self.surface_x0[:-1]), seg / dx0 - 1.0

    def to_dict(self) -> dict[str, Any]:
        """Plain data of the curves, the transitions and the cost (no mesh)."""
        out: dict[str, Any] = {
            "spec": self.spec.to_dict(),
            "engineering_strain": self.engineering_strain.tolist(),
            "surface_strain": self.surface_strain.tolist(),
            "force": self.force.tolist(),
            "force_unit": "N per mm of width",
            "seconds": self.seconds,
            "newton_iterations": self.newton_iterations,
            "cutbacks": self.cutbacks,
            "dofs": int(self.points.size),
        }
        for kind in ("engineering", "surface"):
            t = self.transition(kind)
            out[f"transition_{kind}"] = t.transition_strain
            out[f"primary_modulus_{kind}"] = t.primary_modulus
            out[f"secondary_modulus_{kind}"] = t.secondary_modulus
        return out


def _materials(spec: CouponSpec) -> tuple[Any, float, float]:
    """Matrix umat, paper Young's modulus (MPa) and paper thickness (mm)."""
    import pneumorph.materials as pm
    from pneumorph.fem.ogden import OgdenCompressible
    from pneumorph.materials.laws.hyperelastic import Ogden

    matrix = pm.get(spec.matrix)
    if not isinstance(matrix.model, Ogden):
        raise CrimpError(f"the matrix {spec.matrix!r} must have an Ogden model, it has {type(matrix.model).__name__}")
    bulk = spec.bulk_modulus
    if bulk is None:
        if matrix.bulk_modulus is None:
            raise CrimpError(f"the matrix {spec.matrix!r} has no bulk modulus; pass bulk_modulus")
        bulk = matrix.bulk_modulus.value
    umat = OgdenCompressible(matrix.model.mu, matrix.model.alpha, bulk)
    paper = pm.get(spec.paper)
    if paper.youngs_modulus is None or paper.thickness is None:
        raise CrimpError(f"the paper {spec.paper!r} needs a Young's modulus and a thickness")
    return umat, paper.youngs_modulus.value, paper.thickness.value


def simulate_coupon(
    spec: CouponSpec,
    strain_max: float | None = None,
    levels: int = 100,
    settings: StepSettings | None = None,
    snapshots: tuple[float, ...] = (),
    on_level: Callable[[int, float, float], None] | None = None,
) -> CouponResult:
    """Pull the coupon by its paper end and record the load-strain response.

    Parameters
    ----------
    spec : CouponSpec
    strain_max : float, optional
        Final engineering strain (end displacement / ``L0``). Default: the strain at
        which the paper would be straight (``2 s / lambda - 1``) plus 0.10, so that the
        last ten of the default 100 levels lie on the stiff branch.
    levels : int
        Equally spaced load levels recorded (besides the unloaded state).
    settings : StepSettings, optional
        Substeps, cut-backs and Newton settings between levels (default: 1 substep,
        8 cut-backs, 30 iterations).
    snapshots : tuple of float
        Engineering strains at which the displacements of all nodes are kept (the
        nearest level each); the last level is always kept.
    on_level : callable, optional
        ``on_level(k, strain, force)`` after load level ``k`` (0-based, of ``levels``) has
        converged: its engineering strain and reaction force (N per mm of width).

    Returns
    -------
    CouponResult

    Raises
    ------
    SimulationFailed
        If a level cannot be reached after the allowed cut-backs.
    """
    strain_max = _check_load(spec, strain_max, levels)
    settings = settings or StepSettings(increments=int(levels), substeps=1, max_cutbacks=8, max_iterations=30)
    mesh = spec.mesh()
    fields, paper_fields, matrix, paper, paper_thickness = _bodies(spec, mesh)
    dof0, dof1, pulled = _supports(fields, mesh)
    last = int(mesh.paper[-1])
    L0 = spec.crimp.length
    d_max = float(strain_max) * L0

    top = mesh.top
    eng, surf, force, pforce, surface = [0.0], [0.0], [0.0], [(0.0, 0.0)], [mesh.points[top].copy()]
    snaps: dict[int, FloatArray] = {}
    wanted = {int(np.argmin(np.abs(np.linspace(0, strain_max, int(levels) + 1) - s))) for s in snapshots}
    wanted.add(int(levels))

    def record(k: int, t: float) -> None:
        u = fields[0].values
        r = matrix.assemble.vector(fields).toarray() + paper.assemble.vector(paper_fields).toarray()
        n = paper.results.stress * paper_thickness
        x = mesh.points[top] + u[top]
        eng.append(t * d_max / L0)
        surf.append((x[-1, 0] - x[0, 0]) / L0 - 1.0)
        force.append(float(r.reshape(-1, 2)[last, 0]))
        pforce.append((float(np.min(n)), float(np.max(n))))
        surface.append(x)
        if k + 1 in wanted:
            snaps[k + 1] = u.copy()
        if on_level is not None:
            on_level(k, eng[-1], force[-1])

    start = time.perf_counter()
    def pull(t: float) -> None:  # the loaded node's x-displacement, a prescribed value of the field
        fields[0].values.ravel()[dof0[pulled]] = t * d_max

    stats = ramp([matrix, paper], fields, pull, dof1, dof0, settings, on_level=record,
                 check=partial(newton_check, still=UPDATE_TOLERANCE))
    return CouponResult(
        spec=spec, engineering_strain=np.asarray(eng), surface_strain=np.asarray(surf), force=np.asarray(force),
        paper_force=np.asarray(pforce), surface_x0=mesh.points[top, 0].copy(), surface=np.asarray(surface),
        points=mesh.points, quads=mesh.quads, paper_nodes=mesh.paper, snapshots=snaps,
        seconds=time.perf_counter() - start, newton_iterations=stats.newton_iterations, cutbacks=stats.cutbacks,
    )


def _check_load(spec: CouponSpec, strain_max: float | None, levels: int) -> float:
    """The final engineering strain (by default past the paper's straightening), ``levels`` checked.

    Raises
    ------
    ValueError
        A strain that is not positive, or fewer than 2 levels.
    """
    if strain_max is None:
        strain_max = spec.crimp.limit_transition_strain + 0.10
    if not strain_max > 0:
        raise ValueError(f"strain_max must be positive, got {strain_max}")
    if int(levels) < 2:
        raise ValueError(f"levels must be at least 2, got {levels}")
    return strain_max


def _bodies(spec: CouponSpec, mesh: CouponMesh) -> tuple[Any, Any, Any, Any, float]:
    """The matrix (plane-strain quads) and the paper (trusses on the same points), linked.

    Returns
    -------
    fields, paper_fields : felupe.FieldContainer
        The matrix's displacement field and the paper's, linked to it.
    matrix, paper : felupe.SolidBody, felupe.TrussBody
    paper_thickness : float
        mm (the trusses' area per unit depth).
    """
    import felupe as fem

    umat, young, paper_thickness = _materials(spec)
    quad_mesh = fem.Mesh(mesh.points, mesh.quads, "quad")
    line_mesh = fem.Mesh(mesh.points, mesh.lines, "line")
    fields = fem.FieldContainer([fem.FieldPlaneStrain(fem.RegionQuad(quad_mesh), dim=2)])
    paper_fields = fem.FieldContainer([fem.Field(fem.RegionTruss(line_mesh), dim=2)])
    paper_fields.link(fields)
    matrix = fem.SolidBody(umat, fields)
    paper = fem.TrussBody(fem.LinearElastic1D(E=young), paper_fields, area=paper_thickness * 1.0)
    return fields, paper_fields, matrix, paper, paper_thickness


def _supports(fields: Any, mesh: CouponMesh) -> tuple[Any, Any, Any]:
    """The paper's two end nodes held: ``dof0`` (held), ``dof1`` (free), and which of ``dof0`` is pulled.

    The pulled one is the x-dof of the paper's last node; everything else at both ends is fixed.
    """
    import felupe as fem

    first, last = int(mesh.paper[0]), int(mesh.paper[-1])
    mask = np.zeros(len(mesh.points), dtype=bool)
    mask[[first, last]] = True
    dof0, dof1 = fem.dof.partition(fields, {"ends": fem.Boundary(fields[0], mask=mask)})
    pulled = dof0 == 2 * last  # x-dof of the loaded node
    return dof0, dof1, pulled


#: Newton updates below this norm (mm) count as converged: near the unloaded state the
#: reaction forces that scale the residual criterion are ~1e-4 N, while the round-off
#: of the paper's internal forces (EA ~ 700 N) leaves residuals of ~1e-11 N.
UPDATE_TOLERANCE = 1e-9

"""The pressurised body: the one builder of every FE model's FElupe objects.

An actuator (2D section or 3D hexahedra), the bimodal actuator and any body like them is
a mesh whose cells fall into material regions, one displacement field shared by one
``felupe.SolidBody`` per region, a follower pressure on the walls of its closed cavities,
optional dead loads, a clamped base and, for a half model, a plane of symmetry.
:func:`pressurised_body` builds that from plain arrays; :meth:`PressurisedBody.stepper`
gives the substep strategy and the cavity-volume monitor of
:func:`pneumorph.fem.stepping.ramp` for the chosen backend (FElupe's assembly and
``newtonraphson``, or the fast system and its Newton method), so that every model solves
its ramp the same way.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import SettingsError
from pneumorph.fem.cavity import cavity_volume

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

#: FElupe's (region, boundary region, field) classes by cell type, by name so that FElupe
#: is imported only when a body is built.
_REGIONS = {
    "quad": ("RegionQuad", "RegionQuadBoundary", "FieldPlaneStrain"),
    "quad8": ("RegionQuadraticQuad", "RegionQuadraticQuadBoundary", "FieldPlaneStrain"),
    "hexahedron": ("RegionHexahedron", "RegionHexahedronBoundary", "Field"),
    "hexahedron20": ("RegionQuadraticHexahedron", "RegionQuadraticHexahedronBoundary", "Field"),
}

#: The backends that solve a body's ramp.
BACKENDS = ("fast", "felupe")

#: The quadrature rules of a body's quadratic cells: ``"full"`` (FElupe's default Gauss rule,
#: 3x3x3 = 27 points per hex20, 3x3 = 9 per quad8), ``"reduced"`` (Gauss, one order lower: 8
#: points per hex20 as Abaqus' C3D20R, 4 per quad8) and ``"irons"`` (Irons' 14-point rule of the
#: cube, exact to degree 5 like the full rule, hex20 only).
QUADRATURES = ("full", "reduced", "irons")

#: Irons' 14-point rule on [-1, 1]^3: 6 points on the axes at +-a, 8 at the corners of the cube
#: of half-side b (B. M. Irons, Int. J. Numer. Meth. Eng. 3 (1971) 293-294); the weights sum to 8.
_IRONS = (0.795822425754222, 0.758786910639328, 0.886426592797784, 0.335180055401662)


def check_backend(backend: str, allowed: Sequence[str] = BACKENDS) -> str:
    """``backend`` if it is one of ``allowed``, else :class:`SettingsError` naming them.

    >>> check_backend("fast")
    'fast'
    """
    if backend not in allowed:
        raise SettingsError(f"backend must be one of {', '.join(allowed)}, got {backend!r}")
    return backend


def regions_of(cell_type: str, quadrature: str = "full") -> tuple[Any, Any, Any]:
    """FElupe's region, boundary-region and field classes for a cell type.

    With a ``quadrature`` rule other than the full one, the region is that class with the
    rule's scheme (:func:`quadrature_scheme`) given.

    >>> [c.__name__ for c in regions_of("hexahedron20")]
    ['RegionQuadraticHexahedron', 'RegionQuadraticHexahedronBoundary', 'Field']
    >>> regions_of("hexahedron20", "reduced")[0].keywords["quadrature"].points.shape
    (8, 3)
    """
    import felupe as fem

    try:
        names = _REGIONS[cell_type]
    except KeyError:
        raise SettingsError(f"no pressurised body on {cell_type!r} cells; cell types: {', '.join(_REGIONS)}") from None
    region, boundary, field = (getattr(fem, name) for name in names)
    scheme = quadrature_scheme(cell_type, quadrature)
    return (region if scheme is None else functools.partial(region, quadrature=scheme)), boundary, field


def quadrature_scheme(cell_type: str, rule: str = "full") -> Any:
    """FElupe's quadrature scheme of ``rule`` on ``cell_type`` cells (None: the region's default).

    Raises
    ------
    SettingsError
        A rule not in :data:`QUADRATURES`, a cheaper rule on linear cells (whose full rule
        is already the lowest that keeps their rank) or Irons' rule on other cells than hex20.

    Examples
    --------
    >>> quadrature_scheme("hexahedron20") is None
    True
    >>> [quadrature_scheme("hexahedron20", r).points.shape for r in ("reduced", "irons")]
    [(8, 3), (14, 3)]
    >>> round(float(quadrature_scheme("hexahedron20", "irons").weights.sum()), 12)
    8.0
    >>> quadrature_scheme("quad8", "reduced").points.shape
    (4, 2)
    """
    import felupe as fem

    if rule not in QUADRATURES:
        raise SettingsError(f"quadrature must be one of {', '.join(QUADRATURES)}, got {rule!r}")
    if rule == "full":
        return None
    if cell_type not in ("quad8", "hexahedron20") or (rule == "irons" and cell_type != "hexahedron20"):
        raise SettingsError(f"quadrature {rule!r} is not a rule of {cell_type!r} cells (the reduced rule is one of "
                            "quad8 and hex20 cells, Irons' of hex20)")
    if rule == "reduced":
        return fem.GaussLegendre(order=1, dim=2 if cell_type == "quad8" else 3)
    a, b, wa, wb = _IRONS
    axes = [[s * a if j == axis else 0.0 for j in range(3)] for axis in range(3) for s in (-1, 1)]
    corners = [[x * b, y * b, z * b] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    return fem.quadrature.Scheme(np.array(axes + corners), np.array([wa] * 6 + [wb] * 8))


@dataclass
class PressurisedBody:
    """FElupe objects of a pressurised body (built by :func:`pressurised_body`).

    Attributes
    ----------
    points : ndarray, shape (p, dim)
    cells : ndarray, shape (c, n)
    cell_type : str
    dim : int
    field : felupe.FieldContainer
        The global displacement field every item is linked to.
    solids : dict of str to felupe.SolidBody
        One body per material region, in the order given.
    walls : felupe.FieldContainer
        The field on the pressurised cavity walls.
    pressure : felupe.SolidBodyPressure
        The follower pressure on the walls (``pressure.update(p)``).
    forces : dict of str to felupe.SolidBodyForce
        Dead loads per region (``force.update(g)``), for the regions given a density.
    dof0, dof1 : ndarray
        Prescribed (clamped base, symmetry plane) and active degrees of freedom.
    half : bool
        Held on a plane of symmetry (a 3D half model); False: the full width.
    contacts : list of RigidContact
        Rigid obstacles against the outer surface
        (:class:`~pneumorph.fem.fast.contact.RigidContact`; the fast backend only).
    """

    points: FloatArray
    cells: IntArray
    cell_type: str
    dim: int
    field: Any
    solids: dict[str, Any]
    walls: Any
    pressure: Any
    forces: dict[str, Any]
    dof0: IntArray
    dof1: IntArray
    half: bool = False
    contacts: list[Any] = dataclasses.field(default_factory=list)

    @property
    def items(self) -> list[Any]:
        """Every FElupe item whose sum is the residual."""
        return [*self.solids.values(), self.pressure, *self.forces.values(), *self.contacts]

    @property
    def displacement(self) -> FloatArray:
        """The current nodal displacements, shape (p, dim).

        Read it anew after a solve: the FElupe path re-links the field to new arrays.
        """
        return self.field[0].values

    def set_gravity(self, acceleration: FloatArray) -> None:
        """Set the acceleration of every dead load (mm/s^2)."""
        for force in self.forces.values():
            force.update(np.asarray(acceleration, dtype=float))

    def stepper(self, backend: str = "fast", reuse: float | None = None,
                depth: int = 0) -> tuple[Any, Callable[[], float]]:
        """The ramp's substep strategy and monitor for a backend.

        Parameters
        ----------
        backend : {"fast", "felupe"}
            ``"fast"``: :class:`~pneumorph.fem.fast.system.PlaneStrainSystem` (2D) or
            :class:`~pneumorph.fem.fast.system.SolidSystem3D` (3D) with
            :class:`~pneumorph.fem.fast.newton.FastSubstep`; ``"felupe"``: FElupe's
            assembly and ``newtonraphson`` (:class:`~pneumorph.fem.stepping.FElupeSubstep`).
        reuse, depth
            The fast Newton method's tangent reuse and Anderson depth (see
            :class:`~pneumorph.fem.fast.newton.FastSubstep`). Its limit of unknowns for
            single precision is :data:`~pneumorph.fem.fast.newton.SINGLE_PRECISION_MAX_DOFS`,
            twice that for a 3D body of the full width (no plane of symmetry: the same
            element size, twice the unknowns).

        Returns
        -------
        substep : callable
            ``substep(fields, settings) -> (iterations, cause)`` for
            :func:`~pneumorph.fem.stepping.ramp`.
        monitor : callable
            The current enclosed cavity volume (area in 2D).
        """
        from pneumorph.fem.stepping import FElupeSubstep

        if check_backend(backend) == "felupe":
            if self.contacts:
                raise SettingsError("contact with obstacles is solved by the fast backend only (the default)")
            return FElupeSubstep(self.items, self.dof1, self.dof0), lambda: cavity_volume(self.walls)
        from pneumorph.fem.fast.newton import SINGLE_PRECISION_MAX_DOFS, FastSubstep
        from pneumorph.fem.fast.system import PlaneStrainSystem, SolidSystem3D

        system = (PlaneStrainSystem if self.dim == 2 else SolidSystem3D)(self.items, self.field, self.dof1, self.dof0)
        def monitor() -> float:
            return float(system.cavity_volume(self.displacement.ravel()))

        # single precision up to the limit measured on half models, per half width (the same element size)
        limit = SINGLE_PRECISION_MAX_DOFS * (2 if self.dim == 3 and not self.half else 1)
        return FastSubstep(system, reuse=reuse, depth=depth, single_max_dofs=limit), monitor


def pressurised_body(
    points: FloatArray,
    cells: IntArray,
    cell_type: str,
    materials: Sequence[tuple[str, BoolArray | IntArray, Any]],
    cavity_points: BoolArray,
    base_points: BoolArray,
    symmetry_points: BoolArray | None = None,
    walls_of: Sequence[str] | None = None,
    densities: Mapping[str, float] | None = None,
    quadrature: str = "full",
) -> PressurisedBody:
    """Build the FElupe objects of a pressurised body.

    Parameters
    ----------
    points : ndarray, shape (p, dim)
        Mesh points (2D: a plane-strain section; 3D: hexahedra).
    cells : ndarray, shape (c, n)
    cell_type : {"quad", "quad8", "hexahedron", "hexahedron20"}
    materials : sequence of (name, cells, umat)
        Every material region: its name, its cells (a mask or indices into ``cells``) and
        its FElupe material.
    cavity_points : ndarray of bool
        The points of the cavity walls; the pressure acts on every face of a
        ``walls_of`` cell whose points all lie there.
    base_points : ndarray of bool
        Clamped points.
    symmetry_points : ndarray of bool, optional
        Points on a mid-width plane of symmetry (u_z = 0; 3D half models).
    walls_of : sequence of str, optional
        The regions whose faces carry the pressure (default: all). A 2D filler that fills
        the cavities is left out, so that the walls are the silicone's.
    densities : mapping of str to float, optional
        Mass densities (t/mm^3) of the regions that carry their weight (dead loads that
        :meth:`PressurisedBody.set_gravity` switches on); default none.
    quadrature : {"full", "reduced", "irons"}
        The material regions' rule (:func:`quadrature_scheme`; the walls keep theirs).

    Examples
    --------
    >>> import felupe as fem
    >>> from pneumorph.fem import OgdenCompressible
    >>> cube = fem.Cube(n=3)
    >>> inner = np.all(np.isclose(cube.points, 0.5), axis=1)   # no closed cavity here
    >>> body = pressurised_body(cube.points, cube.cells, "hexahedron",
    ...                         [("silicone", np.ones(len(cube.cells), bool), OgdenCompressible([0.1], [2.0], 10.0))],
    ...                         inner, cube.points[:, 0] == 0.0)
    >>> len(body.items), body.dof0.size, body.dof1.size
    (2, 27, 54)
    """
    import felupe as fem

    from pneumorph.fem.parts import clamped_dofs, linked_solid

    points = np.asarray(points, dtype=float)
    cells = np.asarray(cells)
    dim = points.shape[1]
    Region, BoundaryRegion, Field = regions_of(cell_type, quadrature)
    global_field = fem.FieldContainer([Field(Region(fem.Mesh(points, cells, cell_type)), dim=dim)])
    solids: dict[str, Any] = {}
    selected: dict[str, IntArray] = {}
    for name, which, umat in materials:
        if name in solids:
            raise SettingsError(f"material region {name!r} given twice")
        index = np.flatnonzero(which) if np.asarray(which).dtype == bool else np.asarray(which, dtype=np.int64)
        selected[name] = index
        solids[name] = linked_solid(umat, points, cells[index], cell_type, Region, Field, dim, global_field)
    walled = list(solids) if walls_of is None else list(walls_of)
    wall_cells = cells[np.concatenate([selected[name] for name in walled])]
    kwargs = {"ensure_3d": True} if dim == 2 else {}
    walls_region = BoundaryRegion(fem.Mesh(points, wall_cells, cell_type), mask=cavity_points, **kwargs)
    walls = fem.FieldContainer([Field(walls_region, dim=dim)])
    walls.link(global_field)
    pressure = fem.SolidBodyPressure(walls, pressure=0.0)
    forces = {name: fem.SolidBodyForce(solids[name].field, values=np.zeros(dim), scale=float(rho))
              for name, rho in (densities or {}).items()}
    dof0, dof1 = clamped_dofs(global_field, base_points, symmetry_points)
    return PressurisedBody(points, cells, cell_type, dim, global_field, solids, walls, pressure, forces, dof0, dof1,
                           half=symmetry_points is not None)


__all__ = ["BACKENDS", "QUADRATURES", "PressurisedBody", "check_backend", "pressurised_body", "quadrature_scheme",
           "regions_of"]

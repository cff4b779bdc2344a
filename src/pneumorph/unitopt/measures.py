"""What the unit optimisation measures on a solved short actuator (Fig 8.1 of Ellis 2020).

Three numbers per solved actuator of aligned units (orientation 0: the soft wall at
``y = 0``, the stiff layer on top, bending towards +y), all at the design pressure (the
ramp's last level):

``omega_deg`` (Omega of Fig 8.1)
    The turn of the unit's chord: for an interior unit ``i`` the angle from the chord
    ``c[i-1] -> c[i]`` to the chord ``c[i] -> c[i+1]`` between the deformed unit centres
    (:meth:`~pneumorph.geometry.assembly.ActuatorMesh.unit_centres`, the mean of a unit's
    four cavity vertices), counter-clockwise positive, in degrees. The two chords' midpoints
    are the unit's two ends, so this is the angle between the unit's two sides. Omega is
    the turn of the middle unit (of an odd number of units; the mean of the two middle ones
    of an even number): the unit furthest from the clamped base and the free tip, at least
    3 units. In the 15-unit actuator of the built-in unit the interior units turn 20.18-20.19
    degrees each, the unit next to the clamped first one 20.78, the one before the tip 20.31.
``balloon_mm`` (h_b of Fig 8.1)
    The largest outward bulge of a free surface, normal to it, with the unit's rigid motion
    taken out by a chord:

    - *soft (bottom) wall*: every point of a unit's face ``y = 0``, against the deformed
      chord from the face's point at the unit's start to the one at its end (same ``z``),
      along the chord's outward normal (``-y`` before deformation);
    - *free end wall*: every point of the end face ``x = L``, against the chord from its
      bottom point to its top point (same ``z``), along ``+x`` before deformation;
    - *side wall*: ``-u_z`` on the outer side face ``z = 0`` (the half model's symmetry
      keeps the rigid motion in the x-y plane, so no chord is needed).

    The undeformed actuator and any rigid motion in the bending plane give 0.
``strain``
    The largest principal nominal strain of the body material (Mold Star 15): the largest
    principal stretch minus 1, ``sqrt(max eig(F^T F)) - 1``, over the quadrature points
    (27-point Gauss of each hex20) of the body region. The same measure as a datasheet's
    elongation at break. ``layer_strain`` is the same for the stiff layer.

Examples
--------
>>> import numpy as np
>>> c = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 1.0]])
>>> round(float(chord_turns(c)[0]), 6)
45.0
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from itertools import pairwise
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import SettingsError
from pneumorph.geometry.assembly import ActuatorMesh

FloatArray = NDArray[np.float64]

#: bumped whenever a measure changes its definition (part of the probe's fingerprint)
MEASURES_REVISION = 1
#: points closer than this (mm) to a face lie on it
_ON = 1e-6


@dataclass(frozen=True)
class UnitMeasures:
    """The measures of one solved actuator at its design pressure (see the module docstring).

    Attributes
    ----------
    omega_deg : float
        Omega: the chord turn of the middle unit, degrees.
    balloon_mm : float
        h_b: the largest of ``balloon_bottom_mm``, ``balloon_end_mm``, ``balloon_side_mm``.
    balloon_bottom_mm, balloon_end_mm, balloon_side_mm : float
        The bulge of the soft wall, of the free end wall and of the side walls.
    strain : float
        Largest principal nominal strain of the body material.
    layer_strain : float
        The same for the stiff layer (0 without a layer).
    curl_per_unit_deg : float
        The end face's rotation divided by the number of units (the clamped first unit and
        the tip unit included).
    """

    omega_deg: float
    balloon_mm: float
    balloon_bottom_mm: float
    balloon_end_mm: float
    balloon_side_mm: float
    strain: float
    layer_strain: float
    curl_per_unit_deg: float

    def to_dict(self) -> dict[str, float]:
        return {k: float(v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> UnitMeasures:
        """The measures from :meth:`to_dict` (e.g. a cached response's metadata).

        >>> m = UnitMeasures(20.0, 3.0, 3.0, 1.0, 2.0, 1.5, 0.1, 19.0)
        >>> UnitMeasures.from_dict(m.to_dict()) == m
        True
        """
        return cls(**{k: float(data[k]) for k in cls.__dataclass_fields__})


def chord_turns(centres: FloatArray) -> FloatArray:
    """The turn (degrees, counter-clockwise positive) at every interior point of a polyline.

    ``centres`` has shape (n, 2); the result has n - 2 entries, one per interior unit.

    Raises
    ------
    SettingsError
        Fewer than 3 centres (no interior unit).

    Examples
    --------
    >>> import numpy as np
    >>> chord_turns(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])).tolist()
    [0.0]
    """
    c = np.asarray(centres, dtype=float)
    if c.ndim != 2 or c.shape[0] < 3:
        raise SettingsError(f"Omega needs at least 3 unit centres (an interior unit), got {c.shape[0]}")
    d = np.diff(c, axis=0)
    angles = np.arctan2(d[:, 1], d[:, 0])
    turn = (np.diff(angles) + np.pi) % (2 * np.pi) - np.pi
    return np.asarray(np.degrees(turn), dtype=float)


def middle_turn(turns: FloatArray) -> float:
    """The turn of the middle interior unit (the mean of the two middle ones for an even count).

    >>> middle_turn(np.array([21.0, 20.0, 22.0])), middle_turn(np.array([21.0, 20.0, 20.5, 23.0]))
    (20.0, 20.25)
    """
    k = len(turns)
    return float(np.mean(turns[(k - 1) // 2: k // 2 + 1]))


def _chord_bulge(x: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Distance of points ``x`` beyond the chord ``a -> b`` (x-y plane), along its right-hand normal."""
    d = b - a
    n = np.stack([d[..., 1], -d[..., 0]], axis=-1) / np.linalg.norm(d, axis=-1, keepdims=True)
    return np.asarray(np.sum((x - a) * n, axis=-1), dtype=float)


def balloon_heights(mesh: ActuatorMesh, displacement: FloatArray) -> tuple[float, float, float]:
    """The bulges (bottom wall, free end wall, side walls) of a 3D actuator of aligned units, mm.

    Parameters
    ----------
    mesh : ActuatorMesh
        A 3D mesh (half or full width) of units in orientation 0.
    displacement : ndarray, shape (p, 3)
        Nodal displacements.

    Raises
    ------
    SettingsError
        A 2D mesh, or a design with a unit turned over (its soft wall is not at ``y = 0``).
    """
    if mesh.dim != 3:
        raise SettingsError("the ballooning height is measured on a 3D mesh")
    if set(mesh.orientation) != {"0"}:
        raise SettingsError(f"the ballooning height is measured on aligned units (orientation 0), got "
                            f"{mesh.orientation!r}")
    p = mesh.points
    x = p + displacement
    height = float(p[:, 1].max())
    bounds = mesh.unit_bounds
    key_z = np.round(p[:, 2], 6)

    def bulge_along(face: NDArray[np.bool_], along: int, lo: float, hi: float) -> float:
        """Largest bulge of the face points ``face`` against the chord from ``along = lo`` to ``hi`` per z."""
        best = 0.0
        idx = np.flatnonzero(face)
        for z in np.unique(key_z[idx]):
            line = idx[key_z[idx] == z]
            first = line[np.abs(p[line, along] - lo) < _ON]
            last = line[np.abs(p[line, along] - hi) < _ON]
            if not len(first) or not len(last):
                continue
            a, b = x[first[0], :2], x[last[0], :2]
            best = max(best, float(_chord_bulge(x[line, :2], a, b).max()))
        return best

    bottom_face = np.abs(p[:, 1]) < _ON
    bottom = 0.0
    for lo, hi in pairwise(bounds):
        on = bottom_face & (p[:, 0] > lo - _ON) & (p[:, 0] < hi + _ON)
        bottom = max(bottom, bulge_along(on, 0, float(lo), float(hi)))
    length = float(p[:, 0].max())
    end_face = np.abs(p[:, 0] - length) < _ON
    # chord from the bottom to the top point of the end face; its right-hand normal is +x
    end = bulge_along(end_face, 1, 0.0, height)
    # the outer side faces: z = 0 (outward -z) and, in a full-width model, z = width (outward +z)
    side = max(0.0, float(-displacement[np.abs(p[:, 2] - float(p[:, 2].min())) < _ON, 2].min()))
    if mesh.symmetry_points is None or not mesh.symmetry_points.any():
        side = max(side, float(displacement[np.abs(p[:, 2] - float(p[:, 2].max())) < _ON, 2].max()))
    return bottom, end, side


def principal_strains(mesh: ActuatorMesh, displacement: FloatArray, region: str) -> float:
    """The largest principal nominal strain (largest principal stretch - 1) in ``region``.

    Evaluated at the quadrature points of the region's cells (FElupe's default rule of the
    mesh's element: 27-point Gauss for hex20, 9-point for quad8). Returns 0 for an empty
    region.

    Examples
    --------
    >>> from pneumorph.geometry.assembly import assemble
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> mesh = assemble(UnitSpec(element_size=3.0), "0", dim=3, half=True)
    >>> u = 0.2 * mesh.points * [1.0, 0.0, 0.0]        # a uniform stretch of 1.2 along x
    >>> round(principal_strains(mesh, u, "body"), 9)
    0.2
    """
    import felupe as fem

    from pneumorph.fem.body import regions_of

    cells = mesh.cells[mesh.regions[region]]
    if not len(cells):
        return 0.0
    Region = regions_of(mesh.cell_type)[0]  # the models' region of this cell type
    fe_region = Region(fem.Mesh(mesh.points, cells, mesh.cell_type))
    field = fem.FieldContainer([fem.Field(fe_region, dim=mesh.dim, values=np.asarray(displacement, dtype=float))])
    grad = field.extract(grad=True, sym=False, add_identity=True)[0]  # (dim, dim, q, c)
    f = np.moveaxis(np.asarray(grad), (0, 1), (-2, -1))
    c = np.einsum("...ki,...kj->...ij", f, f)
    stretch = float(np.sqrt(np.linalg.eigvalsh(c)[..., -1].max()))
    return stretch - 1.0


def measure(mesh: ActuatorMesh, displacements: FloatArray, curl_deg: float, level: int = -1) -> UnitMeasures:
    """The :class:`UnitMeasures` of a solved actuator at reported level ``level`` (the last by default).

    Parameters
    ----------
    mesh : ActuatorMesh
        The 3D mesh of at least 3 aligned units.
    displacements : ndarray, shape (k, p, 3)
        The displacements at every reported level (:attr:`pneumorph.models.fe.Solution.displacements`).
    curl_deg : float
        The end face's rotation at that level (the response's curl).
    """
    u = np.asarray(displacements[level], dtype=float)
    omega = middle_turn(chord_turns(mesh.unit_centres(u)))
    bottom, end, side = balloon_heights(mesh, u)
    return UnitMeasures(
        omega_deg=omega,
        balloon_mm=max(bottom, end, side),
        balloon_bottom_mm=bottom,
        balloon_end_mm=end,
        balloon_side_mm=side,
        strain=principal_strains(mesh, u, "body"),
        layer_strain=principal_strains(mesh, u, "layer") if "layer" in mesh.regions else 0.0,
        curl_per_unit_deg=float(curl_deg) / mesh.n_units,
    )


__all__ = ["MEASURES_REVISION", "UnitMeasures", "balloon_heights", "chord_turns", "measure", "middle_turn",
           "principal_strains"]

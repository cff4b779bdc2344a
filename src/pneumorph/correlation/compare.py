"""How far a scan lies from the model: aligned, then measured on the surface, outline and centreline.

The model side is a :class:`ModelShape`: the deformed outer surface (3D, full width), the
outline in the bending plane (x along the actuator, y up) and the unit centres. A 3D scan
is aligned to the surface, a 2D trace (a photo) to the outline. Then:

- **surface** (3D scans): distance of each scan point to the nearest surface node;
- **outline**: in-plane distance of each scan point that sees the outline (in 3D, a point
  whose nearest surface node is not on a side wall) to the outline;
- **centreline**: at each unit centre, the scan's and the model's mid-points between
  their extreme points across the actuator, in a slab a quarter pitch either side; the
  distance between the two mid-points.

Distances to the outline use the outline resampled every 0.05 mm, so they are exact to
0.025 mm.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from pneumorph.correlation.align import Alignment, icp
from pneumorph.correlation.scans import Scan
from pneumorph.errors import ScanError
from pneumorph.geometry.boundary import mirrored_surface_points, outline, surface_normals

FloatArray = NDArray[np.float64]
SPACING = 0.05  # mm between outline samples
UNIT_RANGE = (0.25, 4.0)  # scan extent / model extent outside this: a unit mistake
LENGTH_RANGE = (0.12, 3.0)  # scan extent / undeformed length, checked before solving
SIDEWAYS_TRACE = ("a design that leaves the bending plane (a sideways unit) needs a 3D scan: a 2D trace shows one "
                  "view only")


@dataclass(frozen=True)
class ModelShape:
    """The deformed model as a scan sees it (mm).

    Attributes
    ----------
    surface : ndarray, shape (n, 3) or (0, 3)
        Outer surface nodes, full width (empty for a 2D model).
    side : ndarray of bool, shape (n,)
        Surface nodes on a side wall (z = 0 or the width before deforming).
    outline : ndarray, shape (m, 2, 2)
        Outline segments in the bending plane.
    centres : ndarray, shape (u, 2)
        Unit centres in the bending plane.
    pitch : float
    """

    surface: FloatArray
    side: NDArray[np.bool_]
    outline: FloatArray
    centres: FloatArray
    pitch: float
    normals: FloatArray = field(default_factory=lambda: np.empty((0, 3)))

    @property
    def samples(self) -> FloatArray:
        """The outline resampled every :data:`SPACING` mm."""
        return resample(self.outline)[0]

    @property
    def sample_normals(self) -> FloatArray:
        """Unit normals of the outline at :attr:`samples`."""
        _, segment = resample(self.outline)
        d = self.outline[:, 1] - self.outline[:, 0]
        n = np.c_[-d[:, 1], d[:, 0]] / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
        return n[segment]

    @property
    def extent(self) -> float:
        pts = self.surface if len(self.surface) else self.outline.reshape(-1, 2)
        return float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))


def model_shape(solution: Any, level: int = -1) -> ModelShape:
    """The :class:`ModelShape` of a solved design at a reported level (default: the last)."""
    mesh = solution.mesh
    u = solution.displacements[level]
    if not np.all(np.isfinite(u)):
        raise ScanError(f"the model did not converge up to level {level}; nothing to compare the scan with")
    x = mesh.points + u
    edges = outline(mesh)
    segments = x[edges][..., :2]
    centres = mesh.unit_centres(u)
    if mesh.dim == 2:
        return ModelShape(np.empty((0, 3)), np.empty(0, dtype=bool), segments, centres, mesh.spec.pitch)
    surface = mirrored_surface_points(mesh, u)
    ref = mirrored_surface_points(mesh)  # the same nodes in the same order, undeformed
    side = np.isclose(ref[:, 2], 0.0) | np.isclose(ref[:, 2], mesh.spec.width)
    normals = surface_normals(mesh, u)
    return ModelShape(surface, side, segments, centres, mesh.spec.pitch, normals)


def resample(segments: FloatArray, spacing: float = SPACING) -> tuple[FloatArray, NDArray[np.int64]]:
    """Points every ``spacing`` mm along the segments, and the segment of each."""
    a, b = segments[:, 0], segments[:, 1]
    n = np.maximum(1, np.ceil(np.linalg.norm(b - a, axis=1) / spacing).astype(int))
    t = np.concatenate([np.arange(k + 1) / k for k in n])
    i = np.repeat(np.arange(len(segments)), n + 1)
    return a[i] + t[:, None] * (b[i] - a[i]), i


@dataclass(frozen=True)
class Measure:
    """RMS and maximum of a set of distances, mm, and how many there were."""

    rms: float
    max: float
    count: int

    @classmethod
    def of(cls, d: FloatArray) -> Measure:
        d = np.asarray(d, dtype=float)
        if d.size == 0:
            return cls(float("nan"), float("nan"), 0)
        return cls(float(np.sqrt(np.mean(d**2))), float(d.max()), int(d.size))


@dataclass(frozen=True)
class Correlation:
    """A scan against the model: the alignment and the distances.

    Attributes
    ----------
    alignment : Alignment
        Maps the scan onto the model.
    surface, outline, centreline : Measure
    centre_offsets : ndarray, shape (u,)
        Per unit, the distance between the scan's and the model's centreline points (NaN
        where the scan has too few points).
    aligned : ndarray
        The scan points in the model's frame.
    """

    alignment: Alignment
    surface: Measure
    outline: Measure
    centreline: Measure
    centre_offsets: FloatArray
    aligned: FloatArray = field(repr=False)
    outline_points: FloatArray = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        def m(x: Measure) -> dict[str, Any]:
            return {"rms_mm": x.rms, "max_mm": x.max, "points": x.count}

        return {"transform": self.alignment.transform.to_dict(), "icp_rms_mm": self.alignment.rms,
                "iterations": self.alignment.iterations, "surface": m(self.surface), "outline": m(self.outline),
                "centreline": m(self.centreline), "centre_offsets_mm": self.centre_offsets.tolist()}


def check_length(scan: Scan, length: float) -> None:
    """Refuse, before any solve, a scan far larger or smaller than the actuator's length ``length`` mm.

    An inflated actuator spans between about a fifth of its length (curled) and a bit more
    than its length; a scan in cm or m, or a photo without its scale, does not.
    """
    ratio = scan.extent / length
    if not LENGTH_RANGE[0] <= ratio <= LENGTH_RANGE[1]:
        raise ScanError(
            f"scan {scan.source} spans {scan.extent:.4g} mm, {ratio:.3g} times the actuator's length {length:.4g} mm: "
            "check the scan's unit (--scan-unit mm, cm, m, in) or --scale")


def check_units(scan: Scan, shape: ModelShape) -> None:
    """Refuse a scan whose size is far from the model's: a unit or scale mistake."""
    ratio = scan.extent / max(shape.extent, 1e-12)
    if not UNIT_RANGE[0] <= ratio <= UNIT_RANGE[1]:
        raise ScanError(
            f"scan {scan.source} spans {scan.extent:.4g} mm but the model {shape.extent:.4g} mm "
            f"({ratio:.3g} times): check the scan's unit (--scan-unit mm, cm, m, in) or --scale")


def _slab_mids(points: FloatArray, centres: FloatArray, pitch: float) -> FloatArray:
    """Per centre, the mid-point offset across the actuator of the points in its slab (NaN if < 3)."""
    tangents = np.gradient(centres, axis=0)
    tangents /= np.linalg.norm(tangents, axis=1, keepdims=True)
    normals = np.c_[-tangents[:, 1], tangents[:, 0]]
    out = np.full(len(centres), np.nan)
    for i, (c, t, n) in enumerate(zip(centres, tangents, normals, strict=False)):
        rel = points - c
        inside = np.abs(rel @ t) <= pitch / 4
        if inside.sum() >= 3:
            across = rel[inside] @ n
            # only the points around this unit: the nearest run across it (a curled actuator folds back)
            across = across[np.abs(across) <= 2 * pitch]
            if across.size >= 3:
                out[i] = 0.5 * (across.min() + across.max())
    return out


def correlate(scan: Scan, shape: ModelShape, scale: bool = False, planar: bool = True) -> Correlation:
    """Align ``scan`` to the model and measure the distances (see the module docstring).

    ``planar=False`` (a design that leaves the bending plane: a sideways unit) measures the
    surface only: the outline and centreline measures are those of the bending plane.

    Raises
    ------
    ScanError
        A scan of the wrong size (unit), a 3D scan against a 2D model, a 2D trace of a
        design that leaves the plane.
    """
    check_units(scan, shape)
    if not planar and scan.dim != 3:
        raise ScanError(SIDEWAYS_TRACE)
    if scan.dim == 3:
        if not len(shape.surface):
            raise ScanError("a 3D scan needs the 3D model (--model 3d); a 2D model has no surface")
        alignment = icp(scan.points, shape.surface, scale=scale, normals=shape.normals)
        aligned = alignment.transform(scan.points)
        dist, nearest = cKDTree(shape.surface).query(aligned)
        surface = Measure.of(dist)
        outline_pts = aligned[~shape.side[nearest], :2]  # points on the top, bottom and end faces
    else:
        alignment = icp(scan.points, shape.samples, scale=scale, normals=shape.sample_normals)
        aligned = alignment.transform(scan.points)
        surface = Measure.of(np.empty(0))
        outline_pts = aligned
    if not planar:
        empty = Measure.of(np.empty(0))
        offsets = np.full(len(shape.centres), np.nan)
        return Correlation(alignment, surface, empty, empty, offsets, aligned, np.empty((0, 2)))
    samples = shape.samples
    outline_d, _ = cKDTree(samples).query(outline_pts)
    mids_scan = _slab_mids(outline_pts, shape.centres, shape.pitch)
    mids_model = _slab_mids(samples, shape.centres, shape.pitch)
    offsets = np.abs(mids_scan - mids_model)
    return Correlation(alignment, surface, Measure.of(outline_d), Measure.of(offsets[np.isfinite(offsets)]),
                       offsets, aligned, outline_pts)

"""Synthetic scans: a model's inflated shape as a scanner would return it, for trials of the scan loop.

A cast that differs from the nominal model (a softer silicone, a thinner wall) is stood in for by
the model with those changes; its shape is sampled (the surface nodes in 3D, the outline in 2D,
as :func:`~pneumorph.correlation.compare.model_shape` gives them), moved by a rigid motion the
scanner's frame would add, and given Gaussian noise. :func:`write_scan` writes it in a format
:func:`~pneumorph.correlation.scans.read_scan` reads: XYZ (3D) or a CSV of ``x,y`` (2D).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from pneumorph import checks
from pneumorph.correlation.align import Transform
from pneumorph.correlation.compare import ModelShape
from pneumorph.correlation.scans import MAX_SCAN_POINTS, MIN_POINTS, Scan
from pneumorph.errors import GeometryError, ScanError, SettingsError
from pneumorph.io.files import all_or_nothing_file
from pneumorph.models.factory import SCALE_RANGES, unit_or_library

#: the model settings a cast's silicone can differ by (factors on the body's moduli)
CAST_SCALES = ("body_bulk_scale", "body_shear_scale")


def cast_settings(settings: Mapping[str, Any], changes: Mapping[str, float]) -> dict[str, Any]:
    """The model settings of a cast that differs from ``settings`` by ``changes``.

    Parameters
    ----------
    settings : mapping
        The nominal model's settings (:func:`~pneumorph.models.factory.make_model`).
    changes : mapping of str to float
        ``body_bulk_scale`` and ``body_shear_scale`` (factors on the body silicone's moduli, as
        an identified model has them), or any numeric field of the unit (``wall``, ``layer``,
        ``side_wall``, mm ...): the cast's values.

    Raises
    ------
    SettingsError
        An unknown name, a scale outside its range, a unit field over a unit library, or a unit
        the changed field makes invalid (the message names the field).

    Examples
    --------
    >>> s = cast_settings({"fidelity": "2d"}, {"wall": 1.4, "body_shear_scale": 0.9})
    >>> s["unit"]["wall"], s["body_shear_scale"], s["fidelity"]
    (1.4, 0.9, '2d')
    """
    out = dict(settings)
    unit_changes = {k: float(v) for k, v in changes.items() if k not in CAST_SCALES}
    for key in CAST_SCALES:
        if key in changes:  # the range the model factory refuses outside of, checked here as the change's
            out[key] = checks.real(changes[key], key, *SCALE_RANGES[key])
    if unit_changes:
        unit, _ = unit_or_library(out)
        if unit is None:
            raise SettingsError(f"{', '.join(unit_changes)}: a unit library's types are changed in its file, not "
                                "one field for all")
        data = unit.with_own_filler().to_dict()  # the cast keeps the nominal unit's 2D filler law
        for key, value in unit_changes.items():
            if not isinstance(data.get(key), float) or key == "element_size":
                names = ", ".join([*CAST_SCALES, *sorted(k for k, v in data.items()
                                                         if isinstance(v, float) and k != "element_size")])
                raise SettingsError(f"unknown cast change {key!r}; known: {names}")
            data[key] = value
        try:
            type(unit).from_dict(data, source="the cast's unit")
        except GeometryError as exc:
            raise SettingsError(f"the cast's unit: {exc}") from None
        out.pop("unit_file", None)
        out["unit"] = data
    return out


@dataclass(frozen=True)
class ScanNoise:
    """How a synthetic scan differs from the model's shape.

    Parameters
    ----------
    points : int
        Points sampled (without repeats; all of them when the shape has fewer).
    noise : float
        Standard deviation of the Gaussian noise on every coordinate, mm.
    rotation : float
        Angle of the rigid rotation into the scanner's frame, degrees (about a random axis;
        in 2D about the normal of the plane).
    shift : float
        Length of the rigid translation, mm (in a random direction).
    seed : int
        Seed of the sample, the motion and the noise: the same scan every time.
    """

    points: int = 1500
    noise: float = 0.05
    rotation: float = 15.0
    shift: float = 10.0
    seed: int = 0

    def check(self) -> None:
        """Refuse settings no scan can have, naming the field.

        >>> ScanNoise(points=5).check()
        Traceback (most recent call last):
        ...
        pneumorph.errors.ScanError: points = 5: a scan needs between 10 and 500000 points
        """
        if not MIN_POINTS <= self.points <= MAX_SCAN_POINTS:
            raise ScanError(f"points = {self.points}: a scan needs between {MIN_POINTS} and {MAX_SCAN_POINTS} points")
        for name, value, top in (("noise", self.noise, 10.0), ("rotation", self.rotation, 180.0),
                                 ("shift", self.shift, 1e4)):
            if not (np.isfinite(value) and 0.0 <= value <= top):
                raise ScanError(f"{name} = {value}: give a value between 0 and {top:g}")


def synthetic_scan(shape: ModelShape, settings: ScanNoise | None = None) -> tuple[Scan, Transform]:
    """A scan of ``shape``: sampled, moved rigidly and noisy; with the motion that moved it.

    Parameters
    ----------
    shape : ModelShape
        The model's deformed shape (:func:`~pneumorph.correlation.compare.model_shape`): its
        surface nodes (3D) or its outline resampled (2D) are the points scanned.
    settings : ScanNoise, optional
        Points, noise, motion and seed (default :class:`ScanNoise`'s).

    Returns
    -------
    scan : Scan
        The points, mm (no faces).
    motion : Transform
        The rigid motion from the model's frame to the scan's (before the noise).

    Examples
    --------
    >>> import numpy as np
    >>> from pneumorph.correlation.compare import ModelShape
    >>> line = np.array([[[0.0, 0.0], [100.0, 0.0]]])
    >>> shape = ModelShape(np.empty((0, 3)), np.empty(0, bool), line, np.zeros((1, 2)), 10.5)
    >>> scan, motion = synthetic_scan(shape, ScanNoise(points=50, noise=0.0, rotation=0.0, shift=0.0))
    >>> scan.dim, len(scan.points), float(scan.points[:, 1].max())
    (2, 50, 0.0)
    """
    s = ScanNoise() if settings is None else settings
    s.check()
    rng = np.random.default_rng(s.seed)
    cloud = shape.surface if len(shape.surface) else shape.samples
    dim = cloud.shape[1]
    chosen = cloud[np.sort(rng.choice(len(cloud), min(s.points, len(cloud)), replace=False))]
    axis = rng.normal(size=3) if dim == 3 else np.array([0.0, 0.0, 1.0])
    rotation = Rotation.from_rotvec(np.radians(s.rotation) * axis / np.linalg.norm(axis)).as_matrix()[:dim, :dim]
    direction = rng.normal(size=dim)
    motion = Transform(rotation, np.asarray(s.shift * direction / np.linalg.norm(direction), dtype=float))
    points = motion(chosen) + rng.normal(scale=s.noise, size=chosen.shape)
    return Scan(points, None, f"synthetic scan ({len(points)} points, noise {s.noise:g} mm, seed {s.seed})"), motion


def write_scan(scan: Scan, path: str | Path) -> Path:
    """Write ``scan`` for :func:`~pneumorph.correlation.scans.read_scan`: XYZ for 3D points, CSV for 2D.

    The file appears whole or not at all (a failure or Ctrl-C while writing leaves nothing).

    Raises
    ------
    ScanError
        A suffix that does not hold the scan's points (``.xyz`` for 3D, ``.csv`` for 2D).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from pneumorph.correlation.scans import read_scan
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "trace.csv"
    >>> scan = Scan(np.c_[np.arange(12.0), np.arange(12.0) % 2], None, "zigzag")
    >>> read_scan(write_scan(scan, p)).points[-1].tolist()
    [11.0, 1.0]
    """
    p = Path(path)
    want = ".xyz" if scan.dim == 3 else ".csv"
    if p.suffix.lower() != want:
        kind = "a 3D scan's points go to an .xyz file" if scan.dim == 3 else "a 2D trace goes to a .csv file of x,y"
        raise ScanError(f"{p}: {kind}")
    with all_or_nothing_file(p) as tmp:
        header = "" if scan.dim == 3 else "x,y"
        np.savetxt(tmp, scan.points, fmt="%.5f", delimiter=" " if scan.dim == 3 else ",", header=header, comments="")
    return p


__all__ = ["CAST_SCALES", "ScanNoise", "cast_settings", "synthetic_scan", "write_scan"]

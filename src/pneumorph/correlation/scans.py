"""Reading scans of inflated actuators: meshes and point clouds, or points traced on a photo.

A scan is a cloud of points in mm. Meshes (STL, PLY, OBJ) and point clouds (PLY, OBJ,
XYZ) are read with trimesh, which is made for these formats; the faces are kept. A CSV
holds traced points, ``x,y`` (2D, from a photo) or ``x,y,z`` with a header row. The scan's
unit (mm, cm, m or in; or a scale in mm per unit, e.g. mm per pixel) converts it to mm.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path
from struct import error as struct_error

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import ScanError, interrupts_kept
from pneumorph.io.reading import MAX_SCAN_BYTES, MAX_TEXT_BYTES, check_input_file, csv_rows, read_text_file

FloatArray = NDArray[np.float64]

#: Millimetres per unit of a scan.
SCAN_UNITS = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}
MESH_SUFFIXES = (".stl", ".ply", ".obj", ".off", ".xyz")
MIN_POINTS = 10
#: Largest coordinate of a scan, mm, after its unit or scale: a kilometre, beyond any scanner's frame; far beyond
#: it the alignment's squares and the scan's extent pass the range of a number
MAX_SCAN_MM = 1e6
#: most points of a scan: the alignment (ICP from several starts, a nearest-neighbour query of every point per
#: iteration) grows with the points, about :data:`ALIGN_SECONDS_PER_POINT` each; this many take about 30 s
MAX_SCAN_POINTS = 500_000
#: seconds of alignment per scan point (measured: 200,000 points against the 3D model of 4 units in 11.5 s)
ALIGN_SECONDS_PER_POINT = 6e-5


def align_seconds(points: int) -> float:
    """The estimated wall time of aligning a scan of ``points`` points (s).

    >>> round(align_seconds(2_000_000))
    120
    """
    return ALIGN_SECONDS_PER_POINT * int(points)


def check_points(path: str | Path, points: int) -> None:
    """Refuse a scan of more than :data:`MAX_SCAN_POINTS` points, with the estimate of its alignment.

    Raises
    ------
    ScanError
        Naming the count, the limit and how to thin the scan out.

    Examples
    --------
    >>> check_points("big.stl", 2_000_000)
    Traceback (most recent call last):
    ...
    pneumorph.errors.ScanError: scan big.stl: 2,000,000 points, more than MAX_SCAN_POINTS = 500,000
        (pneumorph.correlation.scans): aligning them would take about 2 min; thin the scan out (one point in 4
        leaves 500,000)
    """
    if points > MAX_SCAN_POINTS:
        from pneumorph.io.progress import duration_text

        every = -(-int(points) // MAX_SCAN_POINTS)
        raise ScanError(f"scan {path}: {points:,} points, more than MAX_SCAN_POINTS = {MAX_SCAN_POINTS:,} "
                        f"(pneumorph.correlation.scans): aligning them would take about "
                        f"{duration_text(align_seconds(points))}; thin the scan out (one point in {every} "
                        f"leaves {-(-int(points) // every):,})")


@dataclass(frozen=True)
class Scan:
    """Points of a scan in mm, and its faces if it is a mesh.

    Attributes
    ----------
    points : ndarray, shape (n, 2) or (n, 3)
    faces : ndarray, shape (m, 3), or None
    source : str
    """

    points: FloatArray
    faces: NDArray[np.int64] | None
    source: str

    @property
    def dim(self) -> int:
        return int(self.points.shape[1])

    @property
    def extent(self) -> float:
        """Diagonal of the bounding box, mm."""
        return float(np.linalg.norm(self.points.max(axis=0) - self.points.min(axis=0)))


def read_scan(path: str | Path, unit: str = "mm", scale: float | None = None) -> Scan:
    """A scan from a mesh, point-cloud or CSV file, in mm.

    Parameters
    ----------
    path : str or Path
    unit : {"mm", "cm", "m", "in"}
        The unit the file is written in.
    scale : float, optional
        mm per unit of the file (a photo's mm per pixel), instead of ``unit``.

    Raises
    ------
    ScanError
        Unreadable, empty, not a mesh or point cloud, fewer than 10 points or more than
        :data:`MAX_SCAN_POINTS` (:func:`check_points`), not finite.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "trace.csv"
    >>> _ = p.write_text("x,y\\n" + "".join(f"{i},{i * i}\\n" for i in range(12)))
    >>> s = read_scan(p, scale=0.5)
    >>> s.dim, s.points[-1].tolist()
    (2, [5.5, 60.5])
    """
    p = Path(path)
    if unit not in SCAN_UNITS:
        raise ScanError(f"unknown scan unit {unit!r}; known: {', '.join(SCAN_UNITS)}")
    factor = SCAN_UNITS[unit] if scale is None else float(scale)
    if not (np.isfinite(factor) and factor > 0):
        raise ScanError(f"the scan's scale must be a positive number of mm per unit, got {scale!r}")
    if check_input_file(p, "scan", ScanError, MAX_SCAN_BYTES).st_size == 0:  # a folder, a device, a pipe: by name
        raise ScanError(f"scan {p}: the file is empty")
    suffix = p.suffix.lower()
    if suffix in (".csv", ".txt"):
        points, faces = _read_csv(p), None
    elif suffix in MESH_SUFFIXES:
        points, faces = _read_mesh(p)
    else:
        raise ScanError(f"scan {p}: unknown format {suffix or '(none)'}; give STL, PLY, OBJ, OFF, XYZ or CSV")
    if len(points) < MIN_POINTS:
        raise ScanError(f"scan {p}: {len(points)} points; at least {MIN_POINTS} are needed")
    check_points(p, len(points))
    if not np.all(np.isfinite(points)):
        raise ScanError(f"scan {p}: some coordinates are not finite")
    with np.errstate(over="ignore"):  # past the range of a number: inf, refused below in one line
        scaled = points * factor
    largest = float(np.abs(scaled).max())
    if largest > MAX_SCAN_MM:
        raise ScanError(f"scan {p}: a coordinate of {largest:.3g} mm, and a scan lies within {MAX_SCAN_MM:g} mm of "
                        "its origin: check the scan's unit (--scan-unit mm, cm, m, in) or --scale")
    check_spread(p, points)
    return Scan(scaled, faces, str(p))


#: Least spread of a scan across its thinnest direction, relative to its widest (singular values of the centred
#: points): below it the points lie on a line (2D) or a plane (3D), which no alignment can place
MIN_SPREAD = 1e-6


def check_spread(path: str | Path, points: FloatArray) -> None:
    """Refuse a scan whose points lie on a line (a 2D trace) or on a plane (a 3D scan), before any solve.

    An actuator's outline is two-dimensional and its surface three-dimensional: points without spread across
    one direction leave the alignment free along it (and say nothing of a bend), so the fit would not converge.

    Raises
    ------
    ScanError
        The thinnest spread below :data:`MIN_SPREAD` of the widest.

    Examples
    --------
    >>> line = np.c_[np.linspace(0, 40, 500), np.linspace(0, 20, 500)]
    >>> check_spread("line.csv", line)
    Traceback (most recent call last):
    ...
    pneumorph.errors.ScanError: scan line.csv: its 500 points lie on a straight line (a 2D trace must follow the
        outline of the actuator, its width too): no alignment can place them
    >>> check_spread("trace.csv", np.c_[line[:, 0], np.sin(line[:, 0])])
    """
    centred = points - points.mean(axis=0)
    size = float(np.abs(centred).max()) if centred.size else 0.0
    if size > 0:  # the ratio is the same at any scale; coordinates near the float range would overflow squared
        centred = centred / size
    spread = np.sqrt(np.clip(np.linalg.eigvalsh(centred.T @ centred), 0.0, None))  # ascending
    if spread[-1] > 0 and spread[0] >= MIN_SPREAD * spread[-1]:
        return
    dim = points.shape[1]
    shape = ("a single point" if spread[-1] == 0 else "a straight line" if dim == 2 or spread[1] < MIN_SPREAD *
             spread[-1] else "a plane")
    need = ("a 2D trace must follow the outline of the actuator, its width too" if dim == 2 else
            "a 3D scan must cover the actuator's surface, not one face of it")
    raise ScanError(f"scan {path}: its {len(points)} points lie on {shape} ({need}): no alignment can place them")


def _read_csv(path: Path) -> FloatArray:
    text = read_text_file(path, "scan", ScanError, encoding="utf-8-sig", limit=MAX_TEXT_BYTES)  # 500,000 points: 25 MB
    check_points(path, text.count("\n") - 1)  # the rows below the header, before they are parsed
    rows = [r for r in csv_rows(io.StringIO(text), f"scan {path}", ScanError) if any(c.strip() for c in r)]
    if not rows:
        raise ScanError(f"scan {path}: no rows")
    header = [c.strip().lower() for c in rows[0]]
    if header[:2] != ["x", "y"] or (len(header) > 2 and header[2] != "z"):
        raise ScanError(f"scan {path}: expected a header row 'x,y' or 'x,y,z', found {','.join(rows[0])!r}")
    width = 3 if len(header) > 2 else 2
    values = []
    for number, row in enumerate(rows[1:], start=2):
        try:
            values.append([float(c) for c in row[:width]])
        except ValueError:
            raise ScanError(f"scan {path}, row {number}: expected {width} numbers, got {row!r}") from None
        if len(values[-1]) != width:
            raise ScanError(f"scan {path}, row {number}: expected {width} numbers, got {row!r}")
    return np.array(values, dtype=float).reshape(-1, width)


def _why(exc: Exception, suffix: str) -> str:
    """A parser's failure in words: what is wrong with the file, not which module tripped.

    >>> _why(KeyError("z"), ".ply"), _why(ModuleNotFoundError("charset_normalizer"), ".stl")
    ('its vertices have no z coordinate', 'its contents are neither a binary nor a text .stl file')
    """
    kind = suffix.lower() or "mesh"
    if isinstance(exc, KeyError) and exc.args and str(exc.args[0]) in ("x", "y", "z"):
        return f"its vertices have no {exc.args[0]} coordinate"
    if isinstance(exc, (ModuleNotFoundError, UnicodeDecodeError)):
        return _neither(suffix)
    if isinstance(exc, (IndexError, ValueError, struct_error)):
        return f"its contents do not match the {kind} format ({type(exc).__name__}: {exc})"
    return f"{type(exc).__name__}: {exc}"


def _neither(suffix: str) -> str:
    """A file that is no mesh of its format, binary or text."""
    return f"its contents are neither a binary nor a text {suffix.lower() or 'mesh'} file"


def _read_mesh(path: Path) -> tuple[FloatArray, NDArray[np.int64] | None]:
    with interrupts_kept():  # trimesh swallows a Ctrl-C in its optional imports, at import and at load
        import trimesh

        try:
            loaded = trimesh.load(path, force=None, process=False)
        except Exception as exc:  # any parser failure is a file that is not a scan
            raise ScanError(f"scan {path}: not a readable mesh or point cloud ({_why(exc, path.suffix)})") from None
    if isinstance(loaded, trimesh.Scene):
        geometries = list(loaded.geometry.values())
        if not geometries:  # an STL parser that finds no facet (junk read as text) answers an empty scene
            why = f" ({_neither(path.suffix)})" if path.suffix.lower() == ".stl" else ""
            raise ScanError(f"scan {path}: the file holds no geometry{why}")
        loaded = trimesh.util.concatenate(geometries) if len(geometries) > 1 else geometries[0]
    vertices = np.asarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=float)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) == 0:
        raise ScanError(f"scan {path}: no points found")
    faces = getattr(loaded, "faces", None)
    if faces is None or len(faces) == 0:
        return vertices, None
    return vertices, check_faces(path, np.asarray(faces), len(vertices))


def check_faces(path: str | Path, faces: NDArray[np.int64], vertices: int) -> NDArray[np.int64]:
    """A mesh's faces as vertex indices, refused if they do not fit its vertices.

    Raises
    ------
    ScanError
        Faces that are not triples of whole numbers, or an index outside ``0 .. vertices - 1`` (a file whose face
        list refers to vertices it does not have), naming the first such face.

    Examples
    --------
    >>> check_faces("a.ply", np.array([[0, 1, 2], [1, 2, 3]]), 4).shape
    (2, 3)
    >>> check_faces("a.ply", np.array([[0, 1, 2], [1, 2, 7]]), 4)
    Traceback (most recent call last):
    ...
    pneumorph.errors.ScanError: scan a.ply: face 2 refers to vertex 7, but the file has 4 vertices (0 to 3); its
        faces are inconsistent with its vertices
    """
    if faces.ndim != 2 or faces.shape[1] != 3 or faces.dtype.kind not in "iu":
        raise ScanError(f"scan {path}: its faces are not triangles of vertex indices (shape {faces.shape}, "
                        f"{faces.dtype})")
    bad = np.flatnonzero((faces < 0).any(axis=1) | (faces >= vertices).any(axis=1))
    if len(bad):
        row = faces[bad[0]]
        index = int(row[(row < 0) | (row >= vertices)][0])
        raise ScanError(f"scan {path}: face {bad[0] + 1} refers to vertex {index}, but the file has {vertices} "
                        f"vertices (0 to {vertices - 1}); its faces are inconsistent with its vertices")
    return faces.astype(np.int64)

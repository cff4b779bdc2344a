"""CalculiX run on a deck of :mod:`pneumorph.export.calculix`, and its displacements read back:
:func:`run_calculix` runs ``ccx``; :func:`read_dat_displacements` and
:func:`read_frd_displacements` read its displacements and :func:`tip_positions` turns them
into the tip pneumorph reports (the mean deformed (x, y) of the end-face nodes on the
mid-plane, ``ActuatorMesh.end_points``, node set ``TIP``).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import (
    DataFormatError,
    SettingsError,
    SimulationFailed,
)
from pneumorph.export.calculix import calculix_mesh, write_calculix_deck
from pneumorph.geometry.alphabet import Design
from pneumorph.geometry.assembly import ActuatorMesh
from pneumorph.geometry.orientation import parse_orientation

__all__ = ["CalculixResult", "NodalDisplacements", "read_dat_displacements", "read_frd_displacements", "run_calculix",
           "tip_positions"]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


# -- reading CalculiX's results ------------------------------------------------------------

@dataclass(frozen=True)
class NodalDisplacements:
    """Displacements of some nodes at one output time.

    Attributes
    ----------
    time : float
        Step time (the load factor: 1 = the full pressure).
    nodes : ndarray of int
        Node numbers as in the deck (1-based).
    values : ndarray, shape (m, 3)
        Displacements (mm).
    """

    time: float
    nodes: IntArray
    values: FloatArray


_DAT_HEADER = re.compile(r"^\s*displacements \(vx,vy,vz\) for set (\S+) and time\s+(\S+)", re.IGNORECASE)


def read_dat_displacements(path: str | os.PathLike[str], nset: str = "TIP") -> list[NodalDisplacements]:
    """The ``*NODE PRINT`` displacement blocks of node set ``nset`` in a CalculiX ``.dat`` file.

    Parameters
    ----------
    path : str or path-like
    nset : str
        The node set (case-insensitive).

    Returns
    -------
    list of NodalDisplacements
        In file order (increasing time).

    Raises
    ------
    DataFormatError
        If the file is missing, or a line of a block is not ``node ux uy uz``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "a.dat"
    >>> _ = p.write_text(" displacements (vx,vy,vz) for set TIP and time  0.5000000E+00\\n\\n"
    ...                  "         7  1.0E-01 -2.0E-01  0.0E+00\\n")
    >>> r = read_dat_displacements(p)
    >>> r[0].time, r[0].nodes.tolist(), r[0].values.tolist()
    (0.5, [7], [[0.1, -0.2, 0.0]])
    """
    p = Path(path)
    try:
        lines = p.read_text(errors="replace").splitlines()
    except OSError as exc:
        raise DataFormatError(f"cannot read CalculiX results: {exc.strerror or exc}", path=str(p)) from None
    out: list[NodalDisplacements] = []
    i = 0
    while i < len(lines):
        m = _DAT_HEADER.match(lines[i])
        i += 1
        if not m or m.group(1).upper() != nset.upper():
            continue
        t = float(m.group(2))
        nodes, values = [], []
        while i < len(lines) and not lines[i].strip():
            i += 1
        while i < len(lines) and lines[i].strip():
            parts = lines[i].split()
            try:
                if len(parts) != 4:
                    raise ValueError
                nodes.append(int(parts[0]))
                values.append([float(v) for v in parts[1:]])
            except ValueError:
                raise DataFormatError(f"expected 'node ux uy uz', got {lines[i].strip()!r}", path=str(p),
                                      row=i + 1) from None
            i += 1
        out.append(NodalDisplacements(t, np.asarray(nodes, dtype=np.int64), np.asarray(values, dtype=float)))
    return out


def read_frd_displacements(path: str | os.PathLike[str], nodes: Sequence[int] | None = None
                           ) -> list[NodalDisplacements]:
    """The ``DISP`` result blocks of a CalculiX ``.frd`` file (ASCII).

    Parameters
    ----------
    path : str or path-like
    nodes : sequence of int, optional
        Keep these node numbers (1-based) only; all by default.

    Returns
    -------
    list of NodalDisplacements
        One per output time, in file order.

    Raises
    ------
    DataFormatError
        If the file is missing or a result line cannot be read.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "a.frd"
    >>> _ = p.write_text("  100CL  101 1.000000000           1                     0    1           1\\n"
    ...                  " -4  DISP        4    1\\n"
    ...                  " -1         3 1.00000E-01-2.00000E-01 0.00000E+00\\n -3\\n")
    >>> r = read_frd_displacements(p)
    >>> r[0].time, r[0].nodes.tolist(), r[0].values.tolist()
    (1.0, [3], [[0.1, -0.2, 0.0]])
    """
    p = Path(path)
    keep = None if nodes is None else {int(n) for n in nodes}
    try:
        fh = p.open(errors="replace")
    except OSError as exc:
        raise DataFormatError(f"cannot read CalculiX results: {exc.strerror or exc}", path=str(p)) from None
    out: list[NodalDisplacements] = []
    t = float("nan")
    block: tuple[list[int], list[list[float]]] | None = None
    with fh:
        for row, line in enumerate(fh, start=1):
            key = line[:3].strip()
            if line[2:6] == "100C":  # result block header: the time follows the set number
                try:
                    t = float(line[12:24])
                except ValueError:
                    raise DataFormatError(f"cannot read the time in {line.strip()!r}", path=str(p),
                                          row=row) from None
            elif key == "-4":
                block = ([], []) if line[5:13].strip() == "DISP" else None
            elif block is not None and key == "-1":
                try:
                    n = int(line[3:13])
                    vals = [float(line[13 + 12 * k: 25 + 12 * k]) for k in range(3)]
                except ValueError:
                    raise DataFormatError(f"cannot read the result line {line.rstrip()!r}", path=str(p),
                                          row=row) from None
                if keep is None or n in keep:
                    block[0].append(n)
                    block[1].append(vals)
            elif block is not None and key == "-3":
                out.append(NodalDisplacements(t, np.asarray(block[0], dtype=np.int64),
                                              np.asarray(block[1], dtype=float).reshape(-1, 3)))
                block = None
    return out


def tip_positions(results: Sequence[NodalDisplacements], mesh: ActuatorMesh) -> tuple[FloatArray, FloatArray]:
    """The tip pneumorph reports - mean deformed (x, y) of ``mesh.end_points`` - at each time.

    Parameters
    ----------
    results : sequence of NodalDisplacements
        From :func:`read_dat_displacements` (node set ``TIP``) or
        :func:`read_frd_displacements`; node numbers are the mesh's indices + 1.
    mesh : ActuatorMesh
        The mesh the deck was written from (:func:`calculix_mesh`).

    Returns
    -------
    times : ndarray, shape (k,)
    tip : ndarray, shape (k, 2) or (k, 3)
        mm, as :attr:`pneumorph.models.response.Response.tip` ((x, y, z) on the full width).

    Raises
    ------
    DataFormatError
        If a result lacks one of the end-face nodes.
    """
    wanted = mesh.end_points + 1
    axes = mesh.axes  # (x, y), or (x, y, z) on the full width
    x0 = mesh.points[mesh.end_points][:, :axes]
    times, tips = [], []
    for r in results:
        where = {int(n): k for k, n in enumerate(r.nodes)}
        missing = [int(n) for n in wanted if int(n) not in where]
        if missing:
            raise DataFormatError(f"the results at time {r.time:g} lack end-face node(s) {missing[:5]}")
        u = r.values[[where[int(n)] for n in wanted]][:, :axes]
        times.append(r.time)
        tips.append((x0 + u).mean(axis=0))
    return np.asarray(times, dtype=float), np.asarray(tips, dtype=float).reshape(-1, axes)


# -- running CalculiX -------------------------------------------------------------------

@dataclass(frozen=True)
class CalculixResult:
    """What :func:`run_calculix` found.

    Attributes
    ----------
    deck : Path
        The ``.inp`` file run (``.dat`` and ``.frd`` beside it).
    pressures : ndarray, shape (k,)
        The pressures (MPa) of the output times, as ``Response.pressures``.
    tip : ndarray, shape (k, 2)
        The tip (mm) at those pressures, as ``Response.tip``.
    wall_time_s : float
        Time ``ccx`` took.
    log : str
        Its standard output and error.
    """

    deck: Path
    pressures: FloatArray
    tip: FloatArray
    wall_time_s: float
    log: str


def run_calculix(model: Any, design: str | Design, folder: str | os.PathLike[str], *, executable: str = "ccx",
                 threads: int | None = None, timeout: float | None = None, full_output: bool = False,
                 residual_force: float = 1.0e-4) -> CalculixResult:
    """Write the deck of ``design`` into ``folder``, run CalculiX on it and read the tip.

    Parameters
    ----------
    model : Full3D
    design : str
    folder : str or path-like
        Where ``design.inp`` and CalculiX's outputs go (created if needed).
    executable : str
        The CalculiX program (``ccx`` on Debian's ``calculix-ccx``).
    threads : int, optional
        ``OMP_NUM_THREADS`` and ``CCX_NPROC_EQUATION_SOLVER`` for ``ccx`` (default: the
        environment's, else 1).
    timeout : float, optional
        Seconds before ``ccx`` is stopped.
    full_output : bool
        Also write all displacements to the ``.frd`` file.
    residual_force : float
        See :func:`calculix_deck`.

    Returns
    -------
    CalculixResult

    Raises
    ------
    SettingsError
        If ``executable`` is not found.
    SimulationFailed
        If ``ccx`` stops with an error, times out, or does not reach the full pressure.
    """
    exe = shutil.which(executable)
    if exe is None:
        raise SettingsError(f"CalculiX ({executable!r}) is not on the PATH; on Debian: apt-get install calculix-ccx")
    text: str
    if getattr(model, "mixed", False):  # a design over a unit library, in its letters
        text = model.parse(design).text
    else:
        text = parse_orientation(design.orientation if isinstance(design, Design) else design,
                                 getattr(model, "n_units", None))
    design = text
    out_dir = Path(folder)
    out_dir.mkdir(parents=True, exist_ok=True)
    deck = write_calculix_deck(model, design, out_dir / f"design_{design}.inp", full_output=full_output,
                               residual_force=residual_force)
    dat, frd = deck.with_suffix(".dat"), deck.with_suffix(".frd")
    for old in (dat, frd):
        old.unlink(missing_ok=True)
    env = dict(os.environ)
    n = str(threads) if threads is not None else env.get("OMP_NUM_THREADS", "1")
    env.update(OMP_NUM_THREADS=n, CCX_NPROC_EQUATION_SOLVER=n)
    t0 = time.perf_counter()
    try:
        proc = subprocess.run([exe, "-i", deck.stem], cwd=out_dir, env=env, capture_output=True, text=True,
                              timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        raise SimulationFailed(reached=0.0, cause=f"CalculiX did not finish within {timeout:g} s", design=design,
                               pressure=model.ramp.pressure) from None
    wall = time.perf_counter() - t0
    log = proc.stdout + proc.stderr
    mesh = calculix_mesh(model, design)
    times, tip = tip_positions(read_dat_displacements(dat), mesh) if dat.exists() else (np.zeros(0),
                                                                                        np.zeros((0, mesh.axes)))
    reached = float(times[-1]) if times.size else 0.0
    errors = [line.strip() for line in log.splitlines() if "*ERROR" in line]
    if proc.returncode != 0 or errors or not np.isclose(reached, 1.0):
        cause = errors[0] if errors else f"ccx exited with {proc.returncode} at load factor {reached:g}"
        raise SimulationFailed(reached=reached, cause=f"CalculiX: {cause}", design=design,
                               pressure=model.ramp.pressure)
    return CalculixResult(deck, times * model.ramp.pressure, tip, wall, log)

"""What to scan next: the further scan that would determine what the scans do not.

A combination of parameters the scans do not determine (:class:`~pneumorph.identify.linear.Directions`)
is determined by a scan whose shape moves along it. Each candidate (:func:`candidates`: a scanned design
at a second pressure, or a design that bends differently) is solved at the fitted parameters with its
Jacobian, as a scan is; a scan of it is taken to be its model's own shape with as many points as the
scans have (:func:`candidate_normal`), and its ``J^T J`` is added to the scans' (alignment taken out,
each scan's is a sum of its own). :func:`rank` orders the candidates by how many parameters the scans
with it would identify, then by the smallest eigenvalue: which further scan raises the smallest
singular value most. The glue that solves the candidates is :func:`pneumorph.identify.fit.identify`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.correlation.align import Transform
from pneumorph.correlation.compare import ModelShape
from pneumorph.identify.linear import (
    MAX_DIRECTION_ERROR,
    MAX_SHARE,
    Directions,
    LinearisedScan,
    LinearisedState,
    directions,
    linearised_system,
    project_out,
    shape_nodes,
)
from pneumorph.identify.scans import ScanSpec

FloatArray = NDArray[np.float64]

#: a scanned design's second pressure, as a fraction of its scan's pressure
PRESSURE_FRACTION = 0.5
#: the candidates solved at most (each one ramp and a warm start per fitted parameter)
MAX_CANDIDATES = 4


def candidates(specs: Sequence[ScanSpec], limit: int = MAX_CANDIDATES) -> list[ScanSpec]:
    """The further scans to weigh: each scanned design at :data:`PRESSURE_FRACTION` of its pressure, then
    designs of the first scan's length that bend differently (every unit as built, the second half turned,
    every other unit turned) at its pressure; none already scanned, at most ``limit``.

    Examples
    --------
    >>> [(c.design, c.pressure_kpa) for c in candidates([ScanSpec("a.stl", "0110", 30.0)])]
    [('0110', 15.0), ('0000', 30.0), ('0011', 30.0), ('0101', 30.0)]
    """
    done = {(s.design, s.pressure_kpa) for s in specs}
    n, pressure = len(specs[0].design), specs[0].pressure_kpa
    wanted = [(s.design, round(s.pressure_kpa * PRESSURE_FRACTION * 2) / 2) for s in specs]
    wanted += [("0" * n, pressure), ("0" * (n // 2) + "1" * (n - n // 2), pressure), (("01" * n)[:n], pressure)]
    out: list[ScanSpec] = []
    for design, p in wanted:
        if (design, p) not in done and p > 0:
            done.add((design, p))
            out.append(ScanSpec(f"{design} at {p:g} kPa (not scanned)", design, p))
    return out[:limit]


def candidate_normal(shape: ModelShape, derivatives: FloatArray, dim: int, scale: FloatArray,
                     points: int) -> FloatArray:
    """``J^T J`` of a scan of ``shape`` (its own surface nodes, or outline samples, ``points`` of them
    evenly spread) by the parameters in units of ``scale``, its alignment taken out.

    Examples
    --------
    A straight outline whose second end point moves sideways with the parameter: a rigid rotation
    mimics it, so a scan of it learns nothing.

    >>> shape = ModelShape(np.zeros((0, 3)), np.zeros(0, bool), np.array([[[0.0, 0.0], [10.0, 0.0]]]),
    ...                    np.zeros((1, 2)), 10.0, np.zeros((0, 3)))
    >>> float(abs(candidate_normal(shape, np.array([[[0.0, 0.0], [0.0, 1.0]]]), 2, np.ones(1), 50)[0, 0])) < 1e-9
    True
    """
    nodes, normals = shape_nodes(shape, dim)
    cloud = shape.surface if dim == 3 else shape.samples
    x = cloud[np.unique(np.linspace(0, len(cloud) - 1, min(points, len(cloud))).round().astype(int))]
    lin = LinearisedScan(dim, nodes, derivatives, normals)
    identity = Transform(np.eye(dim), np.zeros(dim))
    _, a, _ = linearised_system([lin], [x], LinearisedState(np.zeros(len(scale)), [identity]), scale)
    ap = project_out(a, len(scale)) * np.sqrt(points / len(x))  # as a scan of ``points`` points
    return np.asarray(ap.T @ ap, dtype=float)


def determined(found: Directions) -> NDArray[np.bool_]:
    """The parameters ``found`` determines: not moving with a held combination, standard error within
    a plausible change."""
    return np.asarray((found.shares() <= MAX_SHARE)
                      & (found.standard_errors() <= MAX_DIRECTION_ERROR * found.spans), dtype=bool)


def rank(found: Directions, normal: FloatArray, further: Sequence[tuple[ScanSpec, FloatArray]],
         scanned: Sequence[ScanSpec]) -> list[dict[str, Any]]:
    """The candidates ``further`` (each with its ``J^T J``) added in turn to the scans' ``normal``: what
    each would determine, best first, each with a sentence saying why.

    Examples
    --------
    Two parameters the scans move alike; a further scan that moves only the first tells them apart:

    >>> j = np.array([[1.0, 1.0], [1.0, 1.0001]]) * 100
    >>> found = directions(j.T @ j, 0.05, ("a", "b"), np.array([0.05, 0.05]), 2)
    >>> spec = ScanSpec("s", "0110", 30.0)
    >>> [r["determines"] for r in rank(found, j.T @ j, [(ScanSpec("c", "0110", 15.0), np.diag([1e4, 0]))], [spec])]
    [['a', 'b']]
    >>> import textwrap
    >>> print(textwrap.fill(rank(found, j.T @ j, [(ScanSpec("c", "0110", 15.0), np.diag([1e4, 0]))], [spec])[0]["why"]))
    the scans at 30 kPa cannot tell a and b apart: a scan of design 0110
    again at 15 kPa would identify a and b (the weakest combination's
    standard error 10 -> 0.00076 plausible changes)
    """
    now = determined(found)
    confounded = " and ".join(n for n, ok in zip(found.names, now, strict=True) if not ok)
    weakest = float(directions(normal, found.sigma, found.names, found.spans, found.points).errors().max())
    pressures = ", ".join(f"{p:g}" for p in sorted({s.pressure_kpa for s in scanned}))
    out: list[dict[str, Any]] = []
    for spec, extra in further:
        after = directions(normal + extra, found.sigma, found.names, found.spans, found.points)
        gained = [n for n, k in zip(found.names, determined(after) & ~now, strict=True) if k]
        error = float(after.errors().max())
        if any(s.design == spec.design for s in scanned):
            reason = (f"the scans at {pressures} kPa cannot tell {confounded} apart: a scan of design "
                      f"{spec.design} again at {spec.pressure_kpa:g} kPa")
        else:
            reason = (f"the designs scanned ({', '.join(sorted({s.design for s in scanned}))}) cannot tell "
                      f"{confounded} apart: a scan of design {spec.design}, which bends differently, at "
                      f"{spec.pressure_kpa:g} kPa")
        effect = (f"would identify {' and '.join(gained)}" if gained else
                  f"would not identify {confounded} either")
        out.append({"design": spec.design, "pressure_kpa": spec.pressure_kpa, "determines": gained,
                    "smallest_eigenvalue": float(after.eigenvalues[0]), "weakest_error": error,
                    "why": f"{reason} {effect} (the weakest combination's standard error {weakest:.2g} -> "
                           f"{error:.2g} plausible changes)"})
    out.sort(key=lambda r: (-len(r["determines"]), -r["smallest_eigenvalue"]))
    return out


__all__ = ["MAX_CANDIDATES", "PRESSURE_FRACTION", "candidate_normal", "candidates", "determined", "rank"]

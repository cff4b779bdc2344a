"""A chain table's pressure levels: how far a failed solve got, its first levels, a source for fewer levels.

A table is fitted to responses of one ramp (levels ``p_1 < ... < p_k``, equal steps). A
training or held-out design that does not converge to the top pressure still reports the
levels it reached (:class:`~pneumorph.execution.Outcome` keeps them, NaN after); a build then
fits the table to the levels every design reached (:func:`levels_reached`,
:func:`first_levels`), and the table's source describes the ramp of those levels
(:func:`ramp_source`: top pressure ``p_m``, ``m`` increments), the ramp a model remade with
:func:`~pneumorph.models.chain.sources.ramp_variant` has. The same source serves a table
restricted to fewer levels (:func:`~pneumorph.models.chain.sources.restrict_table`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from pneumorph.errors import ChainTableError
from pneumorph.io.provenance import digest
from pneumorph.models.response import Response

__all__ = ["first_levels", "levels_reached", "ramp_source"]


def levels_reached(response: Response | None) -> int:
    """How many levels of ``response``, from the first, are solved (every centre, the tip and the curl finite).

    >>> import numpy as np
    >>> r = Response.empty("01", np.array([0.01, 0.02, 0.03]), np.zeros((2, 2)), np.zeros(2))
    >>> r.centres[0] = r.tip[0] = 1.0; r.curl[0] = 5.0
    >>> levels_reached(r), levels_reached(None)
    (1, 0)
    """
    if response is None:
        return 0
    ok = (np.isfinite(response.centres).all(axis=(1, 2)) & np.isfinite(response.tip).all(axis=1)
          & np.isfinite(response.curl))
    return int(np.argmin(ok)) if not ok.all() else len(ok)


def first_levels(response: Response, levels: int) -> Response:
    """``response`` as if its ramp ended at its ``levels``-th level: a converged response of those levels.

    Raises
    ------
    ChainTableError
        ``levels`` is not 1 up to the levels the response reached.

    Examples
    --------
    >>> import numpy as np
    >>> r = Response.empty("0", np.array([0.01, 0.02]), np.zeros((1, 2)), np.zeros(2), converged=False)
    >>> r.centres[0] = r.tip[0] = 1.0; r.curl[0] = 5.0
    >>> cut = first_levels(r, 1)
    >>> cut.n_levels, cut.converged, cut.reached
    (1, True, 0.01)
    """
    m, have = int(levels), levels_reached(response)
    if not 1 <= m <= have:
        raise ChainTableError(f"design {response.orientation} reached {have} level(s); {levels!r} asked for")
    if m == response.n_levels and response.converged:
        return response
    cut: dict[str, Any] = {name: None if getattr(response, name) is None else getattr(response, name)[:m].copy()
                           for name in ("pressures", "centres", "tip", "curl", "frames", "end_frame")}
    return replace(response, **cut, converged=True, reached=float(response.pressures[m - 1]), failure=None)


def ramp_source(source: dict[str, Any], pressures: np.ndarray, levels: int, **extra: Any) -> dict[str, Any]:
    """A table's ``source`` for the ramp of its first ``levels`` levels (of ``pressures``, MPa).

    The description's top pressure becomes the last kept level and its increments ``levels``,
    every other setting kept; the key and the training model's fingerprint are hashed again,
    so that :func:`~pneumorph.models.chain.model.check_source` accepts it for the model remade
    with that ramp. ``extra`` entries (e.g. ``restricted_from``, ``cut_from``) are added.

    Raises
    ------
    ChainTableError
        A source without its model's description (the model of fewer levels cannot be named).

    Examples
    --------
    >>> desc = {"pressure_mpa": 0.045, "steps": {"increments": 10}}
    >>> out = ramp_source({"key": digest(desc), "description": desc}, np.linspace(0.0045, 0.045, 10), 8)
    >>> out["description"]["pressure_mpa"], out["description"]["steps"]["increments"], out["key"] == digest(desc)
    (0.036, 8, False)
    """
    desc = source.get("description")
    if not (isinstance(desc, dict) and "pressure_mpa" in desc and isinstance(desc.get("steps"), dict)
            and digest(desc) == source.get("key")):
        raise ChainTableError("the chain table does not hold its model's description (source.description), so "
                              "the model of a restriction to fewer levels cannot be named; rebuild it with "
                              "`pneumorph chain build`")
    m = int(levels)
    description = {**desc, "pressure_mpa": round(float(pressures[m - 1]), 12),
                   "steps": {**desc["steps"], "increments": m}}
    out: dict[str, Any] = {**source, "key": digest(description), "description": description, **extra}
    if "n_units" in source:  # the training model's fingerprint: its description with its units
        out["fingerprint"] = digest({**description, "n_units": source["n_units"]})
    return out

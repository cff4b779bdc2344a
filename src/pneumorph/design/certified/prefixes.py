"""The prefix tree of a chain model's designs: chords placed unit by unit over shared prefixes.

Designs grow unit by unit (every prefix extended by each unit code the table allows). A prefix
of ``p`` units fixes the chords whose windows it covers, hence the first centres; so all
designs are scored at about two chord placements each, and a search can drop a prefix with
all its designs (:mod:`pneumorph.design.certified.search`). :func:`chain_geometry` keeps every
prefix's centres for later queries of the same chain model.
"""

from __future__ import annotations

import threading
import weakref
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.models.chain.model import ChainModel, window_codes

FloatArray = NDArray[np.float64]


def seed_prefixes(chain: ChainModel, polar: bool = False) -> tuple[NDArray[np.uint8], dict[str, Any]]:
    """The one-unit prefixes (2; ``2k`` over ``k`` types) and their state: base point, angle (polar angle, radius)."""
    k, c = chain.table.n_levels, len(chain.table.unit_codes)
    bits = chain.table.unit_codes[:, None].copy()
    st: dict[str, Any] = {"point": np.zeros((c, k, 2)), "angle": np.zeros((c, k))}
    st["point"][..., 1] = chain.table.heights[bits[:, 0]][:, None]
    if polar:
        st.update(theta=np.zeros((c, k)), r=np.zeros((c, k)))
    return bits, st


def grow(bits: NDArray[np.uint8], st: dict[str, Any], codes: NDArray[np.uint8]) -> tuple[NDArray[np.uint8],
                                                                                        dict[str, Any]]:
    """Every prefix extended by each of the unit ``codes`` (child ``c i + b`` of prefix ``i``: code ``codes[b]``)."""
    c = len(codes)
    bits = np.concatenate([np.repeat(bits, c, axis=0), np.tile(codes[:, None], (len(bits), 1))], axis=1)
    return bits, {key: np.repeat(v, c, axis=0) for key, v in st.items()}


def place_chords(chain: ChainModel, bits: NDArray[np.uint8], st: dict[str, Any], placed: int, upto: int,
                  polar: bool = False) -> Any:
    """Place chords ``placed .. upto - 1`` of every prefix (their windows are covered), updating ``st``.

    Yields ``(j, x, y)`` after chord ``j`` with the centre ``j + 1`` it fixes (heights above
    the undeformed axis), for ``j + 1 <= n``; with ``polar``, ``st["theta"]`` (unwrapped)
    and ``st["r"]`` of that centre too.
    """
    table = chain.table
    n, w = chain.n_units, table.window
    if upto <= placed:
        return
    cy = table.heights
    codes = window_codes(bits, w, range(placed, upto), n_types=table.n_types)
    for j in range(placed, upto):
        rows = table.lookup(codes[:, j - placed])
        st["angle"] = st["angle"] + table.turn[rows]
        step = table.length[rows]
        st["point"] = st["point"] + np.stack([step * np.cos(st["angle"]), step * np.sin(st["angle"])], -1)
        if j + 1 <= n:  # centre j + 1 is now known
            x = st["point"][..., 0]
            y = st["point"][..., 1] - cy[bits[:, j]][:, None]
            if polar:
                raw = np.arctan2(y, x)
                st["theta"] = raw if j == 0 else st["theta"] + (raw - st["theta"] + np.pi) % (2 * np.pi) - np.pi
                st["r"] = np.hypot(x, y)
            yield j, x, y


def depths(chain: ChainModel, bits: NDArray[np.uint8], st: dict[str, Any], polar: bool = False,
           place: Any = None, codes: NDArray[np.uint8] | None = None) -> Any:
    """Grow the prefixes unit by unit: yields ``(p, placed, bits, st, centres)`` at every depth ``p``.

    ``centres`` iterates over the chords placed at this depth (:func:`place_chords`, or
    ``place(chain, bits, st, placed, upto)``: a chain in space,
    :mod:`pneumorph.design.certified.spacegrowth`); the caller consumes it, and may then ``send`` back
    pruned ``(bits, st)`` for the next depth. ``codes``: the unit codes a prefix grows by (default every
    code of the table).
    """
    n, w = chain.n_units, chain.table.window
    placed = 0
    for p in range(1, n + 1):
        if p > 1:
            bits, st = grow(bits, st, chain.table.unit_codes if codes is None else codes)
        upto = n + 1 if p == n else max(p - w + 1, 0)
        centres = place_chords(chain, bits, st, placed, upto, polar) if place is None else \
            place(chain, bits, st, placed, upto)
        pruned = yield p, max(placed, upto), bits, st, centres
        placed = max(placed, upto)
        if pruned is not None:
            bits, st = pruned
            yield None  # the value of ``send``


def tip_and_curl(chain: ChainModel, bits: NDArray[np.uint8], st: dict[str, Any]) -> tuple[FloatArray, FloatArray]:
    """Tip point and curl (degrees) of whole designs from their final state."""
    table = chain.table
    erows = table.lookup(window_codes(bits, table.window, [chain.n_units], n_types=table.n_types)[:, 0], end=True)
    return st["point"], np.degrees(st["angle"] + table.end[erows])


@dataclass(frozen=True)
class ChainGeometry:
    """The centres, tip and curl of every design of a chain model, by prefix depth.

    Centre ``j`` is fixed once the prefix covers its windows, at depth ``depth[j]`` (then
    ``c**depth[j]`` prefixes, ``c`` = 2 choices per unit, ``2k`` over ``k`` unit types);
    ``x[j]``, ``y[j]`` (and ``theta[j]``, ``r[j]``) hold it for every prefix at every level,
    so an objective is evaluated once per prefix, not per design. ``tip`` and ``curl`` are
    those of all ``c**n`` designs, in the order of :attr:`bits` (the first unit most
    significant).
    """

    bits: NDArray[np.uint8]
    depth: tuple[int, ...]
    x: tuple[FloatArray, ...]
    y: tuple[FloatArray, ...]
    theta: tuple[FloatArray, ...]
    r: tuple[FloatArray, ...]
    tip: FloatArray
    curl: FloatArray


_GEOMETRY: weakref.WeakKeyDictionary[ChainModel, ChainGeometry] = weakref.WeakKeyDictionary()
_GEOMETRY_LOCK = threading.Lock()


def chain_geometry(chain: ChainModel) -> ChainGeometry:
    """Every design's centres, tip and curl, grown over shared prefixes (kept per chain model).

    Memory: four arrays of about ``(w + 1) 2^n k`` numbers for window ``w`` (15 units,
    window 3, 10 levels: about 50 MB); :func:`grow_designs` keeps it up to
    :data:`~pneumorph.design.certified.search.KEEP_GEOMETRY_UNITS` units.

    Examples
    --------
    >>> from pneumorph.models.chain.sources import find_table
    >>> from pneumorph.models.factory import make_model
    >>> chain = ChainModel(find_table(make_model(5, {"fidelity": "2d"})), 5)
    >>> g = chain_geometry(chain)
    >>> g.bits.shape, len(g.depth), g.tip.shape, chain_geometry(chain) is g
    ((32, 5), 5, (32, 10, 2), True)
    """
    with _GEOMETRY_LOCK:
        hit = _GEOMETRY.get(chain)
    if hit is not None:
        return hit
    depth: list[int] = []
    xs: list[FloatArray] = []
    ys: list[FloatArray] = []
    ths: list[FloatArray] = []
    rs: list[FloatArray] = []
    with np.errstate(all="ignore"):
        # the last depth's designs and state are the complete designs' (used after the loop)
        for p, _, bits, st, centres in depths(chain, *seed_prefixes(chain, polar=True), polar=True):  # noqa: B007
            for _, x, y in centres:
                depth.append(p)
                xs.append(x)
                ys.append(y)
                ths.append(st["theta"])
                rs.append(st["r"])
        tip, curl = tip_and_curl(chain, bits, st)
    geom = ChainGeometry(bits, tuple(depth), tuple(xs), tuple(ys), tuple(ths), tuple(rs), tip, curl)
    with _GEOMETRY_LOCK:
        _GEOMETRY[chain] = geom
    return geom


__all__ = ["ChainGeometry", "chain_geometry", "depths", "grow", "place_chords", "seed_prefixes", "tip_and_curl"]

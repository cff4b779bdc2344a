"""What the units still to place can do: the reachable set of a chain's remaining chords.

A prefix of ``p`` units fixes the chords whose windows it covers, hence a point ``P`` (the
centre where the next chord starts) and a heading ``a`` at every level. The chords still to
place move every later centre, and the tip, by a displacement ``D`` (in the frame of the
heading ``a``) that depends on the units still to choose. This module computes, once per
chain table, an outer bound of the set of such displacements, as *support functions*: for a
direction ``u`` (angle ``phi`` in that frame), ``h(phi) = max_D u . D``. The set of
displacements after ``a`` more units lies in ``{x : u . x <= h(phi) for every phi}``, its
convex hull.

The support function of the displacements follows the chain backwards, one unit at a time
(a dynamic programme over the window state). The next chord of window ``W`` turns by
``t_W`` and has length ``L_W``; in the frame after it the rest is again a chain, rotated by
``t_W``. So, with ``s`` the state (the last units placed) and ``s'`` the state after ``W``,

    h_a(s, phi) = max over W following s of [ L_W cos(phi - t_W) + h_{a-1}(s', phi - t_W) ].

For the centres, ``h_0 = 0``; for the tip, ``h_0(s)`` is the displacement of the last ``w``
chords, whose windows hold the tip symbol and no choice; the curl is a scalar version (the
greatest summed turn plus the end turn). The state is the last ``memory`` units; with fewer
than the ``2 w`` that the next window sees, the maximum also runs over the units forgotten,
which only widens the set (a relaxation, still an outer bound).

Directions are a grid of ``N`` angles ``delta`` apart. Between two grid directions
``phi_1 < phi < phi_2`` the support is at most that of the wedge of the two half-planes,

    h(phi) <= [h(phi_1) sin(phi_2 - phi) + h(phi_2) sin(phi - phi_1)] / sin(delta),

because ``u`` is a non-negative combination of ``u_1`` and ``u_2``. Every shifted function
in the recursion and every query reads the grid through this inequality, so each value is an
upper bound of the true support (never below it: the bound is *admissible*; it is loose by
about ``R delta^2 / 8`` per step for a set of radius ``R``). Values are kept in float32,
rounded up.

From the support in the four axis directions follows a box holding a centre or the tip; a
profile target's term at that centre is at least the gap between the box's heights and the
target's heights over the box's x range (:class:`CurveRange`), and a tip goal's value is at
least the box's, or the distance from a point to the hull (:func:`tip_goal_bound`).

Examples
--------
>>> import numpy as np
>>> from pneumorph.models.chain import ChainModel
>>> from pneumorph.models.chaintables import find_table
>>> from pneumorph.models.factory import make_model
>>> chain = ChainModel(find_table(make_model(15, {"fidelity": "2d"})), 15)
>>> r = reach_of(chain, "centre")
>>> r.memory, r.directions, len(r.centre), len(r.tip)
(4, 360, 16, 0)
"""

from __future__ import annotations

import threading
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.targets import Objective, TipGoal
from pneumorph.models.chain import ChainModel, ChainTable
from pneumorph.models.windows import ends

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: angles of the direction grid of the support functions
DIRECTIONS = 360
#: most states (``(2k)^memory``) the programme keeps per step
MAX_STATES = 128
#: centres ahead of a prefix whose terms the profile bound adds
AHEAD = 6
#: what a kept float32 value may lie below the float64 it rounds (mm): added back at every query
_ROUND = 1e-4
_EMPTY = -1e30


def memory_of(table: ChainTable, max_states: int = MAX_STATES) -> int:
    """Units of the state: the most, up to the ``2 w`` the next window sees, with at most ``max_states`` states.

    >>> from pneumorph.models.chaintables import find_table
    >>> from pneumorph.models.factory import make_model
    >>> memory_of(find_table(make_model(15, {"fidelity": "3d"})))
    6
    """
    c = 2 * table.n_types
    m = 2 * table.window
    while m > 1 and c**m > max_states:
        m -= 1
    return m


def _digits(codes: IntArray, base: int, count: int) -> IntArray:
    """Digits of window codes, least significant (the first unit) first: shape (len, count)."""
    return (np.asarray(codes, dtype=np.int64)[:, None] // base ** np.arange(count)[None, :]) % base


def _state_code(digits: IntArray, c: int) -> IntArray:
    """A state (unit codes, the first least significant) as one integer in base ``c``."""
    return (digits * c ** np.arange(digits.shape[1])[None, :]).sum(axis=1) if digits.shape[1] else \
        np.zeros(len(digits), dtype=np.int64)


def _wedge(values: NDArray[np.floating], phi: FloatArray, delta: float) -> tuple[IntArray, FloatArray, FloatArray]:
    """Grid index and the two weights of the wedge bound for angles ``phi``."""
    t = phi / delta
    j = np.floor(t)
    f = t - j
    s = np.sin(delta)
    return j.astype(np.int64) % values.shape[-1], np.sin((1.0 - f) * delta) / s, np.sin(f * delta) / s


@dataclass(frozen=True)
class Reach:
    """Support functions of the displacements the units still to place can make.

    Attributes
    ----------
    memory : int
        Units in a state (the last ones placed).
    choices : int
        Unit codes (``2k``).
    directions : int
        Angles of the direction grid (``delta = 2 pi / directions``).
    centre : tuple of ndarray, shape (S, k, N) each
        ``centre[a]``: support of the displacement of ``a`` more unit chords (to the centre
        where the ``a``-th ends), per state, level and direction.
    tip : tuple of ndarray, shape (S, k, N) each
        ``tip[a]``: support of the displacement to the tip when ``a`` units remain.
    turn : ndarray, shape (A + 1, S, k)
        ``turn[a]``: the greatest summed turn to the tip's end face (the end turn included)
        when ``a`` units remain (rad).
    """

    memory: int
    choices: int
    directions: int
    centre: tuple[NDArray[np.float32], ...]
    tip: tuple[NDArray[np.float32], ...]
    turn: FloatArray

    @property
    def delta(self) -> float:
        return 2 * np.pi / self.directions

    def state(self, bits: NDArray[np.integer]) -> IntArray:
        """The state of prefixes (m, p), ``p >= memory``: their last ``memory`` units."""
        last = np.asarray(bits, dtype=np.int64)[:, bits.shape[1] - self.memory:]
        return _state_code(last, self.choices)

    def support(self, which: str, a: int, state: IntArray, phi: FloatArray, fan: int = 1) -> FloatArray:
        """Upper bound of the support in the directions ``phi`` (m, k) of the frame, per prefix and level.

        With ``fan > 1``, in the ``fan`` directions ``phi + 2 pi i / fan`` at once: shape (fan, m, k)
        (``fan`` must divide the grid's angles; the wedge's weights are shared).
        """
        values = (self.centre if which == "centre" else self.tip)[a]
        n = values.shape[-1]
        j, wa, wb = _wedge(values, phi, self.delta)
        lev = np.arange(values.shape[1])[None, :]
        s = state[:, None]
        out = []
        for i in range(fan):
            ji = (j + i * (n // fan)) % n
            h1 = values[s, lev, ji].astype(np.float64)
            h2 = values[s, lev, (ji + 1) % n].astype(np.float64)
            v = wa * h1 + wb * h2 + _ROUND
            out.append(np.where((h1 <= _EMPTY / 2) | (h2 <= _EMPTY / 2), _EMPTY, v))
        return out[0] if fan == 1 else np.stack(out)

    def box(self, which: str, a: int, state: IntArray, point: FloatArray, heading: FloatArray
            ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """A box ``(x_lo, x_hi, y_lo, y_hi)`` (m, k) holding every end point of the remaining chords."""
        x, y = point[..., 0], point[..., 1]
        east, north, west, south = self.support(which, a, state, -heading, fan=4)
        return x - west, x + east, y - south, y + north


def _shifted(prev: NDArray[np.float64], rows_next: IntArray, turn: FloatArray, delta: float) -> FloatArray:
    """``prev[s'](phi - t)`` on the grid, bounded from above by the wedge, per window row: (R, k, N).

    ``phi_j - t`` lies ``-t / delta`` cells from grid angle ``j`` for every ``j``: one shift and one pair of
    weights per row and level.
    """
    n = prev.shape[-1]
    start, wa, wb = _wedge(prev, -turn, delta)
    doubled = np.concatenate([prev, prev[..., :1 + n]], axis=-1)  # (S, k, 2n + 1): any run of n + 1 is a slice
    runs = np.lib.stride_tricks.sliding_window_view(doubled, n + 1, axis=-1)  # (S, k, n + 1, n + 1)
    block = runs[rows_next[:, None], np.arange(prev.shape[1])[None, :], start]  # (R, k, n + 1)
    src, nxt = block[..., :n], block[..., 1:]
    out = wa[:, :, None] * src + wb[:, :, None] * nxt
    return np.where((src <= _EMPTY / 2) | (nxt <= _EMPTY / 2), _EMPTY, out)


def _reduce(values: FloatArray, state: IntArray, n_states: int) -> FloatArray:
    """Greatest value per state: rows grouped by ``state``; ``_EMPTY`` where a state has none."""
    out = np.full((n_states, *values.shape[1:]), _EMPTY)
    order = np.argsort(state, kind="stable")
    s = state[order]
    starts = np.flatnonzero(np.r_[True, s[1:] != s[:-1]])
    if len(order):
        out[s[starts]] = np.maximum.reduceat(values[order], starts, axis=0)
    return out


def _round_up(values: FloatArray) -> NDArray[np.float32]:
    """float32 values no smaller than ``values`` (up to :data:`_ROUND`)."""
    out = values.astype(np.float32)
    return np.where(out < values, np.nextafter(out, np.float32(np.inf)), out).astype(np.float32)


def build_reach(table: ChainTable, units: int, memory: int | None = None, directions: int = DIRECTIONS,
                families: tuple[str, ...] = ("centre", "tip")) -> Reach:
    """The support functions of a table for up to ``units`` units still to place.

    Parameters
    ----------
    table : ChainTable
    units : int
        The most units that can remain (the actuator's length).
    memory : int, optional
        Units of the state (default :func:`memory_of`).
    directions : int
        Angles of the direction grid.
    families : tuple of str
        Which to compute: ``"centre"`` (profile targets) and/or ``"tip"`` (tip goals, with the
        curl); the other is left empty.
    """
    w, k = table.window, table.n_types
    c = 2 * k
    b = c + 2
    tip_sym = ends(k)[1]
    m = memory_of(table) if memory is None else int(memory)
    if not 1 <= m <= 2 * w:
        raise ValueError(f"the state holds 1 to {2 * w} units, got {m}")
    n_states = c**m
    delta = 2 * np.pi / directions
    grid = np.arange(directions) * delta
    digits = _digits(table.codes, b, 2 * w + 1)
    unit = (digits < c).all(axis=1)
    ud = digits[unit]
    before = _state_code(ud[:, 2 * w - m: 2 * w], c)
    after = _state_code(ud[:, 2 * w - m + 1:], c)
    t_u, l_u = table.turn[unit], table.length[unit]
    step = l_u[:, :, None] * np.cos(grid[None, None, :] - t_u[:, :, None])  # (R, k, N)
    kl = table.n_levels
    seqs: dict[str, list[FloatArray]] = {}
    turn: list[FloatArray] = []
    if "centre" in families:
        seqs["centre"] = [np.zeros((n_states, kl, directions))]
    if "tip" in families:
        # the last w chords (tip windows, no choice): displacement and summed turn per full state
        full = np.unique(table.codes[unit] % b ** (2 * w))
        disp = np.zeros((len(full), kl, 2))
        angle = np.zeros((len(full), kl))
        ok = np.ones(len(full), dtype=bool)
        window = full.copy()
        last = window
        for _ in range(w):
            window = window + tip_sym * b ** (2 * w)
            rows, found = table.find(window)
            ok &= found
            angle = angle + table.turn[rows]
            disp += table.length[rows][..., None] * np.stack([np.cos(angle), np.sin(angle)], -1)
            last = window
            window = window // b
        erows, found = table.find(last, end=True)
        ok &= found
        angle = angle + table.end[erows]
        fstate = _state_code(_digits(full, b, 2 * w)[:, 2 * w - m:], c)
        tip0 = disp[..., 0][..., None] * np.cos(grid) + disp[..., 1][..., None] * np.sin(grid)
        tip0[~ok] = _EMPTY
        seqs["tip"] = [_reduce(tip0, fstate, n_states)]
        turn = [_reduce(np.where(ok[:, None], angle, _EMPTY), fstate, n_states)]
    for _ in range(1, int(units) + 1):
        for seq in seqs.values():
            vals = step + _shifted(seq[-1], after, t_u, delta)
            seq.append(_reduce(np.where(vals <= _EMPTY / 2, _EMPTY, vals), before, n_states))
        if turn:
            nxt = t_u + turn[-1][after]
            turn.append(_reduce(np.where(turn[-1][after] <= _EMPTY / 2, _EMPTY, nxt), before, n_states))
    return Reach(m, c, directions, tuple(_round_up(v) for v in seqs.get("centre", [])),
                 tuple(_round_up(v) for v in seqs.get("tip", [])), np.asarray(turn))


_REACH: weakref.WeakKeyDictionary[ChainModel, dict[str, Reach]] = weakref.WeakKeyDictionary()
_LOCK = threading.Lock()


def reach_of(chain: ChainModel, family: str) -> Reach:
    """The :class:`Reach` of a chain model's table for its number of units, one family (kept per chain model).

    ``family``: ``"centre"`` for profile targets, ``"tip"`` for tip goals.
    """
    with _LOCK:
        hit = _REACH.get(chain, {}).get(family)
    if hit is not None:
        return hit
    out = build_reach(chain.table, chain.n_units, families=(family,))
    with _LOCK:
        _REACH.setdefault(chain, {})[family] = out
    return out


@dataclass(frozen=True)
class CurveRange:
    """Least and greatest value of ``y = f(x)`` over x intervals, from a fine grid and the slope.

    A sparse table of the grid's minima and maxima over runs of ``2^i`` points answers an
    interval in two look-ups; ``slope * step / 2`` covers the curve between grid points.
    """

    lo: float
    step: float
    slack: float
    mins: tuple[FloatArray, ...]
    maxs: tuple[FloatArray, ...]

    @classmethod
    def of(cls, f: Callable[[FloatArray], FloatArray], lo: float, hi: float, slope: float,
           step: float = 0.05) -> CurveRange:
        x = np.arange(lo, hi + step, step)
        with np.errstate(all="ignore"):
            v = np.asarray(f(x), dtype=float)
        v = np.broadcast_to(v, x.shape)
        mins = [np.where(np.isfinite(v), v, -np.inf)]
        maxs = [np.where(np.isfinite(v), v, np.inf)]
        span = 1
        while 2 * span <= len(x):
            mins.append(np.minimum(mins[-1][:-span], mins[-1][span:]))
            maxs.append(np.maximum(maxs[-1][:-span], maxs[-1][span:]))
            span *= 2
        return cls(float(lo), float(step), float(slope) * step / 2 + 1e-9, tuple(mins), tuple(maxs))

    def between(self, x_lo: FloatArray, x_hi: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Least and greatest ``f`` over ``[x_lo, x_hi]`` (arrays of one shape), widened by the slack."""
        size = len(self.mins[0])
        i = np.clip(np.floor((x_lo - self.lo) / self.step), 0, size - 1).astype(np.int64)
        j = np.clip(np.ceil((x_hi - self.lo) / self.step), 0, size - 1).astype(np.int64)
        j = np.maximum(i, j)
        level = np.floor(np.log2(j - i + 1)).astype(np.int64)
        lo = np.full(i.shape, np.inf)
        hi = np.full(i.shape, -np.inf)
        for lv in np.unique(level):
            sel = level == lv
            span = 1 << int(lv)
            a, z = i[sel], j[sel] - span + 1
            lo[sel] = np.minimum(self.mins[lv][a], self.mins[lv][z])
            hi[sel] = np.maximum(self.maxs[lv][a], self.maxs[lv][z])
        return lo - self.slack, hi + self.slack


def profile_rest(reach: Reach, heights: FloatArray, curve: CurveRange, bits: NDArray[np.integer],
                 point: FloatArray, heading: FloatArray, placed: int, n_units: int, window: int) -> FloatArray:
    """A lower bound on the summed squared Eq 4.1 terms of the centres the prefixes have not fixed, (m, k).

    Centre ``i`` (``placed < i <= n - w + 1``: its chords see no tip) lies in the box of the
    ``i - placed`` chords from the prefixes' point; its term ``f(x) - (y - y_ref)`` is at least
    the gap between the box's heights (less the unit's undeformed centre height, known for the
    prefix's units, else its least and greatest) and the target's values over the box's x
    range. The last ``w - 1`` centres add nothing, nor do those more than :data:`AHEAD` chords
    ahead (their boxes are wide: they would cost more than they add).
    """
    state = reach.state(bits)
    p = bits.shape[1]
    total = np.zeros(heading.shape)
    h_lo, h_hi = float(np.min(heights)), float(np.max(heights))
    for i in range(placed + 1, min(n_units - window + 2, placed + 1 + AHEAD)):
        x_lo, x_hi, y_lo, y_hi = reach.box("centre", i - placed, state, point, heading)
        lo_ref: FloatArray | float = h_lo
        hi_ref: FloatArray | float = h_hi
        if i <= p:
            lo_ref = hi_ref = heights[np.asarray(bits[:, i - 1], dtype=np.int64)][:, None]
        f_lo, f_hi = curve.between(x_lo, x_hi)
        gap = np.maximum(np.maximum(f_lo - (y_hi - lo_ref), (y_lo - hi_ref) - f_hi), 0.0)
        total += np.where(y_lo <= _EMPTY / 2, 0.0, gap * gap)
    return total


#: directions in which the distance from a point to the tip's hull is bounded
_DISTANCE_DIRECTIONS = 8


def tip_goal_rest(reach: Reach, name: str, target: tuple[float, float] | None, tip_height: float,
                  bits: NDArray[np.integer], point: FloatArray, heading: FloatArray, n_units: int) -> FloatArray:
    """A lower bound on a tip goal's cost (its value; minus it when maximising) of every completion, (m, k).

    The tip lies in the hull of the displacements of the chords still to place; the bound is
    the hull's best x or y, its distance from the base or a point (at least ``u . (P - q) -
    h(-u)`` for every unit vector ``u``), or the curl with the greatest remaining turn.
    """
    state = reach.state(bits)
    a = n_units - bits.shape[1]
    if name == "max-curl":
        turn = reach.turn[a][state]
        return np.where(turn <= _EMPTY / 2, np.inf, -np.degrees(heading + turn) - 1e-9)
    x, y = point[..., 0], point[..., 1] - tip_height
    if name in ("max-x", "min-x", "max-y", "min-y"):
        phi = {"max-x": 0.0, "min-x": np.pi, "max-y": np.pi / 2, "min-y": -np.pi / 2}[name]
        h = reach.support("tip", a, state, phi - heading)
        if name == "max-x":
            out = -(x + h)
        elif name == "min-x":
            out = x - h
        elif name == "max-y":
            out = -(y + h)
        else:
            out = y - h
        return np.where(h <= _EMPTY / 2, np.inf, out)
    q = (0.0, 0.0) if name == "min-distance" else target
    assert q is not None
    best = np.zeros(heading.shape)
    toward = np.arctan2(y - q[1], x - q[0])  # from the point to the prefix's point, then a fan around it
    h = reach.support("tip", a, state, toward + np.pi - heading, fan=_DISTANCE_DIRECTIONS)
    for i in range(_DISTANCE_DIRECTIONS):
        psi = toward + 2 * np.pi * i / _DISTANCE_DIRECTIONS
        lb = np.cos(psi) * (x - q[0]) + np.sin(psi) * (y - q[1]) - h[i]
        best = np.maximum(best, np.where(h[i] <= _EMPTY / 2, np.inf, lb))
    return best


# -- the cruder bound of the first units: a box from the chords' heading intervals ----------
def _contains(lo: FloatArray, hi: FloatArray, phase: float) -> NDArray[np.bool_]:
    """True where [lo, hi] contains ``phase + 2 pi m`` for some integer m."""
    return 2 * np.pi * np.ceil((lo - phase) / (2 * np.pi)) + phase <= hi


def _cos_range(lo: FloatArray, hi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Least and greatest cosine over the angle intervals [lo, hi]."""
    c_lo, c_hi = np.cos(lo), np.cos(hi)
    top = np.where(_contains(lo, hi, 0.0), 1.0, np.maximum(c_lo, c_hi))
    bottom = np.where(_contains(lo, hi, np.pi), -1.0, np.minimum(c_lo, c_hi))
    return bottom, top


def _sin_range(lo: FloatArray, hi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Least and greatest sine over the angle intervals [lo, hi]."""
    s_lo, s_hi = np.sin(lo), np.sin(hi)
    top = np.where(_contains(lo, hi, np.pi / 2), 1.0, np.maximum(s_lo, s_hi))
    bottom = np.where(_contains(lo, hi, -np.pi / 2), -1.0, np.minimum(s_lo, s_hi))
    return bottom, top


def _reach_box(table: Any, state: dict[str, Any], remaining: int, axes: str = "xy") -> tuple[FloatArray, ...]:
    """A box (per prefix and level) holding every tip its remaining chords can reach.

    Chord ``i`` of the remaining ones turns by ``i`` tabulated turns at most, so its angle
    lies in ``[a + i t_min, a + i t_max]``; its length in ``[L_min, L_max]``. Only the
    ``axes`` asked for are bounded (the others stay at the current point).
    """
    tmin, tmax = table.turn.min(axis=0), table.turn.max(axis=0)
    lmin, lmax = table.length.min(axis=0), table.length.max(axis=0)
    a = state["angle"]
    x, y = state["point"][..., 0], state["point"][..., 1]
    xlo, xhi, ylo, yhi = x.copy(), x.copy(), y.copy(), y.copy()
    for i in range(1, remaining + 1):
        lo, hi = a + i * tmin, a + i * tmax
        if "x" in axes:
            cmin, cmax = _cos_range(lo, hi)
            xhi += np.where(cmax >= 0, lmax * cmax, lmin * cmax)
            xlo += np.where(cmin <= 0, lmax * cmin, lmin * cmin)
        if "y" in axes:
            smin, smax = _sin_range(lo, hi)
            yhi += np.where(smax >= 0, lmax * smax, lmin * smax)
            ylo += np.where(smin <= 0, lmax * smin, lmin * smin)
    return xlo, xhi, ylo, yhi


def box_bound(chain: ChainModel, objective: Objective, state: dict[str, Any], remaining: int) -> FloatArray:
    """Per level, a lower bound on the cost of every completion from the chords' heading intervals (m, k)."""
    table = chain.table
    name = objective.name
    if name == "max-curl":  # the rest of the turns and the end turn at their largest
        turns = np.degrees(remaining * table.turn.max(axis=0) + table.end.max(axis=0))
        return -(np.degrees(state["angle"]) + turns)
    axes = {"max-x": "x", "min-x": "x", "max-y": "y", "min-y": "y"}.get(name, "xy")
    xlo, xhi, ylo, yhi = _reach_box(table, state, remaining, axes)
    ylo, yhi = ylo - table.tip_ref[1], yhi - table.tip_ref[1]
    if name == "max-x":
        return -xhi
    if name == "min-x":
        return xlo
    if name == "max-y":
        return -yhi
    if name == "min-y":
        return ylo
    # distance to the base or to a point: from the point to the box
    q = (0.0, 0.0) if name == "min-distance" else cast(TipGoal, objective).point
    assert q is not None
    dx = np.maximum(np.maximum(xlo - q[0], q[0] - xhi), 0.0)
    dy = np.maximum(np.maximum(ylo - q[1], q[1] - yhi), 0.0)
    return np.hypot(dx, dy)


__all__ = ["DIRECTIONS", "CurveRange", "Reach", "box_bound", "build_reach", "memory_of", "profile_rest", "reach_of",
           "tip_goal_rest"]

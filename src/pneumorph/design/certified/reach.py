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
rounded up. The programme runs level by level; each level's step is prepared once
(:class:`_Kernel`: the shifted grid indices and weights of every window), so a step is two
gathers, a sum and a grouped maximum.

A table of many windows (four unit types at window +-3: 823,543 windows of units) would
need ``windows x levels x N`` values per step. Past :data:`MAX_ROWS` windows per level, the
windows of one state pair whose turns fall in one bin of width ``eps`` are merged into a
*cluster*, read at its middle turn ``t_c`` and mean length and widened so that it still
bounds each of its windows from above: ``L cos(phi - t) <= L_c cos(phi - t_c) + dL + L eps / 2``
and ``h(phi - t) <= h(phi - t_c) + R eps / 2``, since a support function moves by at most
the set's greatest norm ``R`` per radian (``R <= max h / cos(delta / 2)`` on the grid). The
bound stays admissible and is looser by about ``R eps / 2`` per step.

From the support in the four axis directions follows a box holding a centre or the tip;
:mod:`pneumorph.design.certified.remainder` turns the boxes into bounds on a profile's or a tip goal's cost.

Examples
--------
>>> import numpy as np
>>> from pneumorph.models.chain.model import ChainModel
>>> from pneumorph.models.chain.sources import find_table
>>> from pneumorph.models.factory import make_model
>>> chain = ChainModel(find_table(make_model(15, {"fidelity": "2d"})), 15)
>>> r = reach_of(chain, "centre")
>>> r.memory, r.directions, len(r.centre), len(r.tip)
(4, 360, 7, 0)
"""

from __future__ import annotations

import threading
import weakref
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.windows import ends

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
#: the support of an empty set (no window leaves the state)
EMPTY = -1e30
#: most chord rows per level the programme steps over; a table with more windows merges those of
#: one state pair and close turns into clusters (:func:`_clusters`)
MAX_ROWS = 30_000
#: turn widths (rad) of the clusters, tried in order until the rows fit
CLUSTER_WIDTHS = (2.5e-4, 5e-4, 1e-3, 2e-3, 4e-3, 8e-3)
#: full states whose tip supports are formed at once
_CHUNK = 8192


def memory_of(table: ChainTable, max_states: int = MAX_STATES) -> int:
    """Units of the state: the most, up to the ``2 w`` the next window sees, with at most ``max_states`` states.

    >>> from pneumorph.models.chain.sources import find_table
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


def _wedge(n: int, phi: FloatArray, delta: float) -> tuple[IntArray, FloatArray, FloatArray]:
    """Grid index (of ``n`` angles ``delta`` apart) and the two weights of the wedge bound for angles ``phi``."""
    t = phi / delta
    j = np.floor(t)
    f = t - j
    s = np.sin(delta)
    return j.astype(np.int64) % n, np.sin((1.0 - f) * delta) / s, np.sin(f * delta) / s


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
        j, wa, wb = _wedge(n, phi, self.delta)
        lev = np.arange(values.shape[1])[None, :]
        s = state[:, None]
        out = []
        for i in range(fan):
            ji = (j + i * (n // fan)) % n
            h1 = values[s, lev, ji].astype(np.float64)
            h2 = values[s, lev, (ji + 1) % n].astype(np.float64)
            v = wa * h1 + wb * h2 + _ROUND
            out.append(np.where((h1 <= EMPTY / 2) | (h2 <= EMPTY / 2), EMPTY, v))
        return out[0] if fan == 1 else np.stack(out)

    def at_level(self, k: int) -> Reach:
        """The supports of level ``k`` alone (views): queries then take that level's points and headings, (m, 1)."""
        return replace(self, centre=tuple(v[:, k:k + 1] for v in self.centre),
                       tip=tuple(v[:, k:k + 1] for v in self.tip), turn=self.turn[:, :, k:k + 1])

    def box(self, which: str, a: int, state: IntArray, point: FloatArray, heading: FloatArray
            ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """A box ``(x_lo, x_hi, y_lo, y_hi)`` (m, k) holding every end point of the remaining chords."""
        x, y = point[..., 0], point[..., 1]
        east, north, west, south = self.support(which, a, state, -heading, fan=4)
        return x - west, x + east, y - south, y + north


def _reduce(values: FloatArray, state: IntArray, n_states: int) -> FloatArray:
    """Greatest value per state: rows grouped by ``state``; ``EMPTY`` where a state has none."""
    out = np.full((n_states, *values.shape[1:]), EMPTY)
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


@dataclass(frozen=True)
class _Rows:
    """The chords of one level the programme steps over: windows, or clusters of windows sharing a state.

    A cluster holds windows of one ``(before, after)`` state pair whose turns lie within
    ``turn +- half`` and lengths within ``length +- spread``; a single window has ``half`` and
    ``spread`` zero.
    """

    before: IntArray
    after: IntArray
    turn: FloatArray
    length: FloatArray
    half: FloatArray
    spread: FloatArray
    top: FloatArray  # the greatest turn of the cluster (the curl's bound)


def _clusters(pair: IntArray, before: IntArray, after: IntArray, turn: FloatArray, length: FloatArray,
              max_rows: int) -> _Rows:
    """The windows of one level as they are, or, past ``max_rows``, merged into clusters of close turns.

    The clusters are the windows of one state pair (``pair``) whose turns fall in one bin of
    width ``eps``, the first of :data:`CLUSTER_WIDTHS` that leaves at most ``max_rows`` rows.
    """
    if len(turn) <= max_rows:
        zero = np.zeros(len(turn))
        return _Rows(before, after, turn, length, zero, zero, turn)
    for eps in CLUSTER_WIDTHS:
        key = pair * 1_000_000 + np.floor(turn / eps).astype(np.int64)
        uniq, inverse = np.unique(key, return_inverse=True)
        if len(uniq) <= max_rows or eps == CLUSTER_WIDTHS[-1]:
            break
    n = len(uniq)
    t_lo, t_hi, l_lo, l_hi = np.full(n, np.inf), np.full(n, -np.inf), np.full(n, np.inf), np.full(n, -np.inf)
    np.minimum.at(t_lo, inverse, turn)
    np.maximum.at(t_hi, inverse, turn)
    np.minimum.at(l_lo, inverse, length)
    np.maximum.at(l_hi, inverse, length)
    first = np.zeros(n, dtype=np.int64)
    first[inverse[::-1]] = np.arange(len(turn))[::-1]
    return _Rows(before[first], after[first], (t_lo + t_hi) / 2, (l_lo + l_hi) / 2, (t_hi - t_lo) / 2,
                 (l_hi - l_lo) / 2, t_hi)


@dataclass(frozen=True)
class _Kernel:
    """One level's step of the programme, prepared once: ``h'(s) = max over rows of [base + shifted prev]``.

    ``base`` (R, N) is ``L cos(phi - t)`` with the cluster's widening; ``src`` and ``nxt``
    (R, N) index the flattened ``prev`` (S * N) at the two grid angles around ``phi - t``
    (state ``s'`` of the row), with the wedge's weights ``wa``, ``wb`` (R, 1). Rows are sorted
    by the state before them (``starts``, ``states``: the runs of one state).
    """

    base: FloatArray
    src: IntArray
    nxt: IntArray
    wa: FloatArray
    wb: FloatArray
    after: IntArray
    half: FloatArray
    starts: IntArray
    states: IntArray
    top: FloatArray
    delta: float

    @classmethod
    def of(cls, rows: _Rows, directions: int) -> _Kernel:
        """The kernel of one level's rows (see :class:`_Rows`).

        A cluster is read at its middle turn and widened: the length term by its spread and
        ``L half`` (``L cos`` moves by at most ``L`` per radian of ``t``); the support term is
        widened at each step by ``R half`` (:meth:`step`).
        """
        order = np.argsort(rows.before, kind="stable")
        before = rows.before[order]
        t, length, half = rows.turn[order], rows.length[order], rows.half[order]
        delta = 2 * np.pi / directions
        grid = np.arange(directions, dtype=np.float64) * delta
        spread = rows.spread[order]
        base = length[:, None] * np.cos(grid[None, :] - t[:, None]) + (spread + (length + spread) * half)[:, None]
        start, wa, wb = _wedge(directions, -t, delta)
        index = (start[:, None] + np.arange(directions)[None, :]) % directions
        after = rows.after[order]
        src = after[:, None] * directions + index
        nxt = after[:, None] * directions + (index + 1) % directions
        starts = np.flatnonzero(np.r_[True, before[1:] != before[:-1]])
        return cls(base, src, nxt, wa[:, None], wb[:, None], after, half, starts, before[starts],
                   rows.top[order], delta)

    def step(self, prev: FloatArray) -> FloatArray:
        """The next support (S, N) from ``prev`` (S, N); ``EMPTY`` for states no row leaves.

        A row widened by ``half`` also adds ``R half``, ``R`` the greatest norm of the set of
        ``s'`` (no less than ``max h``: a support function moves by at most ``R |d phi|``; the
        grid's wedge bound of ``max h`` is ``max h_j / cos(delta / 2)``).
        """
        flat = prev.ravel()
        vals = self.base + self.wa * flat[self.src] + self.wb * flat[self.nxt]
        if self.half.any():
            radius = np.maximum(prev.max(axis=-1), 0.0) / np.cos(self.delta / 2)
            vals += (radius[self.after] * self.half)[:, None]
        vals[prev[self.after, 0] <= EMPTY / 2] = EMPTY
        return self._max_by_state(vals, prev.shape)

    def turn(self, prev: FloatArray) -> FloatArray:
        """The greatest summed turn (S,) after one more chord, from ``prev`` (S,)."""
        return self._max_by_state(np.where(prev[self.after] <= EMPTY / 2, EMPTY, self.top + prev[self.after]),
                                  prev.shape)

    def _max_by_state(self, vals: FloatArray, shape: tuple[int, ...]) -> FloatArray:
        """The greatest of the rows' values per state before them; ``EMPTY`` for states no row leaves."""
        out = np.full(shape, EMPTY)
        if len(self.starts):
            out[self.states] = np.maximum.reduceat(vals, self.starts, axis=0)
        return out


def _tip_start(table: ChainTable, m: int, grid: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Support of the last ``w`` chords' displacement (S, k, N) and their summed turn with the end turn (S, k).

    Per full state (the ``2w`` units before the tip), reduced to the ``m`` units kept, in chunks.
    """
    w, k = table.window, table.n_types
    c, b = 2 * k, 2 * k + 2
    n_states = c**m
    tip_sym = ends(k)[1]
    unit = (_digits(table.codes, b, 2 * w + 1) < c).all(axis=1)
    full = np.unique(table.codes[unit] % b ** (2 * w))
    disp = np.zeros((len(full), table.n_levels, 2))
    angle = np.zeros((len(full), table.n_levels))
    ok = np.ones(len(full), dtype=bool)
    window = last = full.copy()
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
    support = np.full((n_states, table.n_levels, len(grid)), EMPTY)
    for lo in range(0, len(full), _CHUNK):
        part = slice(lo, lo + _CHUNK)
        tip0 = disp[part, :, 0, None] * np.cos(grid) + disp[part, :, 1, None] * np.sin(grid)
        tip0[~ok[part]] = EMPTY
        support = np.maximum(support, _reduce(tip0, fstate[part], n_states))
    return support, _reduce(np.where(ok[:, None], angle, EMPTY), fstate, n_states)


def build_reach(table: ChainTable, units: int, memory: int | None = None, directions: int = DIRECTIONS,
                families: tuple[str, ...] = ("centre", "tip"), max_rows: int = MAX_ROWS) -> Reach:
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
    max_rows : int
        Most chord rows per level; a table with more windows steps over clusters of windows of
        close turns (:func:`_clusters`: a wider, still admissible bound).
    """
    w, k = table.window, table.n_types
    c = 2 * k
    m = memory_of(table) if memory is None else int(memory)
    if not 1 <= m <= 2 * w:
        raise ValueError(f"the state holds 1 to {2 * w} units, got {m}")
    n_states = c**m
    delta = 2 * np.pi / directions
    grid: FloatArray = np.arange(directions, dtype=np.float64) * delta
    ud = _digits(table.codes, c + 2, 2 * w + 1)
    unit = (ud < c).all(axis=1)
    ud = ud[unit]
    before = _state_code(ud[:, 2 * w - m: 2 * w], c)
    after = _state_code(ud[:, 2 * w - m + 1:], c)
    pair = _state_code(ud[:, 2 * w - m:], c)
    t_u, l_u = table.turn[unit], table.length[unit]
    kl, steps = table.n_levels, int(units) + 1
    seqs: dict[str, FloatArray] = {}
    turn = np.zeros((0, n_states, kl))
    if "centre" in families:
        seqs["centre"] = np.full((steps, n_states, kl, directions), EMPTY)
        seqs["centre"][0] = 0.0
    if "tip" in families:
        seqs["tip"] = np.full((steps, n_states, kl, directions), EMPTY)
        seqs["tip"][0], turn0 = _tip_start(table, m, grid)
        turn = np.full((steps, n_states, kl), EMPTY)
        turn[0] = turn0
    for lev in range(kl):
        kernel = _Kernel.of(_clusters(pair, before, after, t_u[:, lev], l_u[:, lev], max_rows), directions)
        for seq in seqs.values():
            for a in range(1, len(seq)):
                seq[a, :, lev] = kernel.step(seq[a - 1, :, lev])
        for a in range(1, len(turn)):
            turn[a, :, lev] = kernel.turn(turn[a - 1, :, lev])
    return Reach(m, c, directions, tuple(_round_up(v) for v in seqs.get("centre", ())),
                 tuple(_round_up(v) for v in seqs.get("tip", ())), turn)


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
    units = min(chain.n_units, AHEAD) if family == "centre" else chain.n_units  # the profile bound looks AHEAD
    out = build_reach(chain.table, units, families=(family,))
    with _LOCK:
        _REACH.setdefault(chain, {})[family] = out
    return out


__all__ = ["AHEAD", "CLUSTER_WIDTHS", "DIRECTIONS", "EMPTY", "MAX_ROWS", "Reach", "build_reach", "memory_of",
           "reach_of"]

"""Certified search over a chain in space: designs grown unit by unit with each prefix's point and frame.

A chain in space (:attr:`~pneumorph.models.chain.table.ChainTable.space`, a library with
sideways units) places chord ``j`` in the frame of the point it starts from, after turning
that frame by the window's frame turn. A prefix of ``p`` units fixes the chords whose
windows it covers, as in the plane (:mod:`pneumorph.design.certified.prefixes`), so designs share
their prefixes' placements here too; each prefix carries its point and frame per level.

Bounds (admissible: no design of a dropped prefix can cost less than the bound):

- a Cartesian profile or space curve (Eq 4.1 with a centre's distance in y and z,
  :meth:`~pneumorph.design.objectives.profiles.ProfileTarget.squared_error`): the partial sums only grow,
  so ``min_k sqrt(partial_k)`` bounds every completion; and each of the next
  :data:`~pneumorph.design.certified.reach.AHEAD` centres still to place lies within ``r L_k`` of the
  prefix's last point (``r`` chords on), in a box whose x range bounds the target's y and z
  there (:class:`~pneumorph.design.certified.remainder.CurveRange`) and whose y and z ranges bound the
  centre's: its term is at least the squared gaps (:func:`space_rest`);
- a tip goal: the tip lies within ``r L_k`` of the prefix's last point, with ``r`` chords
  still to place and ``L_k`` the longest chord of the table at level ``k``; every goal is
  1-Lipschitz in the tip (``min-distance`` in its projection on the x-y plane), so it moves by
  at most that. Tighter, with the prefix's last frame: each window turns a frame by at most
  ``theta_k`` (the largest frame turn of the table) and its chord lies within ``alpha_k`` of
  its frame's x axis, so chord ``i`` still to place lies within ``phi_i = min(i theta_k +
  alpha_k, pi)`` of the prefix's frame's x axis ``u``. Along a direction ``e`` at angle ``psi``
  from ``u`` the chords take the tip at most ``h(e) = sum_i L_k cos(max(psi - phi_i, 0))`` (the
  shortest chord where that cosine is negative): the support function of a set holding every
  completion's tip. A coordinate goal moves by at most ``min(r L_k, h(+-e_x or e_y))``; the
  distance to a point ``d`` away is at least ``|d| - h(d / |d|)`` (and ``min-distance`` the
  same in the x-y plane).

The chain's own error bound (``beta``) is the planar one (:mod:`pneumorph.design.certified.search`):
a centre error of norm ``e`` in space changes a centre's term of a space curve,
``|(f(x) - y, g(x) - z)|``, by at most ``e sqrt(1 + f'^2 + g'^2)`` (the largest singular value
of ``[[f', -1, 0], [g', 0, -1]]``), and a tip goal by at most the tip's error. Polar
profiles, the curl and staged targets have no chain in space yet and are refused.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.certified.bounds import ChainScores, chain_errors, max_slope, radix, ranked_costs, target_slope
from pneumorph.design.certified.branching import BEAM, MAX_ENUMERATE, MAX_NODES, kept, narrow, union
from pneumorph.design.certified.prefixes import depths
from pneumorph.design.certified.reach import AHEAD
from pneumorph.design.certified.remainder import CurveRange, path_rest
from pneumorph.design.objectives.fitness import tip_value_array
from pneumorph.design.objectives.paths import PathTarget
from pneumorph.design.objectives.targets import Objective, ProfileTarget, TipGoal, on_actuator
from pneumorph.errors import SearchConfigError
from pneumorph.models.chain.model import ChainModel, window_codes
from pneumorph.models.chain.space import rotation_matrices

FloatArray = NDArray[np.float64]


def check_space_objective(objective: Objective) -> None:
    """Refuse an objective the chain in space cannot score yet.

    Raises
    ------
    SearchConfigError
        A polar profile, the curl or a staged target.
    """
    if (isinstance(objective, ProfileTarget) and objective.coordinates == "cartesian") or isinstance(objective,
                                                                                                  PathTarget):
        return
    if isinstance(objective, TipGoal) and objective.name != "max-curl":
        return
    what = getattr(objective, "label", None) or getattr(objective, "name", type(objective).__name__)
    raise SearchConfigError(f"the certified search over units that leave the plane scores Cartesian profiles, space "
                            f"curves, paths and tip goals other than the curl, not {what!r}; use --search ga")


def _elements(chain: ChainModel) -> tuple[FloatArray, FloatArray]:
    """The table's chords (K, k, 3) and frame turns as rotation matrices (K, k, 3, 3)."""
    space = chain.table.space
    return space[..., :3], rotation_matrices(space[..., 3:])


def _seed(chain: ChainModel, codes: NDArray[np.uint8]) -> tuple[NDArray[np.uint8], dict[str, Any]]:
    """The one-unit prefixes of ``codes`` and their state: the base point (its height that of the first unit) and
    frame."""
    table = chain.table
    bits = np.asarray(codes, dtype=np.uint8)[:, None].copy()
    c, k = len(bits), table.n_levels
    point = np.zeros((c, k, 3))
    point[..., 1] = table.heights[bits[:, 0]][:, None]
    point[..., 2] = table.centre_z
    return bits, {"point": point, "frame": np.broadcast_to(np.eye(3), (c, k, 3, 3)).copy(), "sum": np.zeros((c, k))}


def _placer(chain: ChainModel) -> Any:
    """``place(chain, bits, st, placed, upto)`` of :func:`~pneumorph.design.certified.prefixes.depths`, in space: yields
    ``(j, x, y, z)`` of every centre ``j + 1`` it fixes (y and z from the undeformed axis)."""
    chords, turns = _elements(chain)
    table = chain.table

    def place(chain: ChainModel, bits: NDArray[np.uint8], st: dict[str, Any], placed: int,
              upto: int) -> Iterator[tuple[int, FloatArray, FloatArray, FloatArray]]:
        n, w = chain.n_units, table.window
        if upto <= placed:
            return
        codes = window_codes(bits, w, range(placed, upto), n_types=table.n_types)
        for j in range(placed, upto):
            rows = table.lookup(codes[:, j - placed])
            st["frame"] = st["frame"] @ turns[rows]
            st["point"] = st["point"] + np.einsum("mkij,mkj->mki", st["frame"], chords[rows])
            if j + 1 <= n:
                p = st["point"]
                yield j, p[..., 0], p[..., 1] - table.heights[bits[:, j]][:, None], p[..., 2] - table.centre_z

    return place


def _cone(chain: ChainModel, remaining: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    """How far the ``remaining`` chords still to place turn from the prefix's last frame's x axis, per level: the
    angle ``phi`` (r, k) that chord ``i`` stays within (module docstring), and the shortest and longest chord (k,)."""
    space = chain.table.space
    lengths = np.linalg.norm(space[..., :3], axis=-1)  # (K, k)
    turn = np.linalg.norm(space[..., 3:], axis=-1).max(axis=0)  # the largest frame turn of a window
    off = np.arccos(np.clip(space[..., 0] / np.maximum(lengths, 1e-300), -1.0, 1.0)).max(axis=0)  # chord off x
    i = np.arange(1, remaining + 1)[:, None]
    return np.minimum(i * turn[None] + off[None], np.pi), lengths.min(axis=0), lengths.max(axis=0)


def _support(cos_psi: FloatArray, phi: FloatArray, shortest: FloatArray, longest: FloatArray) -> FloatArray:
    """The most the chords still to place can take the tip along a direction at angle ``psi`` from the frame's x
    axis (``cos_psi``, (m, k)): chord ``i`` within ``phi[i]`` of that axis gives at most ``L cos(max(psi - phi_i,
    0))`` (the shortest chord where that is negative)."""
    cos_psi = np.clip(cos_psi, -1.0, 1.0)
    sin_psi = np.sqrt(1.0 - cos_psi * cos_psi)  # psi in [0, pi]
    free = phi >= np.pi  # chords that may point anywhere: each adds its longest length
    total = np.broadcast_to(free.sum(axis=0) * longest, np.shape(cos_psi)).copy()
    for i in np.flatnonzero(~free.all(axis=1)):  # per chord still to place that is held in a cone at some level
        # cos(max(psi - phi, 0)): 1 inside the cone (psi <= phi), else cos psi cos phi + sin psi sin phi
        c = np.where(cos_psi >= np.cos(phi[i]), 1.0, cos_psi * np.cos(phi[i]) + sin_psi * np.sin(phi[i]))
        total += np.where(free[i], 0.0, np.where(c >= 0.0, longest * c, shortest * c))
    return total


def _tip_bound(chain: ChainModel, goal: TipGoal, point: FloatArray, remaining: int,
               frame: FloatArray | None = None) -> FloatArray:
    """A lower bound on the cost of a tip goal of every completion, shape (m,): the tip within ``remaining`` of the
    longest chords of the current ``point`` and, with the prefix's ``frame``, where chords that turn at most so far
    from its x axis can take it (module docstring)."""
    table = chain.table
    radius = remaining * _longest(chain)  # (k,)
    x = point[..., 0]
    y = point[..., 1] - table.tip_ref[1]
    u = None if frame is None else frame[..., :, 0]  # (m, k, 3): the prefix's last frame's x axis
    cone = None if u is None else _cone(chain, remaining)

    def reach_along(axis: int, sign: float) -> FloatArray:
        """The most the tip can move along ``sign`` times coordinate ``axis``."""
        if u is None or cone is None:
            return np.broadcast_to(radius, x.shape)
        return np.minimum(radius, _support(sign * u[..., axis], *cone))

    if goal.name == "max-x":
        cost = -(x + reach_along(0, 1.0))
    elif goal.name == "min-x":
        cost = x - reach_along(0, -1.0)
    elif goal.name == "max-y":
        cost = -(y + reach_along(1, 1.0))
    elif goal.name == "min-y":
        cost = y - reach_along(1, -1.0)
    elif goal.name == "min-distance":  # |tip_xy| is at least its part along the point's own direction in x-y
        r_xy = np.hypot(x, y)
        cost = r_xy - radius
        if u is not None and cone is not None:
            cos_psi = -(u[..., 0] * x + u[..., 1] * y) / np.maximum(r_xy, 1e-300)
            cost = np.maximum(cost, r_xy - _support(cos_psi, *cone))
        cost = np.maximum(cost, 0.0)
    else:  # reach
        assert goal.point is not None
        target = np.array([*goal.point, 0.0][:3])
        d = target + np.array([0.0, table.tip_ref[1], table.centre_z]) - point  # from the point to the target
        norm = np.linalg.norm(d, axis=-1)
        cost = norm - radius
        if u is not None and cone is not None:  # the distance to a set is at least d.e less its support along e
            cos_psi = np.einsum("mki,mki->mk", d, u) / np.maximum(norm, 1e-300)
            cost = np.maximum(cost, norm - _support(cos_psi, *cone))
        cost = np.maximum(cost, 0.0)
    return np.asarray(cost.min(axis=1), dtype=float)


def _longest(chain: ChainModel) -> FloatArray:
    """The longest chord of the table at each level (k,), mm."""
    return np.asarray(np.linalg.norm(chain.table.space[..., :3], axis=-1).max(axis=0), dtype=float)


def space_rest(chain: ChainModel, curves: tuple[CurveRange, CurveRange], bits: NDArray[np.uint8], point: FloatArray,
               placed: int) -> FloatArray:
    """A lower bound on the summed squared Eq 4.1 terms of the next centres the prefixes have not fixed, (m, k).

    Centre ``i`` (``placed < i``, at most :data:`~pneumorph.design.certified.reach.AHEAD` on) lies within
    ``(i - placed) L_k`` of the prefix's point in x, y and z; its term is at least the squared
    gap between that box's heights (less the unit's undeformed centre height: the prefix's
    unit's if it holds it, else the least and greatest of any) and the target's ``f`` over its
    x range, plus the same in z with ``g``.
    """
    table = chain.table
    f, g = curves
    heights = table.heights
    h_lo, h_hi = float(np.min(heights)), float(np.max(heights))
    longest = _longest(chain)
    total = np.zeros(point.shape[:2])
    x, y, z = point[..., 0], point[..., 1], point[..., 2] - table.centre_z
    for i in range(placed + 1, min(chain.n_units, placed + AHEAD) + 1):
        r = (i - placed) * longest
        lo_ref: FloatArray | float = h_lo
        hi_ref: FloatArray | float = h_hi
        if i <= bits.shape[1]:
            lo_ref = hi_ref = heights[np.asarray(bits[:, i - 1], dtype=np.int64)][:, None]
        f_lo, f_hi = f.between(x - r, x + r)
        g_lo, g_hi = g.between(x - r, x + r)
        gap_y = np.maximum(np.maximum(f_lo - (y + r - lo_ref), (y - r - hi_ref) - f_hi), 0.0)
        gap_z = np.maximum(np.maximum(g_lo - (z + r), (z - r) - g_hi), 0.0)
        total += gap_y * gap_y + gap_z * gap_z
    return total


def _curves(chain: ChainModel, objective: ProfileTarget, errors: dict[str, FloatArray]) -> tuple[CurveRange,
                                                                                                  CurveRange]:
    """The target's ``f`` and ``g`` over x intervals wherever the actuator can reach (:class:`CurveRange`)."""
    reach = chain.table.longest_chord * (chain.n_units + 1) + float(errors["centre"].max())
    length = chain.length
    slope_f = max_slope(lambda x: objective.curve(x, length), -reach, reach)
    slope_g = max_slope(lambda x: objective.curve_z(x, length), -reach, reach)
    return (CurveRange.of(lambda x: objective.curve(x, length), -reach, reach, slope_f),
            CurveRange.of(lambda x: np.broadcast_to(objective.curve_z(x, length), np.shape(x)), -reach, reach,
                          slope_g))


def _beta(chain: ChainModel, objective: Objective, errors: dict[str, FloatArray]) -> FloatArray:
    """The chain's bound on the objective per level (k,) (module docstring)."""
    if isinstance(objective, ProfileTarget):
        slope = target_slope(chain, objective, errors)
        return errors["centre"] * np.sqrt(chain.n_units * (1.0 + slope**2))
    if isinstance(objective, PathTarget):  # 1-Lipschitz in the stacked centres (pneumorph.design.objectives.paths)
        return errors["centre"] * np.sqrt(chain.n_units)
    return errors["tip"]


def grow_space(chain: ChainModel, objective: Objective, beta: FloatArray, threshold: float = float("inf"),
               max_nodes: int = MAX_NODES, beam: int | None = None, spill: bool = False,
               codes: NDArray[np.uint8] | None = None,
               curves: tuple[CurveRange, CurveRange] | None = None) -> ChainScores:
    """Chain scores of every design of a chain in space whose cost is below ``threshold``.

    As :func:`~pneumorph.design.certified.planegrowth.grow_designs` (``beam``, ``spill``, ``max_nodes`` alike), with
    the bounds of the module docstring; ``codes``: the unit codes designs are made of (default every
    code of the table; e.g. the planar units only); ``curves``: the target's ranges, for the bound
    on the centres still to place (:func:`space_rest`; without them the partial sums alone).
    """
    codes = np.asarray(chain.table.unit_codes if codes is None else codes, dtype=np.uint8)
    check_space_objective(objective)
    objective = on_actuator(objective, chain.length, float(chain.table.tip_ref[1]))  # a preset path, drawn for it
    table = chain.table
    n = chain.n_units
    length = chain.length
    profile = isinstance(objective, ProfileTarget)
    path = isinstance(objective, PathTarget)
    prof, goal = cast(ProfileTarget, objective), cast(TipGoal, objective)  # each used on its side only
    route = cast(PathTarget, objective) if path else None
    mid = np.array([0.0, 0.0, table.centre_z])  # a path's z is from the mid-plane
    bits, st = _seed(chain, codes)
    spilled: list[float] | None = [] if spill else None
    place = _placer(chain)
    with np.errstate(all="ignore"):
        growth = depths(chain, bits, st, place=place, codes=codes)
        for p, placed, bits, st, centres in growth:
            for j, x, y, z in centres:
                if profile:
                    st["sum"] = st["sum"] + prof.squared_error(x, y, length, z)
                elif route is not None:
                    st["sum"] = st["sum"] + route.term(j, n, st["point"] - mid)
            if p == n or (not np.isfinite(threshold) and beam is None):
                continue
            if route is not None:
                total = st["sum"] + path_rest(route, n, st["point"] - mid, placed, _longest(chain), st["sum"],
                                              threshold**2)
                bound = np.sqrt(total.min(axis=1))
            elif profile:
                total = st["sum"] if curves is None else st["sum"] + space_rest(chain, curves, bits, st["point"],
                                                                                 placed)
                bound = np.sqrt(total.min(axis=1))
            else:
                bound = _tip_bound(chain, goal, st["point"], n + 1 - placed, st["frame"])
            bits, st = kept(bits, st, narrow(bound < threshold, bound, beam, max_nodes, p, n, spilled))
            growth.send((bits, st))
        if profile or path:
            values = np.sqrt(st["sum"])
        else:
            values = tip_value_array(st["point"], table.tip_reference, np.zeros(st["point"].shape[:2]), goal.name,
                                     goal.point)
    cost, level, optimistic, bound = ranked_costs(values, np.broadcast_to(beta, values.shape), objective.sense)
    return ChainScores(bits, values, cost, level, optimistic, bound, floor=min(spilled or [np.inf]),
                       choices=radix(chain))


def space_scores(chain: ChainModel, objective: Objective, margin: float = 1.0, max_nodes: int = MAX_NODES,
                 max_enumerate: int = MAX_ENUMERATE, codes: NDArray[np.uint8] | None = None) -> ChainScores:
    """Chain scores of every design of a chain in space that can matter, with a floor under the rest.

    As :func:`~pneumorph.design.certified.planegrowth.chain_scores`: every design while there are at most
    ``2^max_enumerate``; above, a beam search (:data:`~pneumorph.design.certified.branching.BEAM` prefixes
    per depth) gives a good cost ``c0``, and branch-and-bound returns every design of chain
    cost below ``c0 + 2 beta``. Where more than ``max_nodes`` prefixes stay open, the best are
    kept and the floor says how much better an unlisted design could be. ``codes``: the unit
    codes designs are made of (:func:`grow_space`).

    Raises
    ------
    SearchConfigError
        An objective :func:`check_space_objective` refuses.

    Examples
    --------
    Every design of 7 units of the spatial library (4^7) for a helix, by its shipped table:

    >>> from pneumorph.design.objectives.targets import make_objective
    >>> from pneumorph.models.chain.sources import find_table
    >>> from pneumorph.models.factory import make_model
    >>> chain = ChainModel(find_table(make_model(7, {"fidelity": "3d", "library": "spatial"})), 7)
    >>> s = space_scores(chain, make_objective("helix", 10.0, length=chain.length))
    >>> s.complete, len(s.bits), bool(set(chain.table.texts(s.bits[s.order()[:1]])[0]) & set("lL"))
    (True, 16384, True)
    """
    check_space_objective(objective)
    errors = chain_errors(chain, margin)
    beta = np.asarray(_beta(chain, objective, errors), dtype=float)
    choices = len(chain.table.unit_codes if codes is None else codes)
    if float(choices) ** chain.n_units <= 2.0**max_enumerate:
        return grow_space(chain, objective, beta, codes=codes)
    curves = _curves(chain, objective, errors) if isinstance(objective, ProfileTarget) else None
    beamed = grow_space(chain, objective, beta, beam=BEAM, codes=codes, curves=curves)
    threshold = float(beamed.cost.min()) + 2 * float(beta.max()) + 1e-9
    scores = grow_space(chain, objective, beta, threshold, max_nodes=max_nodes, spill=True, codes=codes,
                        curves=curves)
    if scores.complete:
        keep = scores.cost < threshold
        return ChainScores(scores.bits[keep], scores.per_level[keep], scores.cost[keep], scores.level[keep],
                           scores.optimistic[keep], scores.bound[keep], floor=threshold - float(beta.max()),
                           choices=scores.choices)
    return replace(union(scores, beamed), floor=min(scores.floor, threshold) - float(beta.max()))


__all__ = ["check_space_objective", "grow_space", "space_scores"]

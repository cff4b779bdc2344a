"""Every design scored by the chain model, grown unit by unit over shared prefixes; above
:data:`~pneumorph.design.certified.branching.MAX_ENUMERATE` units (or ``2^MAX_ENUMERATE`` designs of a unit library), a
branch-and-bound over the same growth that returns every design within reach of the best and
a floor under all others (:mod:`pneumorph.design.certified.search`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.certified.bounds import (
    ChainScores,
    chain_errors,
    curve_range,
    polar_term,
    radix,
    ranked_costs,
    score_designs,
    staged_bound,
    target_slope,
    uniform_bound,
)
from pneumorph.design.certified.branching import BEAM, MAX_ENUMERATE, MAX_NODES, kept, narrow, union
from pneumorph.design.certified.headingbox import box_bound
from pneumorph.design.certified.prefixes import ChainGeometry, chain_geometry, depths, seed_prefixes, tip_and_curl
from pneumorph.design.certified.reach import reach_of
from pneumorph.design.certified.remainder import CurveRange, path_rest, profile_rest, tip_goal_rest
from pneumorph.design.certified.spacegrowth import space_scores
from pneumorph.design.objectives.fitness import tip_value_array
from pneumorph.design.objectives.paths import PathTarget
from pneumorph.design.objectives.targets import Objective, ProfileTarget, StagedTarget, TipGoal, on_actuator
from pneumorph.errors import SearchConfigError
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.windows import every_design

FloatArray = NDArray[np.float64]


SPILL_ROUNDS = 1
"""Probing runs at most before the last: a probe is a branch-and-bound that keeps at most
``MAX_NODES / SPILL_SHARE`` open prefixes (the best, when more stay open); while a probe finds a
better design, the next starts from its lower threshold. The last run keeps up to :data:`MAX_NODES`.
One probe: a second found nothing better in the cases measured and cost 10-20 % more
(BENCHMARKS.md)."""

SPILL_SHARE = 25
"""The share of :data:`MAX_NODES` a probing run keeps."""

REFINE_AT = 20_000
"""Open prefixes of a profile target above which the bound on the centres still to place is added
(below, the partial sums of Eq 4.1 prune well enough, and the support functions cost more than they save)."""

KEEP_GEOMETRY_UNITS = 15
"""Longest actuator whose prefix geometry is kept between queries (15 units: about 50 MB;
the memory doubles with every unit)."""


def choices(chain: ChainModel) -> int:
    """The choices per unit: 2 orientations of each of the table's unit types, 1 of a symmetric type."""
    return len(chain.table.unit_codes)


def designs_of(chain: ChainModel) -> float:
    """How many designs the chain model has: ``(2k)^n``."""
    return float(choices(chain)) ** chain.n_units


def enumerable(chain: ChainModel, units: int) -> bool:
    """At most as many designs as ``2^units`` (every design's geometry fits)."""
    return designs_of(chain) <= 2.0**units


# -- growing designs unit by unit: enumeration and branch-and-bound ---------------------------
def _uses_reach(chain: ChainModel, p: int) -> bool:
    """Whether the support functions bound a prefix of ``p`` units: its next window holds no base symbol (and
    the actuator is longer than one full window)."""
    w = chain.table.window
    return 2 * w <= p < chain.n_units and chain.n_units >= 2 * w + 2


def _prefix_bound(chain: ChainModel, objective: Objective, bits: NDArray[np.uint8], state: dict[str, Any],
                  placed: int, curve: CurveRange | None = None, limit: float = np.inf) -> FloatArray:
    """A lower bound on the cost of every completion of each prefix, shape (m,).

    The partial sums of Eq 4.1 (profiles) or the box of the remaining chords' heading intervals
    (tip goals), and, once the prefix's next window holds no base symbol, the bound on the
    units still to place from the support functions of their displacements
    (:mod:`pneumorph.design.certified.reach`); a path's partial sums and its next centres within the chords'
    reach (:func:`~pneumorph.design.certified.remainder.path_rest`: levels already at ``limit`` are not looked at
    again).
    """
    n = chain.n_units
    p = bits.shape[1]
    use = _uses_reach(chain, p)
    if isinstance(objective, PathTarget):  # the partial sums and the centres still to place (within chords' reach)
        total = state["sum"] + path_rest(objective, n, state["point"], placed, chain.table.length.max(axis=0),
                                         state["sum"], limit**2)
        return np.sqrt(total.min(axis=1))
    if isinstance(objective, ProfileTarget):
        total = state["sum"]
        if use and curve is not None and objective.coordinates == "cartesian":
            total = total + profile_rest(reach_of(chain, "centre"), chain.table.heights, curve, bits, state["point"],
                                         state["angle"], placed, n, chain.table.window)
        return np.sqrt(total.min(axis=1))
    if not use:
        return box_bound(chain, objective, state, n + 1 - placed).min(axis=1)
    return tip_goal_rest(reach_of(chain, "tip"), objective.name, objective.point, float(chain.table.tip_ref[1]), bits,
                         state["point"], state["angle"], n).min(axis=1)


def _score_all(chain: ChainModel, objective: Objective, errors: dict[str, FloatArray]) -> ChainScores:
    """Chain scores of all ``2^n`` designs from :func:`chain_geometry`."""
    g = chain_geometry(chain)
    n = chain.n_units
    e = errors["centre"]
    profile = isinstance(objective, ProfileTarget)
    prof, goal = cast(ProfileTarget, objective), cast(TipGoal, objective)  # each used on its side only
    polar = profile and prof.coordinates == "polar"
    slope = target_slope(chain, prof, errors) if profile else 0.0
    length = chain.length
    c = choices(chain)
    with np.errstate(all="ignore"):
        if profile:
            total = np.zeros((c, chain.table.n_levels))
            bsum = np.zeros_like(total) if polar else None
            at = 1
            for j, p in enumerate(g.depth):
                if p > at:
                    total = np.repeat(total, c ** (p - at), axis=0)
                    bsum = None if bsum is None else np.repeat(bsum, c ** (p - at), axis=0)
                    at = p
                if polar:
                    d = prof.curve(g.theta[j], length)
                    d -= g.r[j]
                    d *= d
                    bsum += polar_term(g.r[j], e, slope) ** 2  # type: ignore[operator]
                else:  # a space curve's z counts in full: the planar chain's centres lie at z = 0
                    d = prof.squared_error(g.x[j], g.y[j], length)
                total += d
            if at < n:
                total = np.repeat(total, c ** (n - at), axis=0)
                bsum = None if bsum is None else np.repeat(bsum, c ** (n - at), axis=0)
            values = np.sqrt(total, out=total)
        else:
            values = tip_value_array(g.tip, np.asarray(chain.table.tip_ref), g.curl, goal.name, goal.point)
        if polar:
            beta = e[None, :] * np.sqrt(bsum)  # type: ignore[arg-type]
        else:
            beta = np.broadcast_to(uniform_bound(chain, objective, errors, slope), values.shape)
    cost, level, optimistic, bound = ranked_costs(values, beta, objective.sense)
    return ChainScores(g.bits, values, cost, level, optimistic, bound, choices=radix(chain))


def _children(alive: NDArray[np.int64], steps: int, c: int = 2) -> NDArray[np.int64]:
    """Indices of the prefixes ``steps`` units longer than the prefixes ``alive`` (child ``c i + b``)."""
    return (alive[:, None] * c**steps + np.arange(c**steps)).ravel()


def _accumulate(g: ChainGeometry, objective: ProfileTarget, length: float, alive: NDArray[np.int64],
                total: FloatArray, at: int, centres: range, prune: Callable[[FloatArray], NDArray[np.bool_]] | None,
                c: int = 2) -> tuple[NDArray[np.int64], FloatArray, int]:
    """Add the squared Eq 4.1 terms of ``centres`` for the prefixes ``alive`` (at depth ``at``).

    With ``prune``, prefixes whose partial sums it flags are dropped after every centre;
    ``c`` is the number of choices per unit.
    """
    for j in centres:
        p = g.depth[j]
        if p > at:
            alive, total, at = _children(alive, p - at, c), np.repeat(total, c ** (p - at), axis=0), p
        total += objective.squared_error(g.x[j][alive], g.y[j][alive], length)
        if prune is not None:
            keep = ~prune(total)
            alive, total = alive[keep], total[keep]
    return alive, total, at


def best_scores(chain: ChainModel, objective: Objective, top: int = 10, margin: float = 1.0,
                probe: int = 256) -> ChainScores:
    """Chain scores of the designs that can matter: the ``top`` best and every one that could beat the best.

    For a Cartesian profile target the partial sums of Eq 4.1 only grow, so a prefix whose
    optimistic value (``min_k sqrt(partial_k) - beta_k``) already reaches a threshold ``T``
    can be dropped with all its designs. ``T`` comes from a probe: the ``probe`` prefixes of
    lowest partial sum two units before the end, completed exactly, give ``c_1`` and
    ``c_top`` (upper bounds on the true best and top-th costs), and ``T = max(c_top, c_1 +
    beta)``. Every dropped design then has an optimistic value ``>= T``: it is neither among
    the ``top`` best nor able to beat the best design's worst case (cost + bound). The
    answer lists the survivors with ``floor = T``. Other objectives score every design
    (:func:`chain_scores`), and a chain in space goes to
    :func:`~pneumorph.design.certified.spacegrowth.space_scores`.

    Examples
    --------
    >>> from pneumorph.models.chain.sources import find_table
    >>> from pneumorph.models.factory import make_model
    >>> from pneumorph.design.objectives.targets import make_objective
    >>> chain = ChainModel(find_table(make_model(15, {"fidelity": "3d"})), 15)
    >>> s = best_scores(chain, make_objective("sin", 10.0, length=chain.length))
    >>> chain.table.texts(s.bits[s.order()[:1]]), bool(len(s.bits) < 2**15), s.complete
    (['001111010001001'], True, False)
    """
    if chain.table.axes == 3:
        return space_scores(chain, objective, margin)
    errors = chain_errors(chain, margin)
    n = chain.n_units
    if (not isinstance(objective, ProfileTarget) or objective.coordinates != "cartesian"
            or not enumerable(chain, KEEP_GEOMETRY_UNITS) or n < 4):
        return chain_scores(chain, objective, margin)
    g = chain_geometry(chain)
    c = choices(chain)
    length = chain.length
    slope = target_slope(chain, objective, errors)
    beta = np.asarray(uniform_bound(chain, objective, errors, slope), dtype=float)
    def optimistic(total: FloatArray) -> FloatArray:
        return np.min(np.sqrt(total) - beta, axis=1)

    cut = n - 2
    early = range(sum(1 for p in g.depth if p <= cut))
    with np.errstate(all="ignore"):
        alive, total, at = _accumulate(g, objective, length, np.arange(c), np.zeros((c, len(beta))), 1, early, None,
                                       c)
        lb = optimistic(total)
        few = np.argsort(lb, kind="stable")[:probe]
        _, probe_total, _ = _accumulate(g, objective, length, alive[few], total[few], at,
                                        range(len(early), len(g.depth)), None, c)
        costs = np.sort(np.sqrt(probe_total).min(axis=1))
        k = min(top, len(costs)) - 1
        threshold = max(float(costs[k]), float(costs[0] + beta.max())) + 1e-9
        keep = lb < threshold
        alive, total = _accumulate(g, objective, length, alive[keep], total[keep], at,
                                   range(len(early), len(g.depth)), lambda t: optimistic(t) >= threshold, c)[:2]
        if (at := max(g.depth)) < n:  # pragma: no cover - the last centres are fixed by the whole design
            alive, total = _children(alive, n - at, c), np.repeat(total, c ** (n - at), axis=0)
        values = np.sqrt(total)
    cost, level, opt, bound = ranked_costs(values, np.broadcast_to(beta, values.shape), objective.sense)
    return ChainScores(g.bits[alive], values, cost, level, opt, bound, floor=threshold, choices=radix(chain))


def _add_terms(objective: ProfileTarget | PathTarget, st: dict[str, Any], j: int, x: FloatArray, y: FloatArray,
               sizes: tuple[int, float, FloatArray, float]) -> None:
    """Add centre ``j + 1``'s term to the prefixes' partial sums ``st["sum"]`` (a polar profile's bound's too):
    ``sizes`` holds the units, the actuator's length, the chain's centre errors and the target's slope."""
    n, length, e, slope = sizes
    if isinstance(objective, PathTarget):  # the centre where the model puts it: the state's point
        st["sum"] = st["sum"] + objective.term(j, n, st["point"])
    elif objective.coordinates == "cartesian":
        st["sum"] = st["sum"] + objective.squared_error(x, y, length)
    else:
        st["sum"] = st["sum"] + (objective.curve(st["theta"], length) - st["r"]) ** 2
        st["bsum"] = st["bsum"] + polar_term(st["r"], e, slope) ** 2


def grow_designs(chain: ChainModel, objective: Objective, errors: dict[str, FloatArray],
                 threshold: float = float("inf"), max_nodes: int = MAX_NODES, beam: int | None = None,
                 spill: bool = False) -> ChainScores:
    """Chain scores of every design whose cost is below ``threshold`` (all designs for ``inf``).

    Designs grow unit by unit, sharing their prefixes: a prefix of ``p`` units fixes the
    chords whose windows it covers, hence the first centres and the partial sums of Eq 4.1
    (which only grow), or the point where the remaining chords start (the tip then stays in
    the box they can reach, :func:`~pneumorph.design.certified.headingbox.box_bound`). Prefixes whose bound
    reaches ``threshold`` are
    dropped (branch-and-bound); with no threshold this enumerates all ``2^n`` designs at
    about two chord placements per design. With ``beam``, only the ``beam`` prefixes of
    lowest bound are kept at every depth (a heuristic: no longer every design below the
    threshold). With ``spill``, a depth with more than ``max_nodes`` open prefixes keeps the
    ``max_nodes`` of lowest bound and goes on; the scores' ``floor`` is then the least bound
    of the prefixes dropped (no design that is not listed costs less by the chain).

    Raises
    ------
    SearchConfigError
        More than ``max_nodes`` prefixes survive at one depth (the threshold is too loose), without ``spill``.
    """
    objective = on_actuator(objective, chain.length, float(chain.table.tip_ref[1]))  # preset paths, drawn for it
    if isinstance(objective, StagedTarget):
        return _grow_staged(chain, objective, errors, threshold, max_nodes, beam, spill)
    path = isinstance(objective, PathTarget)
    if not np.isfinite(threshold) and beam is None and enumerable(chain, KEEP_GEOMETRY_UNITS) and not path:
        return _score_all(chain, objective, errors)  # every design: from the kept geometry
    table = chain.table
    n, k = chain.n_units, table.n_levels
    profile = isinstance(objective, ProfileTarget)
    prof, goal = cast(ProfileTarget, objective), cast(TipGoal, objective)  # each used on its side only
    polar = profile and prof.coordinates == "polar"
    length = chain.length
    e = errors["centre"]
    slope = target_slope(chain, prof, errors) if profile else 0.0
    bits, st = seed_prefixes(chain, polar)
    spilled: list[float] | None = [] if spill else None
    curve, refine = None, False
    if profile and not polar and np.isfinite(slope) and (np.isfinite(threshold) or beam is not None):
        curve = curve_range(chain, prof, errors, slope)
    if profile or path:
        st["sum"] = np.zeros((len(bits), k))
    if polar:
        st["bsum"] = np.zeros((len(bits), k))
    with np.errstate(all="ignore"):
        growth = depths(chain, bits, st, polar)
        for p, placed, bits, st, centres in growth:
            for j, x, y in centres:
                if profile or path:
                    _add_terms(cast(ProfileTarget | PathTarget, objective), st, j, x, y, (n, length, e, slope))
            if p == n or (not np.isfinite(threshold) and beam is None):
                continue
            bound = _prefix_bound(chain, objective, bits, st, placed, limit=threshold)
            keep = bound < threshold
            if curve is not None and (refine or keep.sum() > REFINE_AT) and _uses_reach(chain, p):
                # the partial sums leave too many prefixes open: add the bound on the centres still to place
                refine = True
                bound[keep] = _prefix_bound(chain, objective, bits[keep], {key: v[keep] for key, v in st.items()},
                                            placed, curve)
                keep = bound < threshold
            bits, st = kept(bits, st, narrow(keep, bound, beam, max_nodes, p, n, spilled))
            growth.send((bits, st))
        if profile or path:
            values = np.sqrt(st["sum"])
        else:
            tip, curl = tip_and_curl(chain, bits, st)
            values = tip_value_array(tip, np.asarray(table.tip_ref), curl, goal.name, goal.point)
        if polar:
            beta = e[None, :] * np.sqrt(st["bsum"])
        else:
            beta = np.broadcast_to(uniform_bound(chain, objective, errors, slope), values.shape)
    cost, level, optimistic, bound = ranked_costs(values, beta, objective.sense)
    return ChainScores(bits, values, cost, level, optimistic, bound, floor=min(spilled or [np.inf]),
                       choices=radix(chain))


def chain_scores(chain: ChainModel, objective: Objective, margin: float = 1.0,
                 max_enumerate: int = MAX_ENUMERATE, max_nodes: int = MAX_NODES) -> ChainScores:
    """Chain scores of every design that can matter, with a floor under the rest.

    A chain in space (``chain.table.axes == 3``) is scored by
    :func:`~pneumorph.design.certified.spacegrowth.space_scores`. Up to ``max_enumerate`` units: all
    ``2^n`` designs. Above: a beam search (the 4096
    prefixes of lowest bound at every depth, :data:`BEAM`) gives a good cost ``c0``; branch-and-bound
    then returns every design of chain cost below ``c0 + 2 beta`` (``beta`` the largest
    bound), the only ones whose FE value can beat a design of chain cost ``c0``; all others
    are at least ``c0 + 2 beta`` by the chain, so their optimistic value is at least
    ``c0 + beta``.

    The branch-and-bound first runs as a probe that keeps at most ``max_nodes / SPILL_SHARE``
    open prefixes, the best ones where more stay open (``spill``); while a probe finds a
    design better than ``c0``, the next starts from its lower threshold (:data:`SPILL_ROUNDS`).
    A probe that keeps every open prefix is the answer. Otherwise a last run keeps up to
    ``max_nodes``; where that spills too, the answer is the best designs found with the floor
    that the dropped prefixes' least bound gives (``lower - beta``): an answer whose
    certificate states how much better an unlisted design could be, not a failure.
    """
    if chain.table.axes == 3:
        return space_scores(chain, objective, margin, max_nodes, max_enumerate)
    errors = chain_errors(chain, margin)
    n = chain.n_units
    if enumerable(chain, max_enumerate):
        return grow_designs(chain, objective, errors)
    beamed = grow_designs(chain, objective, errors, beam=BEAM)
    c0 = float(beamed.cost.min())
    probe = score_designs(chain, objective, np.zeros((1, n), dtype=np.uint8), errors)
    beta = float(probe.bound.max()) if np.isfinite(probe.bound).all() else float(errors["centre"].max())
    found, probes = beamed, 0
    while True:
        final = probes == SPILL_ROUNDS
        threshold = c0 + 2 * beta + 1e-9
        scores = grow_designs(chain, objective, errors, threshold, spill=True,
                              max_nodes=max_nodes if final else max(1, max_nodes // SPILL_SHARE))
        if scores.complete:
            keep = scores.cost < threshold
            return ChainScores(scores.bits[keep], scores.per_level[keep], scores.cost[keep], scores.level[keep],
                               scores.optimistic[keep], scores.bound[keep], floor=threshold - beta,
                               choices=scores.choices)
        found = union(scores, found)
        if final:
            return replace(found, floor=min(scores.floor, threshold) - beta)
        # a probe: a better design lowers the threshold and probes again; none leaves the last, full run
        probes = probes + 1 if float(found.cost.min()) < c0 - 1e-9 else SPILL_ROUNDS
        c0 = float(found.cost.min())


def _staged_rest(chain: ChainModel, profiles: list[tuple[int, ProfileTarget, int]], ranges: dict[int, CurveRange],
                 bits: NDArray[np.uint8], state: dict[str, Any], placed: int) -> FloatArray:
    """Per prefix and stage, a lower bound on the squared Eq 4.1 terms of the centres not yet fixed (m, S): the
    profile bound of :func:`~pneumorph.design.certified.remainder.profile_rest` at each Cartesian profile stage's
    level, 0 for the other stages."""
    rest = np.zeros(state["ssum"].shape)
    if not len(bits):
        return rest
    reach = reach_of(chain, "centre")
    for i, _, k in profiles:
        if i in ranges:
            rest[:, i] = profile_rest(reach.at_level(k), chain.table.heights, ranges[i], bits,
                                      state["point"][:, k:k + 1], state["angle"][:, k:k + 1], placed, chain.n_units,
                                      chain.table.window)[:, 0]
    return rest


def _grow_staged(chain: ChainModel, objective: StagedTarget, errors: dict[str, FloatArray], threshold: float,
                 max_nodes: int, beam: int | None, spill: bool = False) -> ChainScores:
    """:func:`grow_designs` for a staged target: every design below ``threshold`` (all ``(2k)^n`` for ``inf``).

    A prefix's bound is the weighted root-sum-square of its profile stages' partial sums of
    Eq 4.1, each at its stage's level (they only grow; a ``reach`` stage counts 0 until the
    tip is placed), so no design of a dropped prefix costs less than ``threshold``.
    """
    if not np.isfinite(threshold) and beam is None:
        if not enumerable(chain, MAX_ENUMERATE):
            raise SearchConfigError(f"scoring every one of {designs_of(chain):.3g} designs of {chain.n_units} units "
                                    "takes too long; give a threshold")
        bits = every_design(chain.n_units, np.asarray(chain.table.unit_codes, dtype=np.uint8))
        return score_designs(chain, objective, bits, errors)
    n, length = chain.n_units, chain.length
    levels = objective.levels(chain.table.pressures)
    weights = objective.weights
    profiles = [(i, st.target, levels[i]) for i, st in enumerate(objective.stages)
                if isinstance(st.target, ProfileTarget)]
    paths = [(i, st.target, levels[i]) for i, st in enumerate(objective.stages) if isinstance(st.target, PathTarget)]
    ranges = {i: curve_range(chain, target, errors, slope) for i, target, _ in profiles
              if target.coordinates == "cartesian" and np.isfinite(slope := target_slope(chain, target, errors))}
    refine = False
    bits, state = seed_prefixes(chain)
    spilled: list[float] | None = [] if spill else None
    state["ssum"] = np.zeros((len(bits), len(objective.stages)))
    with np.errstate(all="ignore"):
        growth = depths(chain, bits, state)
        for p, placed, bits, state, centres in growth:
            for j, x, y in centres:
                for i, target, k in profiles:
                    state["ssum"][:, i] += target.squared_error(x[:, k], y[:, k], length)
                for i, route, k in paths:
                    state["ssum"][:, i] += route.term(j, n, state["point"][:, k])
            if p == n:
                continue
            bound = np.sqrt(((weights**2) * state["ssum"]).sum(axis=1))
            keep = bound < threshold
            if ranges and (refine or keep.sum() > REFINE_AT) and _uses_reach(chain, p):
                refine = True  # each profile stage's centres still to place, at its level (module docstring)
                rest = _staged_rest(chain, profiles, ranges, bits[keep], {key: v[keep] for key, v in state.items()},
                                    placed)
                bound[keep] = np.sqrt(((weights**2) * (state["ssum"][keep] + rest)).sum(axis=1))
                keep = bound < threshold
            bits, state = kept(bits, state, narrow(keep, bound, beam, max_nodes, p, n, spilled))
            growth.send((bits, state))
        tip, curl = tip_and_curl(chain, bits, state)
        per = np.sqrt(state["ssum"])
        for i, st in enumerate(objective.stages):
            if isinstance(st.target, TipGoal):
                k = levels[i]
                per[:, i] = tip_value_array(tip[:, k], np.asarray(chain.table.tip_ref), curl[:, k], st.target.name,
                                            st.target.point)
        values = objective.at_levels(per, chain.table.pressures)
    beta = np.broadcast_to(staged_bound(chain, objective, errors), values.shape)
    cost, level, optimistic, bound = ranked_costs(values, beta, objective.sense)
    return ChainScores(bits, values, cost, level, optimistic, bound, floor=min(spilled or [np.inf]),
                       choices=radix(chain))

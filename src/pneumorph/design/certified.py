"""Certified search: every design scored by the chain model, the best verified by FE, with a bound.

The chain model (:mod:`pneumorph.models.chain`) predicts the unit centres, tip and curl of
any design within errors measured on held-out FE solves: at level ``k`` every centre
within ``e_k``, the tip within ``t_k``, the curl within ``c_k``. From these follows a bound
``beta_k`` on the objective (derivation in ``docs/chain-model.md``):

- profile ``y = f(x)`` (Eq 4.1): a centre error ``(dx, dy)`` changes the term
  ``f(x) - Y`` by at most ``|dy| + |f'| |dx| <= sqrt(1 + S^2) e_k`` with ``S`` the largest
  slope of ``f``; over ``n`` centres ``beta_k = e_k sqrt(n (1 + S^2))``;
- profile ``r = f(theta)``: radius within ``e_k``, angle within ``e_k / (r_i - e_k)``,
  so ``beta_k = e_k sqrt(sum_i (1 + S_theta / (r_i - e_k))^2)`` (per design);
- tip goals: ``t_k`` for positions and distances (1-Lipschitz), ``c_k`` for the curl.

Since the objective is the best over the levels, a design's FE value lies within
``max_k beta_k`` of its chain value, and it is at least as good as ``min_k (v_k - beta_k)``
(minimising; the *optimistic* value). The search orders all designs by chain value,
verifies the best with FE and reports how far at most any unverified design could beat the
verified winner; with ``certify`` it verifies in chain order until none can.

Up to :data:`MAX_ENUMERATE` units every design is scored, grown unit by unit over shared
prefixes; above, a branch-and-bound over the same growth (the partial sums of Eq 4.1 only
grow; the tip stays in the box its remaining chords can reach) returns every design whose
chain value is within reach of the best, and a floor under all others.

Over a unit library of ``k`` types (a chain table with an alphabet) every unit has ``2k``
choices (type and orientation, codes ``2t + o``) instead of 2: the same growth with ``2k``
children per prefix, all ``(2k)^n`` designs scored while there are at most
``2^MAX_ENUMERATE`` of them, branch-and-bound above.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.fitness import profile_error_array, score, tip_value_array
from pneumorph.design.prefixes import ChainGeometry, chain_geometry, depths, seed_prefixes, tip_and_curl
from pneumorph.design.reach import CurveRange, box_bound, profile_rest, reach_of, tip_goal_rest
from pneumorph.design.scoring import Candidate, ScoreBook
from pneumorph.design.targets import Objective, ProfileTarget, StagedTarget, TipGoal
from pneumorph.errors import SearchConfigError
from pneumorph.execution.evaluators import Evaluator
from pneumorph.models.chain import ChainModel
from pneumorph.models.response import ActuatorModel
from pneumorph.models.windows import design_numbers, every_design

FloatArray = NDArray[np.float64]

MAX_ENUMERATE = 20
"""Longest actuator whose 2^n designs are all scored; longer ones go through branch-and-bound
(over ``2k`` choices per unit: while ``(2k)^n <= 2^MAX_ENUMERATE``)."""
CHUNK = 8192
"""Designs scored at once (memory: about 2 kB per design and level)."""
MAX_NODES = 500_000
"""Most open prefixes the branch-and-bound keeps at one depth."""
REFINE_AT = 20_000
"""Open prefixes of a profile target above which the bound on the centres still to place is added
(below, the partial sums of Eq 4.1 prune well enough, and the support functions cost more than they save)."""
KEEP_GEOMETRY_UNITS = 15
"""Longest actuator whose prefix geometry is kept between queries (15 units: about 50 MB;
the memory doubles with every unit)."""


class BranchOverflow(SearchConfigError):
    """The branch-and-bound keeps more open prefixes than it may (:data:`MAX_NODES`).

    ``lower`` is the least bound among the open prefixes: no design that was not listed has a
    chain cost below ``min(lower, threshold)``.
    """

    def __init__(self, message: str, lower: float) -> None:
        super().__init__(message)
        self.lower = lower


# -- errors of the chain and the bound on the objective --------------------------------------
def chain_errors(chain: ChainModel, margin: float = 1.0) -> dict[str, FloatArray]:
    """The chain's validated worst errors per level: ``centre``, ``tip`` (mm), ``curl`` (deg).

    The held-out errors of the table, times ``margin``, and for actuators longer than the
    training designs times ``n / n_train`` (angle errors accumulate along the chain).
    """
    val = chain.table.validation
    try:
        errs = {k: np.asarray(val[src], dtype=float) for k, src in
                (("centre", "centre_worst_mm"), ("tip", "tip_worst_mm"), ("curl", "curl_worst_deg"))}
    except KeyError:
        raise SearchConfigError("the chain table carries no validation; rebuild it with `pneumorph chain build`") \
            from None
    trained = int(chain.table.source.get("n_units", chain.n_units))
    scale = margin * max(1.0, chain.n_units / max(trained, 1))
    return {k: v * scale for k, v in errs.items()}


def choices(chain: ChainModel) -> int:
    """The choices per unit: 2 orientations of each of the table's unit types, 1 of a symmetric type."""
    return len(chain.table.unit_codes)


def _radix(chain: ChainModel) -> int:
    """The base in which designs are numbered (:func:`design_numbers`): the unit codes ``0 .. 2k - 1``."""
    return 2 * chain.table.n_types


def designs_of(chain: ChainModel) -> float:
    """How many designs the chain model has: ``(2k)^n``."""
    return float(choices(chain)) ** chain.n_units


def _enumerable(chain: ChainModel, units: int) -> bool:
    """At most as many designs as ``2^units`` (every design's geometry fits)."""
    return designs_of(chain) <= 2.0**units


def _max_slope(f: Callable[[FloatArray], FloatArray], lo: float, hi: float, samples: int = 20001) -> float:
    """Largest |df/ds| on [lo, hi], from a fine grid (finite differences)."""
    s = np.linspace(lo, hi, samples)
    v = f(s)
    with np.errstate(all="ignore"):
        d = np.abs(np.diff(v) / np.diff(s))
    if not np.isfinite(d).all():
        return float("inf")
    return float(d.max())


def _target_slope(chain: ChainModel, objective: ProfileTarget, errors: dict[str, FloatArray]) -> float:
    """The largest slope of a profile target wherever the actuator can reach.

    ``|df/dx|`` over every x within the chords' summed greatest length of the base, or
    ``|df/dtheta|`` over two turns either way.
    """
    length = chain.length
    if objective.coordinates == "polar":
        return _max_slope(lambda t: objective.curve(t, length), -4 * np.pi, 4 * np.pi)
    reach = _x_reach(chain, errors)
    return _max_slope(lambda x: objective.curve(x, length), -reach, reach)


def _x_reach(chain: ChainModel, errors: dict[str, FloatArray]) -> float:
    """How far from the base any centre can be (mm): the chords' summed greatest length plus the chain's error."""
    return float(chain.table.length.max()) * (chain.n_units + 1) + float(errors["centre"].max())


def _curve_range(chain: ChainModel, objective: ProfileTarget, errors: dict[str, FloatArray],
                 slope: float) -> CurveRange:
    """The range of a Cartesian profile target over x intervals wherever the actuator can reach."""
    reach = _x_reach(chain, errors)
    return CurveRange.of(lambda x: objective.curve(x, chain.length), -reach, reach, slope)


def _polar_term(r: FloatArray, e: FloatArray, slope: float) -> FloatArray:
    """``(1 + S / (r - e))`` of one centre in the polar bound, infinite within ``e`` of the base."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(r > e, 1.0 + slope / (r - e), np.inf)


def _uniform_bound(chain: ChainModel, objective: Objective, errors: dict[str, FloatArray],
                   slope: float) -> FloatArray:
    """``beta_k`` of the objectives whose bound is the same for every design, shape (k,)."""
    if isinstance(objective, StagedTarget):
        return _staged_bound(chain, objective, errors)
    if isinstance(objective, ProfileTarget):
        return errors["centre"] * np.sqrt(chain.n_units * (1.0 + slope**2))
    return errors["curl"] if objective.name == "max-curl" else errors["tip"]


def _staged_bound(chain: ChainModel, objective: StagedTarget, errors: dict[str, FloatArray]) -> FloatArray:
    """``beta`` of a staged target, shape (k,): at the highest stage's level ``sqrt(sum_s (w_s beta_s)^2)``, each
    ``beta_s`` its stage's bound at the stage's level; 0 at the other levels (their value is the worst anyway).

    The weighted root-sum-square is a norm of the stages' values, so by the triangle
    inequality it moves by at most the same norm of the stages' bounds.
    """
    levels = objective.levels(chain.table.pressures)
    each = []
    for stage, k in zip(objective.stages, levels, strict=True):
        slope = _target_slope(chain, stage.target, errors) if isinstance(stage.target, ProfileTarget) else 0.0
        each.append(_uniform_bound(chain, stage.target, errors, slope)[k])
    beta = np.zeros(chain.table.n_levels)
    beta[max(levels)] = objective.combine(np.array(each))
    return beta


def objective_bounds(chain: ChainModel, objective: Objective, centres: FloatArray, reference: FloatArray,
                     errors: dict[str, FloatArray]) -> FloatArray:
    """Bound ``beta`` on the objective error per design and level, shape (m, k)."""
    m, k = centres.shape[:2]
    polar = isinstance(objective, ProfileTarget) and objective.coordinates == "polar"
    slope = _target_slope(chain, objective, errors) if isinstance(objective, ProfileTarget) else 0.0
    if not polar:
        return np.broadcast_to(_uniform_bound(chain, objective, errors, slope), (m, k))
    e = errors["centre"]
    r = np.hypot(centres[..., 0], centres[..., 1] - reference[:, None, :, 1])
    return e[None, :] * np.sqrt((_polar_term(r, e[None, :, None], slope) ** 2).sum(axis=-1))


# -- scoring every design -------------------------------------------------------------------
@dataclass(frozen=True)
class ChainScores:
    """Chain values of a set of designs.

    Attributes
    ----------
    bits : ndarray, shape (m, n)
        The designs (0/1 per unit).
    per_level : ndarray, shape (m, k)
        The objective at every level (worst where a level is not finite).
    cost : ndarray, shape (m,)
        The best level's value as a cost (the value when minimising, its negative when
        maximising).
    level : ndarray, shape (m,)
        The best level.
    optimistic : ndarray, shape (m,)
        The best cost the FE model can have given the bound (``min_k (cost_k - beta_k)``).
    bound : ndarray, shape (m,)
        ``max_k beta_k`` per design.
    floor : float
        The optimistic cost of every design *not* in the set (``inf`` when the set is all).
    choices : int
        The base in which the designs are numbered for ordering ties: the unit codes ``2k``.
    """

    bits: NDArray[np.integer]
    per_level: FloatArray
    cost: FloatArray
    level: NDArray[np.int64]
    optimistic: FloatArray
    bound: FloatArray
    floor: float = float("inf")
    choices: int = 2

    @property
    def complete(self) -> bool:
        return bool(np.isinf(self.floor))

    def order(self) -> NDArray[np.int64]:
        """Indices best first (ties: the smaller design)."""
        return np.lexsort((self._as_int(), self.cost))

    def _as_int(self) -> NDArray[np.int64]:
        return design_numbers(self.bits, self.choices)


def level_values(chain: ChainModel, objective: Objective, bits: NDArray[np.integer]) -> tuple[FloatArray, ...]:
    """Objective per design and level (m, k), with the predicted centres and references."""
    centres, tip, curl = chain.predict(bits)
    ref_c, _ = chain.table.reference(bits)

    def values_of(o: ProfileTarget | TipGoal) -> FloatArray:
        # L: the actuator of the first unit type (over a library the designs' lengths differ), and the
        # tip's undeformed height, which every design shares
        if isinstance(o, ProfileTarget):
            return profile_error_array(centres, ref_c[:, None], o, chain.length)
        return tip_value_array(tip, np.asarray(chain.table.tip_ref), curl, o.name, o.point)

    if isinstance(objective, StagedTarget):
        levels = objective.levels(chain.table.pressures)
        per = np.stack([values_of(st.target)[:, k] for st, k in zip(objective.stages, levels, strict=True)], axis=-1)
        return objective.at_levels(per, chain.table.pressures), centres, ref_c
    return values_of(objective), centres, ref_c


def _costs(values: FloatArray, beta: FloatArray, sense: str) -> tuple[FloatArray, NDArray[np.int64], FloatArray,
                                                                      FloatArray]:
    c = values * -1.0 if sense == "max" else values.copy()
    c[~np.isfinite(c)] = np.inf
    level = np.argmin(c, axis=1)
    cost = c[np.arange(len(c)), level]
    if beta.ndim == 2 and beta.strides[0] == 0:  # the same bound for every design: one row
        row = np.where(np.isfinite(beta[0]), beta[0], np.inf)
        optimistic = np.min(c - row, axis=1)
        bound = np.full(len(c), row.max())
    else:
        optimistic = np.min(c - beta, axis=1)
        bound = np.max(np.where(np.isfinite(beta), beta, np.inf), axis=1)
    return cost, level, optimistic, bound


def score_designs(chain: ChainModel, objective: Objective, bits: NDArray[np.integer],
                  errors: dict[str, FloatArray]) -> ChainScores:
    """Chain scores of the given designs (chunked)."""
    bits = np.asarray(bits, dtype=np.uint8)
    parts: list[tuple[Any, ...]] = []
    for lo in range(0, len(bits), CHUNK):
        b = bits[lo : lo + CHUNK]
        values, centres, ref_c = level_values(chain, objective, b)
        beta = objective_bounds(chain, objective, centres, ref_c, errors)
        parts.append((values, *_costs(values, beta, objective.sense)))
    values, cost, level, optimistic, bound = (np.concatenate([p[i] for p in parts]) for i in range(5))
    return ChainScores(bits, values, cost, level, optimistic, bound, choices=_radix(chain))


# -- growing designs unit by unit: enumeration and branch-and-bound ---------------------------
def _uses_reach(chain: ChainModel, p: int) -> bool:
    """Whether the support functions bound a prefix of ``p`` units: its next window holds no base symbol (and
    the actuator is longer than one full window)."""
    w = chain.table.window
    return 2 * w <= p < chain.n_units and chain.n_units >= 2 * w + 2


def _prefix_bound(chain: ChainModel, objective: Objective, bits: NDArray[np.uint8], state: dict[str, Any],
                  placed: int, curve: CurveRange | None = None) -> FloatArray:
    """A lower bound on the cost of every completion of each prefix, shape (m,).

    The partial sums of Eq 4.1 (profiles) or the box of the remaining chords' heading intervals
    (tip goals), and, once the prefix's next window holds no base symbol, the bound on the
    units still to place from the support functions of their displacements
    (:mod:`pneumorph.design.reach`).
    """
    n = chain.n_units
    p = bits.shape[1]
    use = _uses_reach(chain, p)
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
    slope = _target_slope(chain, prof, errors) if profile else 0.0
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
                    bsum += _polar_term(g.r[j], e, slope) ** 2  # type: ignore[operator]
                else:
                    d = prof.curve(g.x[j], length)
                    d -= g.y[j]
                d *= d
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
            beta = np.broadcast_to(_uniform_bound(chain, objective, errors, slope), values.shape)
    cost, level, optimistic, bound = _costs(values, beta, objective.sense)
    return ChainScores(g.bits, values, cost, level, optimistic, bound, choices=_radix(chain))


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
        d = objective.curve(g.x[j][alive], length)
        d -= g.y[j][alive]
        d *= d
        total += d
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
    (:func:`chain_scores`).

    Examples
    --------
    >>> from pneumorph.models.chaintables import find_table
    >>> from pneumorph.models.factory import make_model
    >>> from pneumorph.design.targets import make_objective
    >>> chain = ChainModel(find_table(make_model(15, {"fidelity": "3d"})), 15)
    >>> s = best_scores(chain, make_objective("sin", 10.0, length=chain.length))
    >>> chain.table.texts(s.bits[s.order()[:1]]), bool(len(s.bits) < 2**15), s.complete
    (['001111010001001'], True, False)
    """
    errors = chain_errors(chain, margin)
    n = chain.n_units
    if (not isinstance(objective, ProfileTarget) or objective.coordinates != "cartesian"
            or not _enumerable(chain, KEEP_GEOMETRY_UNITS) or n < 4):
        return chain_scores(chain, objective, margin)
    g = chain_geometry(chain)
    c = choices(chain)
    length = chain.length
    slope = _target_slope(chain, objective, errors)
    beta = np.asarray(_uniform_bound(chain, objective, errors, slope), dtype=float)
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
    cost, level, opt, bound = _costs(values, np.broadcast_to(beta, values.shape), objective.sense)
    return ChainScores(g.bits[alive], values, cost, level, opt, bound, floor=threshold, choices=_radix(chain))


def _narrow(keep: NDArray[np.bool_], bound: FloatArray, beam: int | None, max_nodes: int, p: int,
            n: int) -> NDArray[np.bool_]:
    """The open prefixes (``keep``) cut to the ``beam`` of lowest bound, if given.

    Raises
    ------
    BranchOverflow
        More than ``max_nodes`` stay open at depth ``p`` of ``n``.
    """
    if beam is not None and keep.sum() > beam:
        keep = np.zeros(len(bound), dtype=bool)
        keep[np.argpartition(bound, beam)[:beam]] = True
    if keep.sum() > max_nodes:
        raise BranchOverflow(f"branch-and-bound: {int(keep.sum()):,} open prefixes at unit {p} of {n}: too many "
                             "designs come within the chain's error bound of the best to list them all - use "
                             "--search ga", float(bound[keep].min()))
    return keep


def grow_designs(chain: ChainModel, objective: Objective, errors: dict[str, FloatArray],
                 threshold: float = float("inf"), max_nodes: int = MAX_NODES, beam: int | None = None) -> ChainScores:
    """Chain scores of every design whose cost is below ``threshold`` (all designs for ``inf``).

    Designs grow unit by unit, sharing their prefixes: a prefix of ``p`` units fixes the
    chords whose windows it covers, hence the first centres and the partial sums of Eq 4.1
    (which only grow), or the point where the remaining chords start (the tip then stays in
    the box they can reach, :func:`~pneumorph.design.reach.box_bound`). Prefixes whose bound reaches ``threshold`` are
    dropped (branch-and-bound); with no threshold this enumerates all ``2^n`` designs at
    about two chord placements per design. With ``beam``, only the ``beam`` prefixes of
    lowest bound are kept at every depth (a heuristic: no longer every design below the
    threshold).

    Raises
    ------
    SearchConfigError
        More than ``max_nodes`` prefixes survive at one depth (the threshold is too loose).
    """
    if isinstance(objective, StagedTarget):
        return _grow_staged(chain, objective, errors, threshold, max_nodes, beam)
    if not np.isfinite(threshold) and beam is None and _enumerable(chain, KEEP_GEOMETRY_UNITS):
        return _score_all(chain, objective, errors)  # every design: from the kept geometry
    table = chain.table
    n, k = chain.n_units, table.n_levels
    profile = isinstance(objective, ProfileTarget)
    prof, goal = cast(ProfileTarget, objective), cast(TipGoal, objective)  # each used on its side only
    polar = profile and prof.coordinates == "polar"
    length = chain.length
    e = errors["centre"]
    slope = _target_slope(chain, prof, errors) if profile else 0.0
    bits, st = seed_prefixes(chain, polar)
    curve, refine = None, False
    if profile and not polar and np.isfinite(slope) and (np.isfinite(threshold) or beam is not None):
        curve = _curve_range(chain, prof, errors, slope)
    if profile:
        st["sum"] = np.zeros((len(bits), k))
    if polar:
        st["bsum"] = np.zeros((len(bits), k))
    with np.errstate(all="ignore"):
        growth = depths(chain, bits, st, polar)
        for p, placed, bits, st, centres in growth:
            for _, x, y in centres:
                if profile:
                    if not polar:
                        st["sum"] = st["sum"] + (prof.curve(x, length) - y) ** 2
                    else:
                        st["sum"] = st["sum"] + (prof.curve(st["theta"], length) - st["r"]) ** 2
                        st["bsum"] = st["bsum"] + _polar_term(st["r"], e, slope) ** 2
            if p == n or (not np.isfinite(threshold) and beam is None):
                continue
            bound = _prefix_bound(chain, objective, bits, st, placed)
            keep = bound < threshold
            if curve is not None and (refine or keep.sum() > REFINE_AT) and _uses_reach(chain, p):
                # the partial sums leave too many prefixes open: add the bound on the centres still to place
                refine = True
                bound[keep] = _prefix_bound(chain, objective, bits[keep], {key: v[keep] for key, v in st.items()},
                                            placed, curve)
                keep = bound < threshold
            keep = _narrow(keep, bound, beam, max_nodes, p, n)
            bits = bits[keep]
            st = {key: v[keep] for key, v in st.items()}
            growth.send((bits, st))
        if profile:
            values = np.sqrt(st["sum"])
        else:
            tip, curl = tip_and_curl(chain, bits, st)
            values = tip_value_array(tip, np.asarray(table.tip_ref), curl, goal.name, goal.point)
        if polar:
            beta = e[None, :] * np.sqrt(st["bsum"])
        else:
            beta = np.broadcast_to(_uniform_bound(chain, objective, errors, slope), values.shape)
    cost, level, optimistic, bound = _costs(values, beta, objective.sense)
    return ChainScores(bits, values, cost, level, optimistic, bound, choices=_radix(chain))


def chain_scores(chain: ChainModel, objective: Objective, margin: float = 1.0,
                 max_enumerate: int = MAX_ENUMERATE, max_nodes: int = MAX_NODES) -> ChainScores:
    """Chain scores of every design that can matter, with a floor under the rest.

    Up to ``max_enumerate`` units: all ``2^n`` designs. Above: a beam search (the 4096
    prefixes of lowest bound at every depth) gives a good cost ``c0``; branch-and-bound
    then returns every design of chain cost below ``c0 + 2 beta`` (``beta`` the largest
    bound), the only ones whose FE value can beat a design of chain cost ``c0``; all others
    are at least ``c0 + 2 beta`` by the chain, so their optimistic value is at least
    ``c0 + beta``.

    Where more than ``max_nodes`` prefixes stay open, the answer is the beam's designs with
    the floor that the open prefixes' least bound gives (``lower - beta``): an answer whose
    certificate states how much better an unlisted design could be, not a failure.
    """
    errors = chain_errors(chain, margin)
    n = chain.n_units
    if _enumerable(chain, max_enumerate):
        return grow_designs(chain, objective, errors)
    beamed = grow_designs(chain, objective, errors, beam=4096)
    c0 = float(beamed.cost.min())
    probe = score_designs(chain, objective, np.zeros((1, n), dtype=np.uint8), errors)
    beta = float(probe.bound.max()) if np.isfinite(probe.bound).all() else float(errors["centre"].max())
    threshold = c0 + 2 * beta + 1e-9
    try:
        scores = grow_designs(chain, objective, errors, threshold, max_nodes=max_nodes)
    except BranchOverflow as exc:
        floor = min(exc.lower, threshold) - beta
        return replace(beamed, floor=floor)
    keep = scores.cost < threshold
    return ChainScores(scores.bits[keep], scores.per_level[keep], scores.cost[keep], scores.level[keep],
                       scores.optimistic[keep], scores.bound[keep], floor=threshold - beta, choices=scores.choices)


def _grow_staged(chain: ChainModel, objective: StagedTarget, errors: dict[str, FloatArray], threshold: float,
                 max_nodes: int, beam: int | None) -> ChainScores:
    """:func:`grow_designs` for a staged target: every design below ``threshold`` (all ``(2k)^n`` for ``inf``).

    A prefix's bound is the weighted root-sum-square of its profile stages' partial sums of
    Eq 4.1, each at its stage's level (they only grow; a ``reach`` stage counts 0 until the
    tip is placed), so no design of a dropped prefix costs less than ``threshold``.
    """
    if not np.isfinite(threshold) and beam is None:
        if not _enumerable(chain, MAX_ENUMERATE):
            raise SearchConfigError(f"scoring every one of {designs_of(chain):.3g} designs of {chain.n_units} units "
                                    "takes too long; give a threshold")
        bits = every_design(chain.n_units, np.asarray(chain.table.unit_codes, dtype=np.uint8))
        return score_designs(chain, objective, bits, errors)
    n, length = chain.n_units, chain.length
    levels = objective.levels(chain.table.pressures)
    weights = objective.weights
    profiles = [(i, st.target, levels[i]) for i, st in enumerate(objective.stages)
                if isinstance(st.target, ProfileTarget)]
    bits, state = seed_prefixes(chain)
    state["ssum"] = np.zeros((len(bits), len(objective.stages)))
    with np.errstate(all="ignore"):
        growth = depths(chain, bits, state)
        for p, _placed, bits, state, centres in growth:
            for _, x, y in centres:
                for i, target, k in profiles:
                    state["ssum"][:, i] += (target.curve(x[:, k], length) - y[:, k]) ** 2
            if p == n:
                continue
            bound = np.sqrt(((weights**2) * state["ssum"]).sum(axis=1))
            keep = _narrow(bound < threshold, bound, beam, max_nodes, p, n)
            bits = bits[keep]
            state = {key: v[keep] for key, v in state.items()}
            growth.send((bits, state))
        tip, curl = tip_and_curl(chain, bits, state)
        per = np.sqrt(state["ssum"])
        for i, st in enumerate(objective.stages):
            if isinstance(st.target, TipGoal):
                k = levels[i]
                per[:, i] = tip_value_array(tip[:, k], np.asarray(chain.table.tip_ref), curl[:, k], st.target.name,
                                            st.target.point)
        values = objective.at_levels(per, chain.table.pressures)
    beta = np.broadcast_to(_staged_bound(chain, objective, errors), values.shape)
    cost, level, optimistic, bound = _costs(values, beta, objective.sense)
    return ChainScores(bits, values, cost, level, optimistic, bound, choices=_radix(chain))


# -- the search -------------------------------------------------------------------------------
@dataclass(frozen=True)
class CertifiedResult:
    """A certified search's answer.

    Attributes
    ----------
    winner : Candidate
        The best FE-verified design (its FE value, level and response).
    winner_chain : Candidate
        The same design as the chain model sees it.
    hall_of_fame : tuple of Candidate
        The best designs by chain value (chain values and responses), best first.
    verified : dict
        FE candidates of every verified design.
    certificate : dict
        ``bound`` (largest objective bound), ``gap`` (how much better at most an unverified
        design could be than the winner; 0 when certified exactly, at most ``epsilon`` when
        certified within it), ``could_beat`` (unverified designs whose optimistic value beats
        the winner by more than ``epsilon``), ``epsilon``, ``tied`` (unverified designs that
        could beat it by at most ``epsilon``), ``certified``, ``designs_scored``, ``complete``
        (all 2^n scored) and ``floor``.
    scores : ChainScores
    solves : int
        New FE solves.
    wall_time : float
    """

    winner: Candidate
    winner_chain: Candidate
    hall_of_fame: tuple[Candidate, ...]
    verified: dict[str, Candidate]
    certificate: dict[str, Any]
    scores: ChainScores = field(repr=False)
    solves: int = 0
    wall_time: float = 0.0


def _solve_estimate(model: Any, count: int) -> str:
    """`` (about 15 s each)``: the measured solve time of the model's fidelity, or nothing."""
    from pneumorph.models.buildplan import duration_text, solve_seconds

    seconds = solve_seconds(str(getattr(model, "fidelity", "")), int(getattr(model, "n_units", 0) or 0))
    if not seconds:
        return ""
    each = " each" if count > 1 else ""
    return f" ({getattr(model, 'fidelity', '')}, about {duration_text(seconds)}{each})"


def chain_candidate(chain: ChainModel, objective: Objective, design: str) -> Candidate:
    """A design as the chain model sees it: its response and its score."""
    r = chain.evaluate(design)
    s = score(r, objective)
    return Candidate(design, s.value, s.level, s.pressure, None, r)


def certified_search(
    fe_model: ActuatorModel,
    chain: ChainModel,
    objective: Objective,
    evaluator: Evaluator | None = None,
    verify: int = 1,
    certify: bool = False,
    hall_of_fame: int = 10,
    margin: float = 1.0,
    max_verify: int = 200,
    on_progress: Callable[[str], None] | None = None,
    max_failures: int = 4,
    epsilon: float = 0.0,
) -> CertifiedResult:
    """Score every design with the chain, verify the best with FE, and bound the rest.

    Parameters
    ----------
    fe_model : ActuatorModel
        The model the chain was fitted to, with the same number of units.
    chain : ChainModel
    objective : ProfileTarget or TipGoal
    evaluator : Evaluator, optional
        Solves the FE verifications (serial by default; a cached one re-uses solves).
    verify : int
        Designs verified per batch (e.g. the number of workers).
    certify : bool
        Keep verifying, in chain order, until no unverified design can beat the winner.
    hall_of_fame : int
        Designs listed by chain value.
    margin : float
        Factor on the chain's validated errors in the bound.
    max_verify : int
        Stop certifying after this many FE solves (the gap then stays open).
    max_failures : int
        Give up when this many verified designs in a row failed to converge in the FE model
        before any converged (each failure can cost minutes).
    epsilon : float
        Certify within ``epsilon`` (the objective's units): designs that could beat the winner
        by at most ``epsilon`` are *tied* - counted in the certificate, not verified - and
        the winner is certified when no other design can beat it by more.

    Raises
    ------
    SearchConfigError
        Mismatched models, ``verify < 1``, or no verified design converged.
    """
    start = time.perf_counter()
    say = on_progress or (lambda text: None)
    if int(fe_model.n_units) != chain.n_units:
        raise SearchConfigError(f"the FE model has {fe_model.n_units} units, the chain model {chain.n_units}")
    if verify < 1:
        raise SearchConfigError(f"at least one design must be verified per batch, got {verify}")
    fe_p, chain_p = np.asarray(fe_model.pressures()), chain.pressures()
    if fe_p.shape != chain_p.shape or not np.allclose(fe_p, chain_p, rtol=0, atol=1e-12):
        raise SearchConfigError("the FE model and the chain model report different pressure levels")
    if not (np.isfinite(margin) and margin > 0):
        raise SearchConfigError(f"the bound's margin must be a positive number, got {margin!r}")
    if not (np.isfinite(epsilon) and epsilon >= 0):
        raise SearchConfigError(f"the certificate's epsilon must be a number >= 0, got {epsilon!r}")
    if chain.table.alphabet and isinstance(objective, ProfileTarget) and objective.length is None:
        # over a library the designs' lengths differ: L is that of the first type's actuator, for the chain
        # and the FE verifications alike
        objective = replace(objective, length=chain.length)
    scores = chain_scores(chain, objective, margin)
    order = scores.order()
    designs = chain.table.texts(scores.bits[order])
    say(f"chain: {len(designs):,} designs scored{'' if scores.complete else ' (branch-and-bound)'} in "
        f"{time.perf_counter() - start:.2f} s; best {designs[0]}")
    book = ScoreBook(fe_model, objective, evaluator)
    sign = 1.0 if objective.sense == "min" else -1.0
    optimistic = scores.optimistic[order]
    done = np.zeros(len(designs), dtype=bool)
    verified: list[str] = []

    def winner_cost() -> float:
        costs = [sign * book.scores[d].value for d in verified if not book.scores[d].failed]
        return min(costs) if costs else float("inf")

    while True:
        best = winner_cost()
        if np.isfinite(best) and not certify:
            break  # one batch that converged
        pending = np.flatnonzero(~done & (optimistic < best - epsilon)) if np.isfinite(best) else \
            np.flatnonzero(~done)
        if not len(pending):
            break
        if len(verified) >= max_verify:
            say(f"stopped after {len(verified)} FE verifications (max_verify)")
            break
        if not np.isfinite(best) and len(verified) >= max_failures:
            failures = "; ".join(f"{d}: {book.outcomes[d].failure}" for d in verified[:2])
            raise SearchConfigError(f"the FE model did not converge for the chain's {len(verified)} best designs "
                                    f"({failures}); check the model (units, pressure) with pneumorph simulate")
        batch = pending[:verify]
        todo = [designs[i] for i in batch]
        say(f"verifying {', '.join(todo)} by FE{_solve_estimate(fe_model, len(todo))} ...")
        book.score_many(todo)
        done[batch] = True
        verified += todo
        say(f"verified {', '.join(todo)} by FE: " + ", ".join(f"{book.scores[d].value:.4g}" for d in todo))
    if not any(not book.scores[d].failed for d in verified):
        raise SearchConfigError("no design converged in the FE model")
    best_cost = winner_cost()
    rest = optimistic[~done]
    could_beat = int((rest < best_cost - epsilon).sum())
    tied = int(((rest < best_cost) & (rest >= best_cost - epsilon)).sum())
    beat_floor = scores.floor < best_cost - epsilon
    gap = max(0.0, best_cost - min(float(rest.min()) if len(rest) else float("inf"), scores.floor))
    winner = min((book.candidate(d) for d in verified if not book.scores[d].failed),
                 key=lambda c: (sign * c.value, c.design))
    hof = tuple(chain_candidate(chain, objective, d) for d in designs[:hall_of_fame])
    winner_chain = next((c for c in hof if c.design == winner.design), None) or \
        chain_candidate(chain, objective, winner.design)
    certificate = {
        "bound": float(scores.bound[order[designs.index(winner.design)]]),
        "bound_worst": float(np.max(scores.bound)),
        "gap": gap,
        "could_beat": could_beat,
        "epsilon": epsilon,
        "tied": tied,
        "certified": could_beat == 0 and not beat_floor,
        "verified": list(verified),
        "designs_scored": len(designs),
        "complete": scores.complete,
        "floor": None if scores.complete else sign * scores.floor,
        "margin": margin,
        "sense": objective.sense,
    }
    return CertifiedResult(winner, winner_chain, hof, {d: book.candidate(d) for d in verified}, certificate, scores,
                           solves=book.solves, wall_time=time.perf_counter() - start)


__all__ = [
    "CertifiedResult",
    "ChainGeometry",
    "ChainScores",
    "best_scores",
    "certified_search",
    "chain_candidate",
    "chain_errors",
    "chain_geometry",
    "chain_scores",
    "grow_designs",
    "objective_bounds",
    "score_designs",
]

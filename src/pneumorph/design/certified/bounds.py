"""The certified search's scores and bound: the chain's validated errors, from them the bound on
the objective of every design (the derivation: :mod:`pneumorph.design.certified.search`,
``docs/chain-model.md``), and the scores of given designs with their bounds
(:class:`ChainScores`, :func:`score_designs`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.certified.remainder import CurveRange
from pneumorph.design.objectives.contact import ContactGoal
from pneumorph.design.objectives.fitness import path_error_array, profile_error_array, tip_value_array
from pneumorph.design.objectives.paths import PathTarget
from pneumorph.design.objectives.targets import Objective, ProfileTarget, StagedTarget, TipGoal
from pneumorph.errors import SearchConfigError
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.windows import design_numbers

FloatArray = NDArray[np.float64]


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


def max_slope(f: Callable[[FloatArray], FloatArray], lo: float, hi: float, samples: int = 20001) -> float:
    """Largest |df/ds| on [lo, hi], from a fine grid (finite differences)."""
    s = np.linspace(lo, hi, samples)
    v = f(s)
    with np.errstate(all="ignore"):
        d = np.abs(np.diff(v) / np.diff(s))
    if not np.isfinite(d).all():
        return float("inf")
    return float(d.max())


def target_slope(chain: ChainModel, objective: ProfileTarget, errors: dict[str, FloatArray]) -> float:
    """The largest slope of a profile target wherever the actuator can reach.

    ``|df/dx|`` over every x within the chords' summed greatest length of the base, or
    ``|df/dtheta|`` over two turns either way; for a space curve ``sqrt(f'^2 + g'^2)`` (the
    chain is planar: its centres lie at z = 0 exactly, so only their x error moves the z term).
    """
    length = chain.length
    if objective.coordinates == "polar":
        return max_slope(lambda t: objective.curve(t, length), -4 * np.pi, 4 * np.pi)
    reach = _x_reach(chain, errors)
    slope = max_slope(lambda x: objective.curve(x, length), -reach, reach)
    if objective.spatial:  # a centre's x error moves its z term by |dg/dx| too: |(dy, dz)| <= e sqrt(1 + f'^2 + g'^2)
        slope = float(np.hypot(slope, max_slope(lambda x: objective.curve_z(x, length), -reach, reach)))
    return slope


def _x_reach(chain: ChainModel, errors: dict[str, FloatArray]) -> float:
    """How far from the base any centre can be (mm): the chords' summed greatest length plus the chain's error."""
    return chain.table.longest_chord * (chain.n_units + 1) + float(errors["centre"].max())


def curve_range(chain: ChainModel, objective: ProfileTarget, errors: dict[str, FloatArray],
                 slope: float) -> CurveRange:
    """The range of a Cartesian profile target over x intervals wherever the actuator can reach."""
    reach = _x_reach(chain, errors)
    return CurveRange.of(lambda x: objective.curve(x, chain.length), -reach, reach, slope)


def polar_term(r: FloatArray, e: FloatArray, slope: float) -> FloatArray:
    """``(1 + S / (r - e))`` of one centre in the polar bound, infinite within ``e`` of the base."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(r > e, 1.0 + slope / (r - e), np.inf)


def uniform_bound(chain: ChainModel, objective: Objective, errors: dict[str, FloatArray],
                   slope: float) -> FloatArray:
    """``beta_k`` of the objectives whose bound is the same for every design, shape (k,)."""
    if isinstance(objective, StagedTarget):
        return staged_bound(chain, objective, errors)
    if isinstance(objective, ProfileTarget):
        return errors["centre"] * np.sqrt(chain.n_units * (1.0 + slope**2))
    if isinstance(objective, PathTarget):  # 1-Lipschitz in the stacked centres (pneumorph.design.objectives.paths)
        return errors["centre"] * np.sqrt(chain.n_units)
    return errors["curl"] if objective.name == "max-curl" else errors["tip"]


def staged_bound(chain: ChainModel, objective: StagedTarget, errors: dict[str, FloatArray]) -> FloatArray:
    """``beta`` of a staged target, shape (k,): at the highest stage's level ``sqrt(sum_s (w_s beta_s)^2)``, each
    ``beta_s`` its stage's bound at the stage's level; 0 at the other levels (their value is the worst anyway).

    The weighted root-sum-square is a norm of the stages' values, so by the triangle
    inequality it moves by at most the same norm of the stages' bounds.
    """
    levels = objective.levels(chain.table.pressures)
    each = []
    for stage, k in zip(objective.stages, levels, strict=True):
        slope = target_slope(chain, stage.target, errors) if isinstance(stage.target, ProfileTarget) else 0.0
        each.append(uniform_bound(chain, stage.target, errors, slope)[k])
    beta = np.zeros(chain.table.n_levels)
    beta[max(levels)] = objective.combine(np.array(each))
    return beta


def objective_bounds(chain: ChainModel, objective: Objective, centres: FloatArray, reference: FloatArray,
                     errors: dict[str, FloatArray]) -> FloatArray:
    """Bound ``beta`` on the objective error per design and level, shape (m, k)."""
    m, k = centres.shape[:2]
    polar = isinstance(objective, ProfileTarget) and objective.coordinates == "polar"
    slope = target_slope(chain, objective, errors) if isinstance(objective, ProfileTarget) else 0.0
    if not polar:
        return np.broadcast_to(uniform_bound(chain, objective, errors, slope), (m, k))
    e = errors["centre"]
    r = np.hypot(centres[..., 0], centres[..., 1] - reference[:, None, :, 1])
    return e[None, :] * np.sqrt((polar_term(r, e[None, :, None], slope) ** 2).sum(axis=-1))

CHUNK = 8192
"""Designs scored at once (memory: about 2 kB per design and level)."""


def radix(chain: ChainModel) -> int:
    """The base in which designs are numbered (:func:`design_numbers`): the unit codes ``0 .. 2k - 1``."""
    return 2 * chain.table.n_types

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
    """Objective per design and level (m, k), with the predicted centres and references.

    Raises
    ------
    SearchConfigError
        A contact goal (``grip``, ``wrap``): the chain model knows no contact.
    """
    if isinstance(objective, ContactGoal):
        raise SearchConfigError(f"the chain model knows no contact: {objective.name!r} is measured by FE with "
                                "contact only (search with --search ga or exhaustive)")
    centres, tip, curl = chain.predict(bits)
    ref_c, _ = chain.table.reference(bits)

    def values_of(o: ProfileTarget | PathTarget | TipGoal) -> FloatArray:
        # L: the actuator of the first unit type (over a library the designs' lengths differ), and the
        # tip's undeformed height, which every design shares
        if isinstance(o, ProfileTarget):
            return profile_error_array(centres, ref_c[:, None], o, chain.length)
        if isinstance(o, PathTarget):
            return path_error_array(centres, ref_c[:, None], o, chain.length, float(chain.table.tip_ref[1]))
        return tip_value_array(tip, chain.table.tip_reference, curl, o.name, o.point)

    if isinstance(objective, StagedTarget):
        levels = objective.levels(chain.table.pressures)
        per = np.stack([values_of(st.target)[:, k] for st, k in zip(objective.stages, levels, strict=True)], axis=-1)
        return objective.at_levels(per, chain.table.pressures), centres, ref_c
    return values_of(objective), centres, ref_c


def ranked_costs(values: FloatArray, beta: FloatArray, sense: str) -> tuple[FloatArray, NDArray[np.int64], FloatArray,
                                                                      FloatArray]:
    c = values * -1.0 if sense == "max" else values.copy()
    c[~np.isfinite(c)] = np.inf
    level = np.argmin(c, axis=1)
    cost = c[np.arange(len(c)), level]
    if beta.ndim == 2 and len(beta) and beta.strides[0] == 0:  # the same bound for every design: one row
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
        parts.append((values, *ranked_costs(values, beta, objective.sense)))
    values, cost, level, optimistic, bound = (np.concatenate([p[i] for p in parts]) for i in range(5))
    return ChainScores(bits, values, cost, level, optimistic, bound, choices=radix(chain))

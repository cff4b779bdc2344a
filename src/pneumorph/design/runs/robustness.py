"""How robust a run's winner is to mould tolerances, and ranking designs by it (``--robust``).

A certified run has a chain model; with the unit's tolerance tables
(:mod:`pneumorph.sensitivity.robust`) every design's objective under seeded samples of the
tolerance class costs a chain scoring per sample, so the winner's spread (mean, worst,
95th percentile) is cheap, and ``--robust worst|mean`` ranks all designs by it. Any other
run re-evaluates its winner with the FE model under the same samples (one solve each).

Each design is judged at one pressure: the winner at its own; with ``--robust``, each
design at the pressure where its statistic is best.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph import checks
from pneumorph.design.certified.bounds import level_values
from pneumorph.design.objectives.fitness import score
from pneumorph.design.certified.planegrowth import KEEP_GEOMETRY_UNITS, chain_scores
from pneumorph.design.search.scoring import Candidate, ScoreBook
from pneumorph.models.chain.model import ChainModel, ChainTable, design_array, design_strings
from pneumorph.models.chain.windows import design_numbers
from pneumorph.sensitivity.robust import Robustness, ToleranceTables, spread
from pneumorph.sensitivity.tolerances import Tolerance, box_units

#: designs listed by their robust statistic
TOP = 10


def design_robustness(table: ChainTable, tables: ToleranceTables, objective: Any, bits: NDArray[np.integer],
                      level: NDArray[np.integer] | None = None, samples: int = 30, seed: int = 0,
                      choose: str | None = None) -> Robustness:
    """The objective of designs ``bits`` under ``samples`` seeded offsets of the tolerance class.

    Parameters
    ----------
    level : ndarray, optional
        The level each design is judged at (its nominal best level, say); with ``choose``
        instead, the level of each design that minimises that statistic (``"worst"`` or
        ``"mean"``: the pressure at which it is most robust).

    Every design of an actuator short enough to keep its prefix geometry is scored by
    growing the designs unit by unit (:func:`~pneumorph.design.certified.search.chain_scores`, the
    certified search's scoring, twice as fast); other sets of designs one by one.
    """
    samples = checks.integer(samples, "samples", 1, 10_000)
    bits = np.atleast_2d(np.asarray(bits, dtype=np.uint8))
    offsets = tables.tolerance.samples(samples, seed)
    n = bits.shape[1]
    codes = design_numbers(bits)
    every = n <= KEEP_GEOMETRY_UNITS and len(bits) == 2**n and len(np.unique(codes)) == 2**n
    per = []  # (samples, m, k)
    for o in offsets:
        chain = ChainModel(tables.perturbed(table, o), n)
        if every:
            scores = chain_scores(chain, objective)
            grown = design_numbers(scores.bits)
            where = np.empty(2**n, dtype=np.int64)
            where[grown] = np.arange(len(grown))
            values = scores.per_level[where[codes]]
        else:
            values, _, _ = level_values(chain, objective, bits)
        per.append(np.where(np.isfinite(values), values, np.inf if objective.sense == "min" else -np.inf))
    stack = np.stack(per)
    if level is None:
        name = choose or "worst"
        probe = Robustness(bits, np.zeros(len(bits), dtype=np.int64), stack.reshape(samples, -1), offsets,
                           objective.sense).statistic(name).reshape(len(bits), -1)
        cost = probe if objective.sense == "min" else -probe
        level = np.argmin(cost, axis=1)
    level = np.asarray(level, dtype=np.int64)
    values = stack[:, np.arange(len(bits)), level]
    return Robustness(bits, level, values, offsets, objective.sense)


def chain_robustness(config: Any, chain: Any, tables: Any, objective: Any, winner: Candidate) -> dict[str, Any]:
    """The winner's objective under ``config.robust_samples`` samples, by the chain with tolerance tables."""
    level = 0 if winner.level is None else int(winner.level)
    rob = design_robustness(chain.table, tables, objective, design_array(winner.design), level=np.array([level]),
                            samples=config.samples(chain=True), seed=config.seed)
    return {"method": "chain model with tolerance tables", "tolerance_mm": config.tolerance,
            "samples": config.samples(chain=True), "seed": config.seed,
            "winner": {"design": winner.design, "level": level,
                       "pressure_kpa": None if winner.pressure is None else winner.pressure * 1e3,
                       "nominal_fe": winner.value, **rob.summary(0)},
            "offsets_mm": rob.offsets.tolist(), "winner_values": rob.values[:, 0].tolist()}


def robust_ranking(config: Any, chain: Any, tables: Any, objective: Any,
                   bits: np.ndarray) -> tuple[list[dict[str, Any]], Any]:
    """All ``bits`` ranked by ``config.robust`` under the tolerance samples (best first), and the Robustness."""
    rob = design_robustness(chain.table, tables, objective, bits, samples=config.samples(chain=True),
                            seed=config.seed, choose=config.robust)
    stat = rob.statistic(config.robust)
    cost = stat if objective.sense == "min" else -stat
    order = np.lexsort((np.arange(len(cost)), cost))[:TOP]
    names = design_strings(rob.bits[order])
    pressures = chain.pressures()
    rows = [{"rank": r + 1, "design": d, "pressure_kpa": float(pressures[rob.level[i]] * 1e3),
             **rob.summary(i)} for r, (d, i) in enumerate(zip(names, order, strict=True))]
    return rows, rob


def robust_winner(config: Any, model: Any, objective: Any, evaluator: Any, rows: list[dict[str, Any]]) -> Candidate:
    """The best design by the robust statistic, verified by the FE model (its nominal value)."""
    book = ScoreBook(model, objective, evaluator)
    book.score_many([rows[0]["design"]])
    return book.candidate(rows[0]["design"])


def fe_robustness(config: Any, model: Any, objective: Any, winner: Candidate, evaluator: Any) -> dict[str, Any] | None:
    """The winner's objective under the tolerance samples, each solved by the FE model (None: not an FE model)."""
    if not hasattr(model, "variant") or not hasattr(model, "unit") or winner.level is None:
        return None
    tolerance = Tolerance(config.tolerance)
    offsets = tolerance.samples(config.samples(chain=False), config.seed)
    nominal, units = box_units(model.unit, tolerance, offsets)
    cases = [(model.variant(unit=u), winner.design) for u in (nominal, *units)]
    values = np.full(len(cases), np.nan)
    for i, outcome in evaluator.iter_cases(cases):
        if outcome.ok:
            values[i] = score(outcome.response, objective).values[winner.level]
    ok = np.isfinite(values[1:])
    out: dict[str, Any] = {"method": "FE model, one solve per sample", "tolerance_mm": config.tolerance,
                           "samples": config.samples(chain=False), "seed": config.seed, "failed": int((~ok).sum()),
                           "element_size_mm": nominal.element_size, "offsets_mm": offsets.tolist(),
                           "winner_values": [None if not np.isfinite(v) else float(v) for v in values[1:]]}
    out["winner"] = {"design": winner.design, "level": int(winner.level),
                     "pressure_kpa": None if winner.pressure is None else winner.pressure * 1e3,
                     "nominal_fe": winner.value, "nominal_matched_mesh": float(values[0]),
                     **(spread(values[1:][ok], objective.sense) if ok.any() else {})}
    return out


def winner_robustness(problem: Any, winner: Candidate | None) -> dict[str, Any] | None:
    """A run's winner under the mould tolerance by FE solves (:func:`fe_robustness`) for a
    :class:`~pneumorph.design.algorithms.problem.Problem`; None without a tolerance, over a unit library of
    several types (the tolerances are those of one unit) or for a failed winner."""
    config = problem.config
    if config.tolerance == 0 or getattr(problem.model, "mixed", False) or winner is None or winner.failure is not None:
        return None
    problem.say(f"robustness of {winner.design}: {config.samples(False) + 1} FE solves under "
                f"+-{config.tolerance:g} mm")
    return fe_robustness(config, problem.model, problem.objective, winner, problem.evaluator)


__all__ = ["chain_robustness", "design_robustness", "fe_robustness", "robust_ranking", "robust_winner",
           "winner_robustness"]

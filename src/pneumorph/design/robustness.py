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

from pneumorph.design.fitness import score
from pneumorph.design.scoring import Candidate, ScoreBook
from pneumorph.models.chain import design_array, design_strings
from pneumorph.sensitivity.robust import design_robustness, spread
from pneumorph.sensitivity.tolerances import Tolerance, box_units

#: designs listed by their robust statistic
TOP = 10


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


__all__ = ["chain_robustness", "fe_robustness", "robust_ranking", "robust_winner"]

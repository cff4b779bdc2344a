"""Certified search: every design scored by the chain model, the best verified by FE, with a bound.

The chain model (:mod:`pneumorph.models.chain.model`) predicts the unit centres, tip and curl of
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
from typing import Any

import numpy as np

from pneumorph.design.certified.bounds import ChainScores, chain_errors, objective_bounds, score_designs
from pneumorph.design.certified.branching import MAX_ENUMERATE, MAX_NODES, OpenWatch, cap_text, watching
from pneumorph.design.certified.planegrowth import best_scores, chain_scores, designs_of, enumerable, grow_designs
from pneumorph.design.certified.prefixes import ChainGeometry, chain_geometry
from pneumorph.design.certified.spacegrowth import space_scores
from pneumorph.design.objectives.fitness import score
from pneumorph.design.objectives.targets import Objective, ProfileTarget, on_actuator
from pneumorph.design.search.scoring import Candidate, ScoreBook
from pneumorph.errors import SearchConfigError
from pneumorph.execution.evaluators import Evaluator
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.plan import evaluator_workers, solve_estimate
from pneumorph.models.response import ActuatorModel


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
    epsilon: float = 0.0, max_nodes: int = MAX_NODES,
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
    max_nodes : int
        Open prefixes a branch-and-bound keeps at most (the floor bounds the rest).

    Raises
    ------
    SearchConfigError
        Mismatched models, ``verify < 1``, or no verified design converged.
    """
    start = time.perf_counter()
    say = on_progress or (lambda text: None)
    _check_search(fe_model, chain, verify, margin, epsilon)
    # a preset path is drawn for the chain's actuator, for the FE alike
    objective = on_actuator(objective, chain.length, float(chain.table.tip_ref[1]))
    if chain.table.alphabet and isinstance(objective, ProfileTarget) and objective.length is None:
        # over a library the designs' lengths differ: L is that of the first type's actuator, for the chain
        # and the FE verifications alike
        objective = replace(objective, length=chain.length)
    scores, order, designs = _scored(chain, objective, margin, max_nodes, say, start)
    state = _Verification(ScoreBook(fe_model, objective, evaluator), designs, scores.optimistic[order],
                          1.0 if objective.sense == "min" else -1.0, np.zeros(len(designs), dtype=bool))
    _verify(state, fe_model, verify, certify, epsilon, max_verify, max_failures, say)
    book, verified = state.book, state.verified
    winner = min((book.candidate(d) for d in verified if not book.scores[d].failed),
                 key=lambda c: (state.sign * c.value, c.design))
    hof = tuple(chain_candidate(chain, objective, d) for d in designs[:hall_of_fame])
    winner_chain = next((c for c in hof if c.design == winner.design), None) or \
        chain_candidate(chain, objective, winner.design)
    certificate = _certificate(state, scores, float(scores.bound[order[designs.index(winner.design)]]), epsilon,
                               margin, objective.sense)
    if chain.table.axes == 3 and (planar := _planar_best(fe_model, chain, objective, margin, book, say)):
        certificate["planar"] = planar
    return CertifiedResult(winner, winner_chain, hof, {d: book.candidate(d) for d in verified}, certificate, scores,
                           solves=book.solves, wall_time=time.perf_counter() - start)


def _scored(chain: ChainModel, objective: Objective, margin: float, max_nodes: int, say: Callable[[str], None],
            start: float) -> tuple[ChainScores, np.ndarray, list[str]]:
    """Every design that can matter scored by the chain, their order and names, said with the most open prefixes a
    branch-and-bound kept at one depth (and, where they reached ``max_nodes``, the table's bound that left them)."""
    if not enumerable(chain, MAX_ENUMERATE):  # a branch-and-bound: a tip goal over sideways units takes a minute
        say(f"chain: scoring {designs_of(chain):,.0f} designs (branch-and-bound, at most {max_nodes:,} open "
            "prefixes) ...")
    with watching(OpenWatch(say, cap=max_nodes)) as watch:
        scores = chain_scores(chain, objective, margin, max_nodes=max_nodes)
    order = scores.order()
    designs = chain.table.texts(scores.bits[order])
    opened = f", at most {watch.peak:,} open prefixes at a depth" if watch.peak else ""
    say(f"chain: {len(designs):,} designs scored{'' if scores.complete else ' (branch-and-bound)'}{opened} in "
        f"{time.perf_counter() - start:.2f} s; best {designs[0]}")
    if watch.reached:
        say(cap_text(chain, margin, max_nodes))
    return scores, order, designs


def planar_codes(fe_model: ActuatorModel, chain: ChainModel) -> np.ndarray | None:
    """The unit codes of the types that bend in the plane, of a library with sideways ones too (else None)."""
    library = getattr(fe_model, "library", None)
    if library is None or library.is_single:
        return None
    flat = {2 * t + o for t, unit in enumerate(library.units) if not unit.layer_side for o in (0, 1)}
    codes = np.array([c for c in chain.table.unit_codes if int(c) in flat], dtype=np.uint8)
    return codes if 0 < len(codes) < len(chain.table.unit_codes) else None


def _planar_best(fe_model: ActuatorModel, chain: ChainModel, objective: Objective, margin: float, book: ScoreBook,
                 say: Callable[[str], None]) -> dict[str, Any] | None:
    """The best design without sideways units by the chain, verified by FE: what the plane alone can do (None for a
    library without both kinds)."""
    codes = planar_codes(fe_model, chain)
    if codes is None:
        return None
    scores = space_scores(chain, objective, margin, codes=codes)
    best = scores.order()[0]
    design = chain.table.texts(scores.bits[best : best + 1])[0]
    say(f"the best design that stays in the plane, by the chain: {design}; verifying it by FE ...")
    book.score_many([design])
    fe = book.scores[design]
    return {"design": design, "chain": float(scores.per_level[best, scores.level[best]]),
            "fe": None if fe.failed else float(fe.value), "designs_scored": len(scores.bits)}


def _check_search(fe_model: ActuatorModel, chain: ChainModel, verify: int, margin: float, epsilon: float) -> None:
    """Refuse mismatched models and settings out of range (:class:`SearchConfigError`)."""
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


@dataclass
class _Verification:
    """The FE verification's state: the designs in chain order, their optimistic costs (``sign * value``,
    lower is better), which are verified (``done``, and ``verified`` in the order solved)."""

    book: ScoreBook
    designs: list[str]
    optimistic: np.ndarray
    sign: float
    done: np.ndarray
    verified: list[str] = field(default_factory=list)

    def winner_cost(self) -> float:
        """The best cost of the converged verified designs (``inf`` while none converged)."""
        costs = [self.sign * self.book.scores[d].value for d in self.verified if not self.book.scores[d].failed]
        return min(costs) if costs else float("inf")


def _verify(state: _Verification, fe_model: ActuatorModel, verify: int, certify: bool, epsilon: float,
            max_verify: int, max_failures: int, say: Callable[[str], None]) -> None:
    """Verify designs by FE in chain order, ``verify`` at a time: until one converged, or with ``certify``
    until no unverified design can beat the winner by more than ``epsilon`` (or ``max_verify`` solves)."""
    book = state.book
    while True:
        best = state.winner_cost()
        if np.isfinite(best) and not certify:
            break  # one batch that converged
        pending = np.flatnonzero(~state.done & (state.optimistic < best - epsilon)) if np.isfinite(best) else \
            np.flatnonzero(~state.done)
        if not len(pending):
            break
        if len(state.verified) >= max_verify:
            say(f"stopped after {len(state.verified)} FE verifications (max_verify)")
            break
        if not np.isfinite(best) and len(state.verified) >= max_failures:
            failures = "; ".join(f"{d}: {book.outcomes[d].failure}" for d in state.verified[:2])
            raise SearchConfigError(f"the FE model did not converge for the chain's {len(state.verified)} best "
                                    f"designs ({failures}); check the model (units, pressure) with pneumorph simulate")
        batch = pending[:verify]
        todo = [state.designs[i] for i in batch]
        workers = evaluator_workers(book.evaluator)
        say(f"verifying {', '.join(todo)} by FE{solve_estimate(fe_model, len(todo), workers=workers)} ...")
        book.score_many(todo)
        state.done[batch] = True
        state.verified += todo
        say(f"verified {', '.join(todo)} by FE: " + ", ".join(f"{book.scores[d].value:.4g}" for d in todo))
    if not any(not book.scores[d].failed for d in state.verified):
        raise SearchConfigError("no design converged in the FE model")


def _certificate(state: _Verification, scores: ChainScores, bound: float, epsilon: float, margin: float,
                 sense: str) -> dict[str, Any]:
    """The certificate (:class:`CertifiedResult`) of the verified winner, whose bound is ``bound``."""
    best_cost = state.winner_cost()
    rest = state.optimistic[~state.done]
    could_beat = int((rest < best_cost - epsilon).sum())
    return {
        "bound": bound,
        "bound_worst": float(np.max(scores.bound)),
        "gap": max(0.0, best_cost - min(float(rest.min()) if len(rest) else float("inf"), scores.floor)),
        "could_beat": could_beat,
        "epsilon": epsilon,
        "tied": int(((rest < best_cost) & (rest >= best_cost - epsilon)).sum()),
        "certified": could_beat == 0 and not scores.floor < best_cost - epsilon,
        "verified": list(state.verified),
        "designs_scored": len(state.designs),
        "complete": scores.complete,
        "floor": None if scores.complete else state.sign * scores.floor,
        "margin": margin,
        "sense": sense,
    }


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

"""The chain's screen of a clearing goal: the designs whose free shape the chain proves to come too close to an
obstacle at the clearing pressure are rejected without an FE solve.

A contact goal with a clearance (:class:`~pneumorph.design.objectives.contact.Clearance`, ``[design.clear]``) asks
the actuator's outer surface to keep ``clearance_mm`` from every obstacle at the pressure ``p1``. The chain model
knows no contact, but it predicts the free shape (the unit centres and the tip at every level) within its validated
worst errors (:func:`~pneumorph.design.certified.bounds.chain_errors`, ``e`` at ``p1``, the larger of the centres'
and the tip's). Where a centre or the tip of the chain's shape at ``p1`` lies closer to an obstacle than
``clearance_mm - e`` (inside it: a negative gap), the FE free shape's point lies closer than ``clearance_mm``. That
point is the centre of a cavity or of the end face, so the segment from it to the obstacle meets the outer
surface, and a surface point is closer too. A design that clears touches nothing at ``p1``, so its state there is
the free one (the free ramp's equilibrium, for a frictionless finger with no other branch), which does not clear:
the design cannot clear, certified by the chain's bound. Every other design is solved by FE with contact, which
measures its clearance and its grip: those are searched, not certified.

The screen wraps the run's evaluator (:class:`ClearingScreen`) and answers a rejected design with a failed outcome
that says why; the run's solves and cache hits count FE answers only. It serves 2D models whose free actuator a
chain table serves (:func:`~pneumorph.models.chain.sources.serve_table`) and whose ramp has the clearing pressure
among the table's levels; without one, every design is solved by FE with contact, and the run says so.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pneumorph.design.certified.bounds import chain_errors
from pneumorph.design.certified.planning import serves
from pneumorph.design.objectives.contact import LEVEL_MATCH, ContactGoal
from pneumorph.execution.outcome import Outcome
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import serve_table


def chain_clearance(chain: ChainModel, design: str, level: int, obstacles: Iterable[Any]) -> float:
    """The least gap (mm) between the chain's free shape of ``design`` (its unit centres and tip) at ``level`` and
    the ``obstacles`` (:class:`~pneumorph.fem.fast.shapes.Obstacle`); negative inside one.

    >>> from pneumorph.fem.fast.shapes import Plane
    >>> from pneumorph.models.chain.sources import shipped_path
    >>> from pneumorph.models.chain.table import ChainTable
    >>> chain = ChainModel(ChainTable.load(shipped_path("2d")), 5)
    >>> round(chain_clearance(chain, "00000", 0, [Plane((0.0, 30.0), (0.0, -1.0))]), 2)  # a ceiling 30 mm up
    22.37
    """
    response = chain.evaluate(design)
    points = np.vstack([response.centres[level], response.tip[level][None]])
    return float(min(o.kinematics(points)[0].min() for o in obstacles))


@dataclass
class ClearingScreen:
    """An evaluator that rejects, without a solve, the designs the chain proves not to clear; ``inner`` answers the
    rest (and every other call).

    Attributes
    ----------
    inner : Evaluator
        The run's evaluator (its cache over the solver).
    chain : ChainModel
    level : int
        The clearing pressure's level among the chain's.
    error : float
        The chain's validated worst error at that level (mm).
    goal : ContactGoal
    obstacles : tuple
        The model's obstacles (:class:`~pneumorph.fem.fast.shapes.Obstacle`).
    rejected : dict
        Every design rejected so far, and why.
    """

    inner: Any
    chain: ChainModel
    level: int
    error: float
    goal: ContactGoal
    obstacles: tuple[Any, ...]
    rejected: dict[str, str] = field(default_factory=dict)

    def verdict(self, design: str) -> str | None:
        """Why ``design`` cannot clear (None: it may, FE decides)."""
        if design not in self.rejected:
            assert self.goal.clear is not None
            gap = chain_clearance(self.chain, design, self.level, self.obstacles)
            if gap < self.goal.clear.distance - self.error:
                clear = self.goal.clear
                self.rejected[design] = (f"does not clear at {clear.pressure * 1e3:g} kPa: the chain's free shape "
                                         f"comes to {gap:.3g} mm of an obstacle (error bound {self.error:.3g} mm, "
                                         f"clearance {clear.distance:g} mm); not solved")
        return self.rejected.get(design)

    def iter_evaluate(self, model: Any, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]:
        designs = list(designs)
        keep = [i for i, d in enumerate(designs) if self.verdict(d) is None]
        kept = set(keep)
        for i, d in enumerate(designs):
            if i not in kept:
                yield i, Outcome(d, None, failure=self.rejected[d], screened=True)
        if keep:
            for j, outcome in self.inner.iter_evaluate(model, [designs[i] for i in keep]):
                yield keep[j], outcome

    def evaluate_many(self, model: Any, designs: Iterable[str]) -> list[Outcome]:
        designs = list(designs)
        out: list[Any] = [None] * len(designs)
        for i, outcome in self.iter_evaluate(model, designs):
            out[i] = outcome
        return out

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


def clearing_screen(evaluator: Any, model: Any, goal: Any, table_dir: Any = None,
                    margin: float = 1.0) -> tuple[Any, str]:
    """``evaluator`` screened by the chain for a clearing ``goal`` on ``model`` (:class:`ClearingScreen`), and a
    line that says how; ``evaluator`` itself (and why, or ``""`` for a goal without a clearance) where no chain
    serves.

    ``table_dir`` is where kept chain tables are looked for besides the shipped ones; ``margin`` multiplies the
    chain's validated errors (:func:`~pneumorph.design.certified.bounds.chain_errors`).
    """
    if not isinstance(goal, ContactGoal) or goal.clear is None:
        return evaluator, ""
    fe = "every design is solved by FE with contact"
    if getattr(model, "fidelity", None) != "2d":
        return evaluator, f"clearing: no chain screen off the 2D model; {fe}"
    n = int(model.n_units)
    served = serve_table(model.variant(obstacles=()), table_dir)
    if served is None or not serves(served.table, n):
        return evaluator, f"clearing: no chain table serves {n} free units of this model; {fe}"
    chain = ChainModel(served.table, n)
    p = chain.pressures()
    near = np.flatnonzero(np.abs(p - goal.clear.pressure) <= LEVEL_MATCH * goal.clear.pressure)
    if not near.size:
        return evaluator, (f"clearing: {goal.clear.pressure * 1e3:g} kPa is not a level of the chain table; {fe}")
    level = int(near[0])
    errors = chain_errors(chain, margin)
    error = float(max(errors["centre"][level], errors["tip"][level]))
    screen = ClearingScreen(evaluator, chain, level, error, goal, tuple(o.obstacle for o in model.obstacles))
    return screen, (f"clearing: a design whose free shape by the chain comes closer to an obstacle at "
                    f"{goal.clear.pressure * 1e3:g} kPa than {goal.clear.distance:g} mm less the chain's error "
                    f"({error:.3g} mm) is rejected without a solve (certified); FE with contact solves the rest")


__all__ = ["ClearingScreen", "chain_clearance", "clearing_screen"]

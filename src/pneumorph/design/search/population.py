"""Population-size study of the GA (section 6.1, Fig 6.1).

For each population size the same objective is optimised from several seeds (different
initial populations) for a fixed number of generations; the spread of the final best
fitness (lowest, largest, mean over the seeds) shows whether the population holds enough
genetic diversity. The dissertation used populations 20, 40, 60 and 80, five seeds and 25
generations. Runs share the evaluator, so with a cache no design is solved twice.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path

import numpy as np

from pneumorph.design.objectives.targets import Objective
from pneumorph.design.search.genetic import GAConfig, GAResult, GenerationStats, run_ga
from pneumorph.errors import SearchConfigError
from pneumorph.execution.evaluators import Evaluator
from pneumorph.models.response import ActuatorModel


@dataclass(frozen=True)
class StudyRow:
    """One population size.

    Attributes
    ----------
    population : int
    best : tuple of float
        Best fitness found by each seed.
    designs : tuple of str
        The best design of each seed.
    converged_at : tuple of int
        First generation at which each seed had found its final best.
    evaluations : tuple of int
        Distinct designs evaluated by each seed.
    """

    population: int
    seeds: tuple[int, ...]
    best: tuple[float, ...]
    designs: tuple[str, ...]
    converged_at: tuple[int, ...]
    evaluations: tuple[int, ...]
    sense: str = "min"

    @property
    def lowest(self) -> float:
        return float(np.min(self.best))

    @property
    def largest(self) -> float:
        return float(np.max(self.best))

    @property
    def mean(self) -> float:
        return float(np.mean(self.best))

    def as_dict(self) -> dict[str, object]:
        return {
            "population": self.population,
            "lowest": self.lowest,
            "largest": self.largest,
            "mean": self.mean,
            "best": list(self.best),
            "designs": list(self.designs),
            "converged_at": list(self.converged_at),
            "evaluations": list(self.evaluations),
        }


@dataclass(frozen=True)
class PopulationStudy:
    """All population sizes of a study."""

    rows: tuple[StudyRow, ...]
    generations: int
    objective: str
    unit: str


def _converged_at(result: GAResult) -> int:
    best = [h.best for h in result.history]
    running = np.minimum.accumulate(best) if result.sense == "min" else np.maximum.accumulate(best)
    return int(np.flatnonzero(running == running[-1])[0])


def population_study(
    model: ActuatorModel,
    objective: Objective,
    populations: Sequence[int] = (20, 40, 60, 80),
    seeds: Sequence[int] = (0, 1, 2, 3, 4),
    generations: int = 25,
    base: GAConfig | None = None,
    evaluator: Evaluator | None = None,
    on_run: Callable[[int, int, GAResult], None] | None = None,
    on_generation: Callable[[int, int, GenerationStats], None] | None = None,
    on_message: Callable[[str], None] | None = None,
) -> PopulationStudy:
    """Run the GA for every population size and seed; summarise the best fitness.

    Parameters
    ----------
    model, objective
        As for :func:`~pneumorph.design.search.genetic.run_ga`.
    populations, seeds : sequences of int
        The grid (section 6.1: 20/40/60/80 and five seeds).
    generations : int
        Generations per run (section 6.1: 25).
    base : GAConfig, optional
        The other GA settings (defaults otherwise).
    evaluator : Evaluator, optional
        Shared by all runs (use a cached evaluator to solve each design once).
    on_run : callable, optional
        Called with (population, seed, result) after each run.
    on_generation : callable, optional
        Called with (population, seed, stats) after each generation of each run
        (:class:`~pneumorph.design.search.genetic.GenerationStats`).
    on_message : callable, optional
        Called with a line of text before each run's generation 0 is evaluated
        (:func:`~pneumorph.design.search.genetic.run_ga`).

    Returns
    -------
    PopulationStudy
    """
    if not populations or not seeds:
        raise SearchConfigError("the study needs at least one population size and one seed")
    base = base or GAConfig()
    rows = []
    for pop in populations:
        results = []
        for seed in seeds:
            config = replace(base, population=int(pop), generations=int(generations), seed=int(seed))
            step = None if on_generation is None else partial(on_generation, int(pop), int(seed))
            res = run_ga(model, objective, config, evaluator, step, on_message=on_message)
            results.append(res)
            if on_run:
                on_run(int(pop), int(seed), res)
        rows.append(
            StudyRow(
                int(pop),
                tuple(int(s) for s in seeds),
                tuple(r.best.value for r in results),
                tuple(r.best.design for r in results),
                tuple(_converged_at(r) for r in results),
                tuple(len(r.scores) for r in results),
                objective.sense,
            )
        )
    return PopulationStudy(tuple(rows), int(generations), objective.label, objective.unit)


def plot_population_study(result: PopulationStudy, path: str | Path) -> Path:
    """Lowest, largest and mean best fitness against the population size (Fig 6.1)."""
    from pneumorph.plot.figure import new_figure, save_figure

    pops = [r.population for r in result.rows]
    fig = new_figure(5.6, 3.8, layout="tight")
    ax = fig.add_subplot()
    ax.plot(pops, [r.lowest for r in result.rows], "v-", label="Lowest")
    ax.plot(pops, [r.largest for r in result.rows], "^-", label="Largest")
    ax.plot(pops, [r.mean for r in result.rows], "o--", label="Mean")
    ax.set_xlabel("population size")
    ax.set_ylabel(f"best objective value ({result.unit})")
    ax.set_title(f"{result.generations} generations, {len(result.rows[0].seeds)} seeds", fontsize=9)
    ax.set_xticks(pops)
    ax.legend()
    ax.grid(alpha=0.3)
    return save_figure(fig, path)

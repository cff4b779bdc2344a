"""Genetic algorithm over orientation vectors: DEAP's ``eaSimple`` (section 4.5).

Over a unit library of several types (``docs/unit-library.md``) a gene is a unit code,
type ``t`` in orientation ``o`` being ``2t + o``, mutated to another code at random; over
one type it is the 0/1 orientation, flipped, as in the dissertation.

This is the only module that touches DEAP's global ``creator``. The generational loop
follows ``deap.algorithms.eaSimple`` step for step (tournament selection, ``varAnd`` with
two-point crossover and bit-flip mutation, evaluation of the individuals whose fitness was
invalidated, generational replacement), with the same operators drawing from a private
``random.Random(seed)``: DEAP's draw from the global :mod:`random` module, which other code
(a Dask scheduler thread, a plotting library) may also draw from. Two additions, both on by
default and both off in plain ``eaSimple``: elitism (the best design is kept) and distinct
offspring (an offspring that repeats a design of its parents' population or another
offspring is mutated again until it differs, as pymoo eliminates duplicates), so that a
small population does not spend its generations on copies of itself. With ``elitism = 0``
and ``distinct = False`` a run reproduces ``eaSimple`` exactly when ``eaSimple`` is given a
global ``random`` seeded with the same seed (tested).

A whole generation is evaluated as one batch through an evaluator, so the solves can run
in parallel; designs seen before in the run are not sent again.
"""

from __future__ import annotations

import math
import random
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np
from deap import base, creator, tools

from pneumorph import checks
from pneumorph.design.objectives.fitness import Score
from pneumorph.design.objectives.targets import Objective, Sense
from pneumorph.design.search.scoring import Candidate, ScoreBook
from pneumorph.errors import SearchConfigError
from pneumorph.execution.evaluators import Evaluator
from pneumorph.models.chain.windows import canonical_codes, design_strings
from pneumorph.models.response import ActuatorModel

_FITNESS = {"min": "PneumorphFitnessMin", "max": "PneumorphFitnessMax"}
_INDIVIDUAL = {"min": "PneumorphIndividualMin", "max": "PneumorphIndividualMax"}
for _sense, _weight in (("min", -1.0), ("max", 1.0)):
    if not hasattr(creator, _FITNESS[_sense]):
        creator.create(_FITNESS[_sense], base.Fitness, weights=(_weight,))
    if not hasattr(creator, _INDIVIDUAL[_sense]):
        creator.create(_INDIVIDUAL[_sense], list, fitness=getattr(creator, _FITNESS[_sense]))

# the settings' checks, raising the search's own error
_integer = partial(checks.integer, error=SearchConfigError)
_real = partial(checks.real, error=SearchConfigError)


@dataclass(frozen=True)
class GAConfig:
    """Settings of the genetic algorithm.

    Defaults: population 100 and 15 generations (section 6.1). The dissertation does not
    give the operator probabilities. Here every offspring is mutated (``mutpb = 1``) with a
    per-unit rate of ``1 / n`` for ``n`` units (``indpb = None``), one changed unit per
    offspring on average, the textbook rate for bit strings; the best design is kept
    (``elitism = 1``) and offspring differ from their parents' population and each other. With
    these defaults, population 12 and 6 generations find the optimum of a 6-unit design in
    at least 4 of 5 seeds for each of five targets (``tests/design/test_ga_defaults.py``;
    against random search and the exhaustive optimum at 6-10 units: ``BENCHMARKS.md``,
    ``benchmarks/ga_defaults.py``). DEAP's example values for ``eaSimple`` (``mutpb = 0.2``,
    ``indpb = 0.05``, no elitism, repeats allowed) found it in 1 to 4 of 5 seeds.

    Attributes
    ----------
    population, generations : int
    cxpb, mutpb : float
        Probability that a pair is crossed over / an individual is mutated.
    indpb : float or None
        Probability that a mutated individual's unit changes; None for ``1 / n`` with ``n``
        the model's number of units.
    tournsize : int
        Individuals per selection tournament.
    elitism : int
        Best distinct individuals carried into the next generation (0 = plain eaSimple).
    distinct : bool
        Mutate an offspring again (up to :data:`RENEW_TRIES` times) while it repeats a design
        of the parents' population or another offspring (False = plain eaSimple). Repeats
        cost no solve, so a run with a ``budget`` of solves and many generations may do better
        with False (``BENCHMARKS.md``).
    hall_of_fame : int
        Number of distinct best designs kept.
    seed : int
        Seed of the private random generator.
    budget : int or None
        Most distinct designs evaluated in the run (solved or taken from the cache). The run
        stops before a generation that would exceed it, so all finished generations are
        plain eaSimple generations and a resumed run stops at the same place.

    Examples
    --------
    >>> GAConfig(population=1)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: [ga] population must be a whole number >= 2 and <= 10000, got 1
    """

    population: int = 100
    generations: int = 15
    cxpb: float = 0.5
    mutpb: float = 1.0
    indpb: float | None = None
    tournsize: int = 3
    elitism: int = 1
    hall_of_fame: int = 10
    seed: int = 0
    budget: int | None = None
    distinct: bool = True

    def __post_init__(self) -> None:
        _integer(self.population, "[ga] population", 2, checks.MAX_POPULATION, limit="MAX_POPULATION")
        _integer(self.generations, "[ga] generations", 0, checks.MAX_GENERATIONS, limit="MAX_GENERATIONS")
        for name in ("cxpb", "mutpb"):
            _real(getattr(self, name), f"[ga] {name}", 0.0, 1.0)
        if self.indpb is not None:
            _real(self.indpb, "[ga] indpb", 0.0, 1.0)
        checks.flag(self.distinct, "[ga] distinct", error=SearchConfigError)
        _integer(self.tournsize, "[ga] tournsize", 1, checks.MAX_POPULATION)
        _integer(self.elitism, "[ga] elitism", 0)
        _integer(self.hall_of_fame, "[ga] hall_of_fame", 1, checks.MAX_POPULATION)
        _integer(self.seed, "[design] seed", 0, 2**32 - 1)
        if self.budget is not None:
            _integer(self.budget, "[ga] budget", 1)
        if not 0 <= self.elitism < self.population:
            raise SearchConfigError(
                f"[ga] elitism must be between 0 and population - 1 = {self.population - 1}, got {self.elitism}"
            )
        if self.budget is not None and self.budget < self.population:
            raise SearchConfigError(
                f"[ga] budget of {self.budget} designs does not cover the initial population of {self.population}"
            )


@dataclass(frozen=True)
class GenerationStats:
    """Statistics of one generation's population (finite fitness values only).

    ``evaluations`` = individuals whose fitness was computed (eaSimple's ``nevals``) =
    ``solves`` (new model solves) + ``cache_hits`` (answered by the evaluation cache, the
    same count as :attr:`CachedEvaluator.hits <pneumorph.execution.CachedEvaluator>` and a
    run's ``cache_hits``, so a run's hits are the sum of its generations') + ``repeats``
    (designs this run had scored before, or twice in the generation: not asked of the
    evaluator at all); ``failures`` = individuals with a failed solve.
    """

    generation: int
    best: float
    mean: float
    worst: float
    std: float
    evaluations: int
    cache_hits: int
    solves: int
    failures: int
    wall_time: float
    best_design: str
    repeats: int = 0

    def as_row(self) -> dict[str, object]:
        return dict(self.__dict__)

    def describe(self, unit: str = "") -> str:
        """One progress line: fitness statistics (in the objective's ``unit``), where the evaluations came from,
        wall time.

        Examples
        --------
        >>> GenerationStats(3, 1.5, 2.25, 4.0, 0.5, 10, 2, 5, 0, 12.34, "0101", repeats=3).describe("mm")
        'best 1.5 mm  mean 2.25 mm  10 evaluated: 5 solved, 2 cache hits, 3 repeats  12.3 s'
        """
        u = f" {unit}" if unit else ""
        return (f"best {self.best:.4g}{u}  mean {self.mean:.4g}{u}  {self.evaluations} evaluated: {self.solves} "
                f"solved, {self.cache_hits} cache hits, {self.repeats} repeats  {self.wall_time:.1f} s")


@dataclass(frozen=True)
class GAResult:
    """What a GA run found.

    Attributes
    ----------
    config : GAConfig
    sense : {"min", "max"}
    history : tuple of GenerationStats
        Generation 0 (the initial population) to the last.
    hall_of_fame : tuple of Candidate
        The best distinct designs, best first.
    population : tuple of str
        The final population.
    stopped : str
        ``"generations"`` or ``"budget"``: why the run ended.
    solves : int
        New model solves in this run (cache hits excluded).
    scores : dict
        Every design evaluated in the run and its score.
    """

    config: GAConfig
    sense: Sense
    history: tuple[GenerationStats, ...]
    hall_of_fame: tuple[Candidate, ...]
    population: tuple[str, ...]
    solves: int
    scores: dict[str, Score] = field(repr=False)
    stopped: str = "generations"

    @property
    def best(self) -> Candidate:
        return self.hall_of_fame[0]


# -- operators with a private generator (same algorithms as deap.tools) -----------------
def cx_two_point(ind1: list[int], ind2: list[int], rng: random.Random) -> tuple[list[int], list[int]]:
    """Two-point crossover in place, as ``deap.tools.cxTwoPoint``."""
    size = min(len(ind1), len(ind2))
    if size < 2:
        return ind1, ind2
    c1 = rng.randint(1, size)
    c2 = rng.randint(1, size - 1)
    if c2 >= c1:
        c2 += 1
    else:
        c1, c2 = c2, c1
    ind1[c1:c2], ind2[c1:c2] = ind2[c1:c2], ind1[c1:c2]
    return ind1, ind2


def mut_flip_bit(individual: list[int], indpb: float, rng: random.Random) -> tuple[list[int]]:
    """Flip each unit with probability ``indpb``, as ``deap.tools.mutFlipBit``."""
    for i in range(len(individual)):
        if rng.random() < indpb:
            individual[i] = type(individual[i])(not individual[i])
    return (individual,)


def mut_other_code(individual: list[int], indpb: float, codes: int, rng: random.Random) -> tuple[list[int]]:
    """Give each unit, with probability ``indpb``, another of the ``codes`` unit codes (each equally likely).

    Over two codes this is :func:`mut_flip_bit` (the only other code is the flipped one); over a unit
    library of ``k`` types there are ``2k`` codes, type ``t`` in orientation ``o`` being ``2t + o``.

    >>> mut_other_code([0, 3, 5], 1.0, 6, random.Random(1))[0] != [0, 3, 5]
    True
    """
    for i in range(len(individual)):
        if rng.random() < indpb:
            other = rng.randrange(codes - 1)
            individual[i] = other + (other >= individual[i])
    return (individual,)


def sel_tournament(individuals: Sequence[Any], k: int, tournsize: int, rng: random.Random) -> list[Any]:
    """``k`` tournaments of ``tournsize`` random picks, as ``deap.tools.selTournament``."""
    return [max((rng.choice(individuals) for _ in range(tournsize)), key=lambda ind: ind.fitness) for _ in range(k)]


def var_and(population: Sequence[Any], toolbox: base.Toolbox, cxpb: float, mutpb: float,
            rng: random.Random) -> list[Any]:
    """Crossover then mutation on clones, as ``deap.algorithms.varAnd``."""
    offspring = [toolbox.clone(ind) for ind in population]
    for i in range(1, len(offspring), 2):
        if rng.random() < cxpb:
            offspring[i - 1], offspring[i] = toolbox.mate(offspring[i - 1], offspring[i])
            del offspring[i - 1].fitness.values, offspring[i].fitness.values
    for i in range(len(offspring)):
        if rng.random() < mutpb:
            (offspring[i],) = toolbox.mutate(offspring[i])
            del offspring[i].fitness.values
    return offspring


def make_toolbox(n_units: int, sense: Sense, config: GAConfig, rng: random.Random, codes: int = 2) -> base.Toolbox:
    """A DEAP toolbox whose random operators all draw from ``rng``; genes are unit codes ``0 .. codes - 1``
    (0/1 orientations, or ``2t + o`` over a unit library of several types).

    A ``config.indpb`` of None is ``1 / n_units``.
    """
    indpb = config.indpb if config.indpb is not None else 1.0 / max(n_units, 1)
    toolbox = base.Toolbox()
    toolbox.register("attr_code", rng.randint, 0, codes - 1)
    toolbox.register("individual", tools.initRepeat, getattr(creator, _INDIVIDUAL[sense]), toolbox.attr_code, n_units)
    toolbox.register("population", tools.initRepeat, list, toolbox.individual)
    toolbox.register("mate", cx_two_point, rng=rng)
    if codes == 2:  # eaSimple's bit flip, draw for draw
        toolbox.register("mutate", mut_flip_bit, indpb=indpb, rng=rng)
    else:
        toolbox.register("mutate", mut_other_code, indpb=indpb, codes=codes, rng=rng)
    toolbox.register("select", sel_tournament, tournsize=config.tournsize, rng=rng)
    return toolbox


def _design(ind: Sequence[int], symbols: Sequence[str] = (), symmetric: Sequence[int] = ()) -> str:
    """A genome as design text: 0/1 digits, or over a library's ``symbols`` the letter of the type,
    upper case for orientation 1 (code ``2t + o``), as the chain tables write designs; a turned-over
    unit of a ``symmetric`` type (indices) is the unit itself, written in lower case."""
    return design_strings(np.asarray(canonical_codes(np.asarray([ind], dtype=np.uint8), symmetric)), symbols)[0]


def _stats(gen: int, population: Sequence[Any], book: ScoreBook, counts: tuple[int, int, int, int],
           wall: float, symbols: Sequence[str] = (), symmetric: Sequence[int] = ()) -> GenerationStats:
    values = np.array([ind.fitness.values[0] for ind in population], dtype=float)
    finite = values[np.isfinite(values)]
    best_ind = max(population, key=lambda ind: ind.fitness)
    if finite.size:
        best, worst_ = (finite.min(), finite.max()) if book.sense == "min" else (finite.max(), finite.min())
        mean, std = float(finite.mean()), float(finite.std())
    else:
        best = worst_ = mean = std = math.nan
    evaluations, hits, solves, repeats = counts
    return GenerationStats(
        gen, float(best), mean, float(worst_), std, evaluations, hits, solves, int(values.size - finite.size), wall,
        _design(best_ind, symbols, symmetric), repeats
    )


def _evaluate(population: Sequence[Any], book: ScoreBook, symbols: Sequence[str] = (),
              symmetric: Sequence[int] = ()) -> tuple[int, int, int, int]:
    """Score the individuals whose fitness is invalid: (evaluations, cache hits, solves, repeats)."""
    invalid = [ind for ind in population if not ind.fitness.valid]
    solves, hits = book.solves, book.hits
    scores = book.score_many([_design(ind, symbols, symmetric) for ind in invalid])
    for ind, s in zip(invalid, scores, strict=True):
        ind.fitness.values = (s.value,)
    solves, hits = book.solves - solves, book.hits - hits
    return len(invalid), hits, solves, len(invalid) - hits - solves


def run_ga(
    model: ActuatorModel,
    objective: Objective,
    config: GAConfig = GAConfig(),
    evaluator: Evaluator | None = None,
    on_generation: Callable[[GenerationStats], None] | None = None,
    on_message: Callable[[str], None] | None = None,
) -> GAResult:
    """Search the orientation vectors of ``model`` for the best fitness with eaSimple.

    Parameters
    ----------
    model : ActuatorModel
        Gives ``n_units`` and evaluates designs.
    objective : ProfileTarget or TipGoal
        What to minimise or maximise.
    config : GAConfig
    evaluator : Evaluator, optional
        How designs are solved (serial by default); wrap it in a
        :class:`~pneumorph.execution.CachedEvaluator` to persist the solves.
    on_generation : callable, optional
        Called with each generation's :class:`GenerationStats` as soon as it is known.
    on_message : callable, optional
        Called with a line of text before generation 0 is evaluated (its designs and the
        expected solve time), so that the longest wait of a run is announced.

    Returns
    -------
    GAResult

    Raises
    ------
    SearchConfigError
        A model with fewer than 1 unit.
    """
    book = ScoreBook(model, objective, evaluator)
    rng = random.Random(config.seed)
    library = getattr(model, "library", None)  # the FE models' unit library; designs over several types
    run = _Run(book, library.alphabet if library is not None else (),
               library.symmetric_types if library is not None else (), on_generation)
    toolbox = make_toolbox(model.n_units, objective.sense, config, rng, codes=2 * max(len(run.symbols), 1))

    start = time.perf_counter()
    population = toolbox.population(n=config.population)
    if on_message:  # the FE verification's estimate of a solve (pneumorph.design.certified.search)
        from pneumorph.models.chain.plan import solve_estimate

        distinct = len({run.design(ind) for ind in population})
        on_message(f"evaluating generation 0: {distinct} designs{solve_estimate(model, distinct)} ...")
    run.record(0, population, run.evaluate(population), start)
    stopped = "generations"
    for gen in range(1, config.generations + 1):
        start = time.perf_counter()
        offspring = _offspring(population, toolbox, config, rng, run)
        if config.budget is not None and run.over_budget(offspring, config.budget):
            stopped = "budget"
            break
        counts = run.evaluate(offspring)
        if config.elitism:
            _keep_elites(population, offspring, config.elitism, toolbox)
        population[:] = offspring
        run.record(gen, population, counts, start)
    return GAResult(config, objective.sense, tuple(run.history), book.hall_of_fame(config.hall_of_fame),
                    tuple(run.design(ind) for ind in population), book.solves, dict(book.scores), stopped)


@dataclass
class _Run:
    """A run's shared state: its score book, the library's letters, the generations so far."""

    book: ScoreBook
    symbols: tuple[str, ...]
    symmetric: Sequence[int]
    on_generation: Callable[[GenerationStats], None] | None
    history: list[GenerationStats] = field(default_factory=list)

    def design(self, ind: Sequence[int]) -> str:
        return _design(ind, self.symbols, self.symmetric)

    def evaluate(self, population: Sequence[Any]) -> tuple[int, int, int, int]:
        return _evaluate(population, self.book, self.symbols, self.symmetric)

    def record(self, gen: int, population: Sequence[Any], counts: tuple[int, int, int, int], start: float) -> None:
        """Keep generation ``gen``'s statistics (its time since ``start``) and report them."""
        wall = time.perf_counter() - start
        self.history.append(_stats(gen, population, self.book, counts, wall, self.symbols, self.symmetric))
        if self.on_generation:
            self.on_generation(self.history[-1])

    def over_budget(self, offspring: Sequence[Any], budget: int) -> bool:
        """Whether the offspring's new designs take the run past ``budget`` distinct designs."""
        new = {self.design(ind) for ind in offspring if not ind.fitness.valid} - self.book.scores.keys()
        return len(self.book.scores) + len(new) > budget


def _offspring(population: list[Any], toolbox: base.Toolbox, config: GAConfig, rng: random.Random,
               run: _Run) -> list[Any]:
    """One generation's offspring: selected, crossed over and mutated (``varAnd``), repeats mutated again."""
    offspring = var_and(toolbox.select(population, len(population)), toolbox, config.cxpb, config.mutpb, rng)
    if config.distinct:
        _renew_repeats(offspring, [run.design(ind) for ind in population], toolbox, run.symbols, run.symmetric)
    return offspring


#: Most extra mutations of an offspring that repeats a design of its generation (``GAConfig.distinct``);
#: past them it stays a repeat.
RENEW_TRIES = 20


def _renew_repeats(offspring: list[Any], known: Iterable[str], toolbox: base.Toolbox,
                   symbols: Sequence[str] = (), symmetric: Sequence[int] = ()) -> None:
    """Mutate again each offspring to be evaluated while it repeats a ``known`` design (the
    parents') or another offspring."""
    taken = set(known)
    for ind in offspring:
        if ind.fitness.valid:  # an unchanged copy of its parent: nothing to evaluate
            continue
        design = _design(ind, symbols, symmetric)
        for _ in range(RENEW_TRIES):
            if design not in taken:
                break
            toolbox.mutate(ind)
            design = _design(ind, symbols, symmetric)
        taken.add(design)


def _keep_elites(population: list[Any], offspring: list[Any], k: int, toolbox: base.Toolbox) -> None:
    """Replace the ``k`` worst offspring by the ``k`` best distinct parents (no random draws)."""
    elites, seen = [], set()
    for ind in sorted(population, key=lambda ind: ind.fitness, reverse=True):
        if tuple(ind) not in seen:
            seen.add(tuple(ind))
            elites.append(toolbox.clone(ind))
        if len(elites) == k:
            break
    worst_first = sorted(range(len(offspring)), key=lambda i: offspring[i].fitness)
    for i, elite in zip(worst_first, elites, strict=False):
        if elite.fitness > offspring[i].fitness:
            offspring[i] = elite

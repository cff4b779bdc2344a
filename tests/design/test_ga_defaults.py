"""The GA's default operators find optima (the fallback search must be good where it is used).

Designs are scored by the 2D model's shipped chain table, so every design of 6 or 8 units is
known at once; ``benchmarks/ga_defaults.py`` measures the same at 6-10 units and more seeds
(``BENCHMARKS.md``).
"""

from __future__ import annotations

import pytest

from pneumorph.design import GAConfig, make_objective, run_exhaustive, run_ga
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.models import ChainModel, ChainTable
from pneumorph.models.chain.sources import shipped_path
from tests.benchmark import load

# the benchmark's targets and its notion of a find, loaded from its file (benchmarks/ is no package)
bench = load("ga_defaults")
TARGETS, chance, found = bench.TARGETS, bench.chance, bench.found


@pytest.fixture(scope="module")
def table() -> ChainTable:
    return ChainTable.load(shipped_path("2d"))


def searches(table: ChainTable, units: int, seeds: range) -> dict[str, tuple[list[bool], float]]:
    """For each target: whether the GA (defaults, population 12, 6 generations) found the
    exhaustive optimum from each seed, and how many of those runs random search over as many
    distinct designs is expected to win."""
    model = ChainModel(table, units)
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    out = {}
    for label, (spec, kw) in TARGETS.items():
        objective = make_objective(spec, **kw)
        exhaustive = run_exhaustive(model, objective, evaluator)
        values = {d: s.value for d, s in exhaustive.scores.items()}
        finds, expected = [], 0.0
        for seed in seeds:
            ga = run_ga(model, objective, GAConfig(population=12, generations=6, seed=seed), evaluator)
            finds.append(found(ga.best.value, exhaustive.best.value))
            expected += chance(values, exhaustive.best.value, len(ga.scores))
        out[label] = (finds, expected)
    return out


def test_the_default_ga_finds_the_optimum_of_6_units_in_4_of_5_seeds_for_each_of_5_targets(table) -> None:
    results = searches(table, 6, range(5))
    assert len(results) == 5
    for label, (finds, _) in results.items():
        assert sum(finds) >= 4, f"{label}: the GA found the optimum in {sum(finds)} of 5 seeds"


def test_the_default_ga_beats_random_search_where_it_cannot_list_the_space(table) -> None:
    # 8 units: 256 designs, of which a run of population 12 and 6 generations evaluates at most 84
    results = searches(table, 8, range(10))
    ga = sum(sum(finds) for finds, _ in results.values())
    random = sum(expected for _, expected in results.values())
    assert ga >= 1.5 * random, f"GA {ga} finds of 50, random search {random:.1f} expected"

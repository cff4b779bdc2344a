"""Exhaustive search (with and without mirror symmetry) and the genetic algorithm."""

from __future__ import annotations

import random

import numpy as np
import pytest
from deap import algorithms, base, creator, tools

from pneumorph.design.objectives.fitness import score
from pneumorph.design.objectives.targets import make_objective
from pneumorph.design.search.exhaustive import mirror_response, run_exhaustive
from pneumorph.design.search.genetic import _INDIVIDUAL, GAConfig, run_ga
from pneumorph.errors import SearchConfigError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.orientation import mirror

from .toy_model import ToyModel

OBJECTIVES = {
    "sin": {"spec": "sin", "amplitude": 10.0},
    "cos": {"spec": "cos", "amplitude": 10.0},
    "min-distance": {"spec": "min-distance"},
    "max-y": {"spec": "max-y"},
    "min-x": {"spec": "min-x"},
    "max-curl": {"spec": "max-curl"},
    "reach": {"spec": "reach", "point": (30.0, 40.0)},
    "polar": {"spec": "r = 20 + 10*theta"},
}


def objective(name: str):
    kw = dict(OBJECTIVES[name])
    return make_objective(kw.pop("spec"), **kw)


@pytest.fixture(scope="module")
def model() -> ToyModel:
    return ToyModel(n_units=8)


@pytest.fixture(scope="module")
def evaluator() -> CachedEvaluator:
    """Every toy design solved once for the whole module."""
    return CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))


@pytest.fixture(scope="module")
def brute(model: ToyModel, evaluator: CachedEvaluator) -> dict[str, object]:
    """All 256 responses, solved directly."""
    designs = [format(i, "08b") for i in range(256)]
    return {o.design: o.response for o in evaluator.evaluate_many(model, designs)}


def test_mirror_response_is_what_the_model_gives_for_the_mirrored_design(model: ToyModel) -> None:
    a, b = model.evaluate("00101101"), model.evaluate(mirror("00101101"))
    m = mirror_response(a)
    assert m.orientation == b.orientation
    for name in ("centres", "reference_centres", "tip", "reference_tip", "curl"):
        np.testing.assert_allclose(getattr(m, name), getattr(b, name), atol=1e-12)


@pytest.mark.parametrize("name", list(OBJECTIVES))
def test_exhaustive_with_symmetry_equals_brute_force(name: str, model, evaluator, brute) -> None:
    obj = objective(name)
    direct = {d: score(r, obj) for d, r in brute.items()}
    before = evaluator.solves
    result = run_exhaustive(model, obj, evaluator, symmetry=True)
    assert evaluator.solves == before  # everything came from the cache filled by brute force
    assert result.n_designs == 256 and len(result.scores) == 256
    for d, s in direct.items():
        assert result.scores[d].value == pytest.approx(s.value, rel=1e-12, abs=1e-12), d
        assert result.scores[d].level == s.level, d
    best = min(direct.values(), key=lambda s: s.value if obj.sense == "min" else -s.value).value
    assert result.best.value == pytest.approx(best, rel=1e-12, abs=1e-12)
    assert direct[result.best.design].value == pytest.approx(best, rel=1e-12, abs=1e-12)


def test_symmetry_halves_the_solves(model: ToyModel) -> None:
    obj = objective("sin")
    progress = []
    half = run_exhaustive(
        model, obj, CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:")), batch_size=32,
        on_progress=lambda done, total: progress.append((done, total)),
    )
    assert progress[0] == (0, 256)  # said before the first solve
    assert progress[-1] == (256, 256) and progress == sorted(progress)
    assert len(progress) == 1 + 127 + 4  # as each of the other 127 solves finishes (with its mirror), and per batch
    full = run_exhaustive(model, obj, CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:")), symmetry=False)
    assert (half.solves, full.solves) == (129, 256)  # 128 + one mirror solved to verify the symmetry
    assert half.ranking == full.ranking


class LopsidedToy(ToyModel):
    """Orientation-1 units turn 10 % less: not mirror-symmetric."""

    def _turns(self, bits, p):
        return super()._turns(bits, p) * np.where(bits == 1, 0.9, 1.0)


def test_an_asymmetric_model_is_caught_before_symmetry_is_used() -> None:
    with pytest.raises(SearchConfigError, match="not mirror-symmetric"):
        run_exhaustive(LopsidedToy(n_units=6), objective("sin"))
    assert run_exhaustive(LopsidedToy(n_units=6), objective("sin"), symmetry=False).n_designs == 64


def test_failed_designs_rank_last_and_do_not_crash(model: ToyModel) -> None:
    bad = ToyModel(n_units=4, fail={"0000", "1111", "0110"})
    result = run_exhaustive(bad, objective("max-curl"), symmetry=False)
    assert [d for d in result.ranking[-3:]] == ["0000", "0110", "1111"]
    assert all(result.scores[d].failed for d in ("0000", "1111", "0110"))
    obj = objective("max-curl")
    usable = {d: score(bad.evaluate(d), obj).value for d in result.ranking if d not in bad.fail}
    assert result.best.value == max(usable.values()) and result.best.design == max(usable, key=usable.get)


# The GA settings of the budget test, fixed before looking at any objective: plain eaSimple
# with DEAP's example probabilities, one flipped unit per mutation on average (1/n), a
# population of 20 and a budget of 85 distinct designs (1/3 of 256).
BUDGET_GA = {"population": 20, "generations": 100, "indpb": 1 / 8, "budget": 85,
             "mutpb": 0.2, "elitism": 0, "distinct": False}


@pytest.mark.parametrize("name", ["sin", "cos", "min-distance"])
def test_ga_finds_the_global_optimum_in_4_of_5_seeds_within_a_third(name: str, model, evaluator) -> None:
    obj = objective(name)
    optimum = run_exhaustive(model, obj, evaluator).best.value
    found = 0
    for seed in range(5):
        result = run_ga(model, obj, GAConfig(seed=seed, **BUDGET_GA), evaluator)
        assert len(result.scores) <= 85  # distinct designs looked at
        found += result.best.value == optimum
    assert found >= 4


def test_ga_is_deap_easimple_with_a_private_generator(model: ToyModel) -> None:
    obj = objective("sin")
    # eaSimple's own settings: DEAP's example probabilities, no elitism, repeats allowed
    plain = GAConfig(population=20, generations=8, seed=11, mutpb=0.2, indpb=0.05, elitism=0, distinct=False)
    ours = run_ga(model, obj, plain)
    # DEAP's own eaSimple with the global generator seeded alike
    tb = base.Toolbox()
    tb.register("attr_bool", random.randint, 0, 1)
    tb.register("individual", tools.initRepeat, getattr(creator, _INDIVIDUAL["min"]), tb.attr_bool, 8)
    tb.register("population", tools.initRepeat, list, tb.individual)
    tb.register("mate", tools.cxTwoPoint)
    tb.register("mutate", tools.mutFlipBit, indpb=0.05)
    tb.register("select", tools.selTournament, tournsize=3)
    tb.register("evaluate", lambda ind: (score(model.evaluate("".join(map(str, ind))), obj).value,))
    stats = tools.Statistics(lambda ind: ind.fitness.values[0])
    stats.register("min", np.min)
    stats.register("avg", np.mean)
    state = random.getstate()
    random.seed(11)
    try:
        pop, log = algorithms.eaSimple(tb.population(n=20), tb, 0.5, 0.2, 8, stats=stats, verbose=False)
    finally:
        random.setstate(state)
    assert sorted("".join(map(str, ind)) for ind in pop) == sorted(ours.population)
    assert [h.best for h in ours.history] == [rec["min"] for rec in log]
    assert [h.evaluations for h in ours.history] == [rec["nevals"] for rec in log]
    np.testing.assert_allclose([h.mean for h in ours.history], [rec["avg"] for rec in log], rtol=1e-12)


def test_same_seed_same_history_other_seed_another(model: ToyModel) -> None:
    obj, cfg = objective("cos"), GAConfig(population=12, generations=6, elitism=1, seed=3)

    def fingerprint(result):
        history = [(h.best, h.mean, h.worst, h.std, h.evaluations, h.best_design) for h in result.history]
        return history, result.population

    a = run_ga(model, obj, cfg)
    random.seed(12345)  # the global generator plays no part
    b = run_ga(model, obj, cfg, CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:")))
    c = run_ga(model, obj, GAConfig(population=12, generations=6, elitism=1, seed=4))
    assert fingerprint(a) == fingerprint(b)
    assert fingerprint(a) != fingerprint(c)


def test_statistics_budget_elitism_and_hall_of_fame(model: ToyModel) -> None:
    seen = []
    result = run_ga(
        model, objective("max-y"), GAConfig(population=10, generations=30, elitism=2, seed=1, budget=20,
                                            hall_of_fame=5), on_generation=seen.append
    )
    assert seen == list(result.history)
    assert result.stopped == "budget" and len(result.scores) <= 20
    bests = [h.best for h in result.history]
    assert bests == sorted(bests)  # elitism: the best never gets lost (maximising)
    hof = result.hall_of_fame
    assert len({c.design for c in hof}) == 5 and [c.value for c in hof] == sorted((c.value for c in hof), reverse=True)
    assert hof[0].value == max(s.value for s in result.scores.values())
    assert all(h.evaluations == h.cache_hits + h.solves + h.repeats for h in result.history)
    assert sum(h.solves for h in result.history) == result.solves == len(result.scores)


def test_cache_hits_are_counted_the_same_per_generation_and_per_run(tmp_path) -> None:
    """A generation's cache hits are the evaluation cache's answers, as the run's total counts them (the
    designs a run scored before are repeats): "0 cache hits" at the end never follows generations with hits."""
    model, goal = ToyModel(n_units=6), objective("sin")
    config = GAConfig(population=12, generations=6, seed=2)
    messages: list[str] = []
    first = CachedEvaluator(SerialEvaluator(), EvaluationCache(tmp_path / "c.sqlite"))
    result = run_ga(model, goal, config, first, on_message=messages.append)
    assert first.hits == 0 == sum(h.cache_hits for h in result.history)
    assert sum(h.repeats for h in result.history) > 0  # a GA meets its designs again
    assert sum(h.solves for h in result.history) == first.solves
    again = CachedEvaluator(SerialEvaluator(), EvaluationCache(tmp_path / "c.sqlite"))
    rerun = run_ga(model, goal, config, again)
    assert again.solves == 0 and sum(h.cache_hits for h in rerun.history) == again.hits == first.solves
    assert [h.repeats for h in rerun.history] == [h.repeats for h in result.history]
    # said before generation 0, which holds only new designs (the toy model has no measured solve time)
    assert messages == [f"evaluating generation 0: {result.history[0].solves} designs ..."]


def test_bad_search_settings_are_rejected() -> None:
    with pytest.raises(SearchConfigError, match="population must be a whole number >= 2 and <= 10000, got 1"):
        GAConfig(population=1)
    with pytest.raises(SearchConfigError, match=r"cxpb must be a finite number >= 0 and <= 1, got 1\.5"):
        GAConfig(cxpb=1.5)
    with pytest.raises(SearchConfigError, match="at least 1 unit, got 0"):
        run_ga(ToyModel(n_units=0), objective("sin"), GAConfig(population=4))
    with pytest.raises(SearchConfigError, match="at least 1 unit, got 0"):
        run_exhaustive(ToyModel(n_units=0), objective("sin"))
    with pytest.raises(SearchConfigError, match="2\\^21 = 2,097,152 designs"):
        run_exhaustive(ToyModel(n_units=21), objective("sin"))

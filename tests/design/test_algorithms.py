"""The search strategies as algorithms: one interface, the driver runs any of them, and the
docs' worked example of a new strategy (docs/extending.md) runs as written and finds the
exhaustive search's winner when its budget covers every design."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from pneumorph.design import DesignConfig
from pneumorph.design.algorithms import ALGORITHMS, CertifiedSearch, ExhaustiveSearch, GeneticSearch, algorithm_for
from pneumorph.design.algorithms.problem import Problem
from pneumorph.design.search.exhaustive import run_exhaustive
from pneumorph.execution.cache import CachedEvaluator, EvaluationCache
from pneumorph.execution.serial import SerialEvaluator

DOC = Path(__file__).resolve().parents[2] / "docs" / "extending.md"


def test_every_strategy_has_the_interface() -> None:
    for name, cls in ALGORITHMS.items():
        algorithm = cls()
        for method in ("plan", "setup", "run", "interrupted"):
            assert callable(getattr(algorithm, method)), (name, method)
        assert algorithm.name == ("certified" if name == "robust" else name)
    assert isinstance(algorithm_for(DesignConfig()), CertifiedSearch)
    assert isinstance(algorithm_for(DesignConfig(search="ga")), GeneticSearch)
    assert isinstance(algorithm_for(DesignConfig(search="exhaustive", units=4)), ExhaustiveSearch)


def test_a_certified_search_of_a_short_actuator_hands_over_to_the_exhaustive_search(tmp_path: Path) -> None:
    config = DesignConfig(units=3, executor="serial", tolerance=0.0, model={"fidelity": "2d"})
    model = config.make_model()
    problem = Problem(config, model, config.make_objective(), table_dir=tmp_path)
    algorithm, planned = algorithm_for(config).plan(problem)
    assert isinstance(algorithm, ExhaustiveSearch) and algorithm.name == "exhaustive"
    assert "exhaustive" in algorithm.note and planned.model is model  # nothing solved, nothing written
    assert not any(tmp_path.iterdir())


@pytest.mark.slow
def test_the_new_strategy_of_the_docs_finds_the_exhaustive_winner(tmp_path: Path) -> None:
    code = re.search(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    assert code is not None
    (tmp_path / "random_search.py").write_text(code.group(1), encoding="utf-8")
    cache = tmp_path / "cache.sqlite"
    env = {**os.environ, "MPLBACKEND": "Agg", "PNEUMORPH_CACHE": str(cache)}
    done = subprocess.run([sys.executable, "random_search.py"], cwd=tmp_path, capture_output=True, text=True,
                          env=env, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    search, design, value, unit = done.stdout.split()
    assert (search, unit) == ("random", "mm")
    folder = tmp_path / "runs" / "random"
    assert 'search = "random"' in (folder / "config.toml").read_text(encoding="utf-8")
    assert "- search: random" in (folder / "report.md").read_text(encoding="utf-8")
    assert (folder / "ranking.csv").read_text(encoding="utf-8").count("\n") == 17  # header and all 16 designs
    config = DesignConfig(units=4, search="exhaustive", executor="serial", tolerance=0.0)
    model = config.make_model()
    with EvaluationCache(cache) as store:  # the designs the example solved: answered from its cache
        evaluator = CachedEvaluator(SerialEvaluator(), store)
        ex = run_exhaustive(model, config.make_objective(), evaluator)
        assert evaluator.solves == 0
    best = ex.hall_of_fame[0]
    # the exhaustive search halves the designs by the mirror symmetry; the random one scored both mirrors
    assert float(value) == pytest.approx(best.value, abs=5e-5)
    assert design == best.design

"""Serial, process-pool and Dask evaluators give the same outcomes; an unreachable scheduler."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import SchedulerUnreachableError, SearchConfigError
from pneumorph.execution import (
    DaskEvaluator,
    ProcessPoolEvaluator,
    SerialEvaluator,
    make_evaluator,
)

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))  # the toy model lives in tests/design; workers import it too
from tests.design.toy_model import ToyModel

DESIGNS = ["000000", "010101", "111000", "001011", "100110", "011110"]


def same(a, b) -> None:
    assert [o.design for o in a] == [o.design for o in b]
    for x, y in zip(a, b, strict=True):
        assert x.failure == y.failure and x.reached == y.reached
        if x.response is not None:
            np.testing.assert_array_equal(x.response.centres, y.response.centres)
            np.testing.assert_array_equal(x.response.curl, y.response.curl)


@pytest.fixture(scope="module")
def model() -> ToyModel:
    return ToyModel(n_units=6, fail={"111000"})


@pytest.fixture(scope="module")
def serial(model: ToyModel) -> list:
    out = SerialEvaluator().evaluate_many(model, DESIGNS)
    assert out[2].failure == "toy failure" and out[2].response is None
    return out


def test_process_pool_matches_serial(serial: list, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(REPO))
    model = ToyModel(n_units=6, fail={"111000"})
    with ProcessPoolEvaluator(workers=2) as ev:
        out = ev.evaluate_many(model, DESIGNS)
        pool = ev._pool
        again = ev.evaluate_many(model, DESIGNS[:2])
        assert ev._pool is pool  # same model: the workers keep theirs
        assert pool.submit(os.getenv, "OMP_NUM_THREADS").result() == "1"
        ev.evaluate_many(ToyModel(n_units=6, turn=20.0), DESIGNS[:1])
        assert ev._pool is not pool  # another model: new workers
    same(out, serial)
    same(again, serial[:2])
    assert model.calls == []  # solved in the workers, not here


def test_dask_local_cluster_matches_serial(model: ToyModel, serial: list) -> None:
    with DaskEvaluator(workers=1, processes=False) as ev:
        out = ev.evaluate_many(model, DESIGNS)
        streamed = sorted(i for i, _ in ev.iter_evaluate(model, DESIGNS[:3]))
    same(out, serial)
    assert streamed == [0, 1, 2]


def test_unreachable_scheduler_fails_fast_and_clearly() -> None:
    start = time.perf_counter()
    with pytest.raises(SchedulerUnreachableError) as err:
        make_evaluator("dask", scheduler="tcp://127.0.0.1:9", timeout=2.0)
    assert time.perf_counter() - start < 6.0
    assert "no Dask scheduler answered at 'tcp://127.0.0.1:9'" in str(err.value)


def test_bad_executor_settings() -> None:
    with pytest.raises(SearchConfigError, match="unknown executor 'threads'"):
        make_evaluator("threads")
    with pytest.raises(SearchConfigError, match="at least 1, got 0"):
        ProcessPoolEvaluator(workers=0)

"""Serial, process-pool and Dask evaluators give the same outcomes; an unreachable scheduler; a worker
that dies fails its design only; no worker process outlives its evaluator."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
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
from tests.design.toy_model import ToyModel  # noqa: E402 - after the path it is found on

DESIGNS = ["000000", "010101", "111000", "001011", "100110", "011110"]


class TroubleToy(ToyModel):
    """The toy, but its process exits (``os._exit(1)``), is killed (SIGKILL) or sleeps on some designs."""

    def __init__(self, exit=(), kill=(), sleep=(), seconds: float = 60.0, **kw) -> None:
        super().__init__(**kw)
        self.exit, self.kill, self.sleep, self.seconds = frozenset(exit), frozenset(kill), frozenset(sleep), seconds

    def fingerprint(self) -> str:  # the workers keep a model while its fingerprint stays the same
        trouble = json.dumps([sorted(self.exit), sorted(self.kill), sorted(self.sleep), self.seconds])
        return super().fingerprint() + trouble

    def evaluate(self, orientation: str):
        if orientation in self.exit:
            os._exit(1)
        if orientation in self.kill:
            os.kill(os.getpid(), signal.SIGKILL)
        if orientation in self.sleep:
            time.sleep(self.seconds)
        return super().evaluate(orientation)


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
        cases = dict(ev.iter_cases([(model, d) for d in DESIGNS]))  # pairs, each with its model
    same(out, serial)
    same([cases[i] for i in range(len(DESIGNS))], serial)
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


@pytest.mark.slow
def test_a_worker_that_dies_fails_its_design_and_the_others_finish(serial: list,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(REPO))
    model = TroubleToy(n_units=6, fail={"111000"}, exit={"010101"}, kill={"100110"})
    with ProcessPoolEvaluator(workers=2) as ev:
        out = ev.evaluate_many(model, DESIGNS)
        assert ev.restarts >= 2  # one pool per death, and the run went on
        died = {o.design: o for o in out if o.failure and o.failure.startswith("worker died")}
        assert set(died) == {"010101", "100110"}
        assert died["010101"].failure == "worker died: the process solving it exited with code 1"
        assert died["100110"].failure == "worker died: the process solving it was killed by SIGKILL"
        assert all(o.transient and o.response is None and not o.ok for o in died.values())
        others = [i for i, d in enumerate(DESIGNS) if d not in died]
        same([out[i] for i in others], [serial[i] for i in others])
        assert not any(out[i].transient for i in others)  # the toy's own failure of 111000 is a real one
        again = ev.evaluate_many(model, DESIGNS[:1])  # the restarted pool serves on
    same(again, serial[:1])


def test_a_single_worker_dies_and_is_restarted(serial: list, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.syspath_prepend(str(REPO))
    model = TroubleToy(n_units=6, fail={"111000"}, exit={"000000"})
    with ProcessPoolEvaluator(workers=1) as ev:
        out = ev.evaluate_many(model, DESIGNS[:3])
        assert ev.restarts == 1
    assert out[0].failure.startswith("worker died") and out[0].transient
    same(out[1:], serial[1:3])


_CHILDREN = """
import json, multiprocessing, os, signal, sys, threading, time
signal.signal(signal.SIGINT, signal.default_int_handler)  # as a shell starts it, whatever SIGINT state it inherited
sys.path.insert(0, {repo!r})
from pneumorph.execution import ProcessPoolEvaluator
from tests.execution.test_evaluators import TroubleToy

model = TroubleToy(n_units=6, sleep={{"111111"}}, seconds=60.0)
ev = ProcessPoolEvaluator(workers=2)
scenario = sys.argv[1]
if scenario == "close":
    ev.evaluate_many(model, ["000000", "010101", "001011"])
    pids = list(ev._pool._processes)
    ev.close()
elif scenario == "interrupt":
    stream = ev.iter_evaluate(model, ["000000", "111111", "111111"])
    next(stream)
    pids = list(ev._pool._processes)
    threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT)).start()
    try:
        list(stream)
    except KeyboardInterrupt:
        pass
    else:
        raise SystemExit("no KeyboardInterrupt")
elif scenario == "exit":  # the interpreter ends with a solve running and the evaluator never closed
    stream = ev.iter_evaluate(model, ["000000", "111111"])
    next(stream)
    pids = list(ev._pool._processes)
alive = [p.pid for p in multiprocessing.active_children()]
print(json.dumps({{"pids": pids, "alive": alive}}), flush=True)
"""


def _running(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False
    except OSError:  # no /proc
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return False
        return True


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("scenario", ["close", "interrupt", "exit"])
def test_no_worker_process_outlives_its_evaluator(scenario: str) -> None:
    script = textwrap.dedent(_CHILDREN.format(repo=str(REPO)))
    start = time.monotonic()
    run = subprocess.run([sys.executable, "-c", script, scenario], check=False, capture_output=True, text=True,
                         timeout=50, env={**os.environ, "PYTHONPATH": str(REPO)})
    took = time.monotonic() - start
    assert run.returncode == 0, run.stderr
    report = json.loads(run.stdout.strip().splitlines()[-1])
    assert len(report["pids"]) == 2
    if scenario != "exit":
        assert report["alive"] == []  # stopped and reaped before the script went on
    assert took < 40  # a 60 s solve was running (interrupt, exit): its worker was stopped, not waited for
    deadline = time.monotonic() + 5
    while any(_running(pid) for pid in report["pids"]) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [pid for pid in report["pids"] if _running(pid)]


def test_a_pool_starts_no_more_processes_than_the_batch_has_designs(serial: list,
                                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """--workers 4 for 2 designs started 4 processes (and --workers 1024 for 13 designs, 132): the pool is sized to
    the batch, says so once, and grows for a larger batch."""
    monkeypatch.syspath_prepend(str(REPO))
    model = ToyModel(n_units=6, fail={"111000"})
    lines: list[str] = []
    with ProcessPoolEvaluator(workers=4, on_message=lines.append) as ev:
        out = ev.evaluate_many(model, DESIGNS[:2])
        assert ev.started == 2 and len({ev._pool.submit(os.getpid).result() for _ in range(8)}) <= 2
        ev.evaluate_many(model, DESIGNS[:1])
        assert ev.started == 2  # a smaller batch keeps the pool
        ev.evaluate_many(model, DESIGNS)
        assert ev.started == 4  # six designs: the four processes asked for, no more
    same(out, serial[:2])
    assert lines == ["starting 2 worker processes, not 4: the batch has 2 designs to solve"]


def test_a_local_dask_cluster_starts_its_workers_as_the_batch_needs(model: ToyModel, serial: list) -> None:
    lines: list[str] = []
    with DaskEvaluator(workers=3, processes=False, on_message=lines.append) as ev:
        assert len(ev._cluster.workers) == 0 and ev.workers == 3  # nothing started before a batch
        out = ev.evaluate_many(model, DESIGNS[:1])
        assert len(ev._cluster.workers) == 1
        ev.evaluate_many(model, DESIGNS)
        assert len(ev._cluster.workers) == 3
    same(out, serial[:1])
    assert lines == ["starting 1 Dask worker, not 3: the batch has 1 design to solve"]

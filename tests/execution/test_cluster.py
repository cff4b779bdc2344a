"""A real Dask cluster: a scheduler and standard workers (with their nannies) started as separate processes on
127.0.0.1. The same table as the process pool, a lost worker's designs retried and counted, a lost scheduler one
line (exit 3) and a re-run that resumes from the cache, workers of another version refused, ignored options
refused before any work."""

from __future__ import annotations

import json
import os
import signal
import socket
import sqlite3
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

from pneumorph.cli import main  # noqa: E402 - after the skip
from pneumorph.errors import ClusterLostError, WorkerVersionError  # noqa: E402
from pneumorph.execution import DaskEvaluator, SerialEvaluator  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))  # the toy models live in tests/; the workers import them too
from tests.execution.slow_toy import SlowToy  # noqa: E402

DESIGNS = ["000000", "010101", "111000", "001011", "100110", "011110"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class Cluster:
    """``python -m distributed.cli.dask_scheduler`` and ``dask_worker`` processes (--nworkers 1 --nthreads 1)."""

    def __init__(self, folder: Path, port: int | None = None) -> None:
        self.folder = folder
        self.port = port or free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}
        self.scheduler = self._start("dask_scheduler", "--host", "127.0.0.1", "--port", str(self.port),
                                     "--no-dashboard", log="scheduler")
        self.workers: list[subprocess.Popen] = []

    def _start(self, module: str, *args: str, log: str) -> subprocess.Popen:
        with open(self.folder / f"{log}.log", "ab") as out:
            return subprocess.Popen([sys.executable, "-m", f"distributed.cli.{module}", *args], cwd=REPO, env=self.env,
                                    stdout=out, stderr=subprocess.STDOUT, start_new_session=True)

    def add_workers(self, n: int) -> None:
        for _ in range(n):
            self.workers.append(self._start("dask_worker", self.address, "--nworkers", "1", "--nthreads", "1",
                                            "--no-dashboard", log=f"worker{len(self.workers)}"))
        with distributed.Client(self.address, timeout=30) as client:
            client.wait_for_workers(len(self.workers), timeout=60)

    def stop(self) -> None:
        for p in [*self.workers, self.scheduler]:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in [*self.workers, self.scheduler]:
            try:
                p.wait(15)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cluster]:
    c = Cluster(tmp_path_factory.mktemp("cluster"))
    try:
        c.add_workers(2)
        yield c
    finally:
        c.stop()


def coarse_unit(folder: Path) -> Path:
    unit = folder / "coarse.toml"
    unit.write_text("[unit]\nelement_size = 3.0\n")
    return unit


@pytest.mark.cluster
def test_chain_build_on_the_cluster_writes_the_process_pools_table(cluster: Cluster, tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    common = ["chain", "build", "--model", "2d", "--unit", str(coarse_unit(tmp_path)), "--pressure", "20",
              "--units", "7", "--heldout", "4", "--json"]
    assert main([*common, "--executor", "dask", "--scheduler", cluster.address, "--cache", str(tmp_path / "d.sqlite"),
                 "--out", str(tmp_path / "dask.json")]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["cluster"] == {"retried": 0, "lost_workers": 0}
    assert main([*common, "--executor", "processes", "--workers", "2", "--cache", str(tmp_path / "p.sqlite"),
                 "--out", str(tmp_path / "pool.json")]) == 0
    dask, pool = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("dask", "pool"))
    assert set(dask) == set(pool)
    for key in set(dask) - {"metadata"}:  # the fit and its validation bit for bit; only when and how long differ
        assert dask[key] == pool[key], key
    assert dask["metadata"]["solves"] == pool["metadata"]["solves"] >= 6


@pytest.mark.cluster
def test_the_workers_are_set_up_for_solving(cluster: Cluster) -> None:
    with DaskEvaluator(cluster.address) as ev:
        assert ev.workers == 2
        threads = ev.client.run(os.environ.get, "OMP_NUM_THREADS")
        assert set(threads.values()) == {"1"}
        plugins = ev.client.run(lambda dask_worker: sorted(dask_worker.plugins))
        assert all("pneumorph-solver-settings" in names for names in plugins.values())
        from pneumorph.execution.evaluators import tune_allocator

        if sys.platform.startswith("linux"):  # glibc: mallopt took the values
            assert set(ev.client.run(tune_allocator).values()) == {True}


@pytest.mark.cluster
def test_workers_of_another_version_are_refused_naming_both(cluster: Cluster, monkeypatch: pytest.MonkeyPatch) -> None:
    import pneumorph

    theirs = pneumorph.__version__
    with DaskEvaluator(cluster.address) as ev:  # connected; then the versions part (as a worker joining later)
        monkeypatch.setattr(pneumorph, "__version__", "98.0")
        with pytest.raises(WorkerVersionError, match=f"runs pneumorph {theirs}, this client pneumorph 98.0"):
            ev.evaluate_many(SlowToy(seconds=0.0, n_units=6), DESIGNS[:1])  # checked at the start of a batch
    monkeypatch.setattr(pneumorph, "__version__", "99.0")
    with pytest.raises(WorkerVersionError) as err:
        DaskEvaluator(cluster.address)
    text = str(err.value)
    assert f"runs pneumorph {theirs}, this client pneumorph 99.0" in text and cluster.address in text
    assert "(and 1 more)" in text  # both workers named by count


@pytest.mark.cluster
def test_a_lost_worker_has_its_designs_retried_and_counted(cluster: Cluster) -> None:
    model = SlowToy(seconds=1.5, n_units=6, fail={"111000"})
    expected = SerialEvaluator().evaluate_many(SlowToy(seconds=0.0, n_units=6, fail={"111000"}), DESIGNS)
    lines: list[str] = []
    with DaskEvaluator(cluster.address, on_message=lines.append) as ev:
        ev.poll = 0.2
        pids = ev.client.run(os.getpid)  # the worker processes (their nannies start new ones)

        def kill_one_while_busy() -> None:
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline:
                busy = [addr for addr, keys in ev.client.processing().items() if keys]
                if len(busy) == 2:
                    time.sleep(0.5)  # both are solving
                    os.kill(pids[busy[0]], signal.SIGKILL)
                    return
                time.sleep(0.05)

        killer = threading.Thread(target=kill_one_while_busy)
        killer.start()
        out = ev.evaluate_many(model, DESIGNS)
        killer.join()
        assert ev.lost_workers == 1 and ev.retried >= 1
    for got, want in zip(out, expected, strict=True):
        assert got.failure == want.failure and not got.transient
        if want.response is not None:
            np.testing.assert_array_equal(got.response.centres, want.response.centres)
    assert len(lines) == 1 and "lost; the " in lines[0] and "retried on the other workers" in lines[0]
    with distributed.Client(cluster.address, timeout=30) as client:  # the nanny's new worker for the next tests
        client.wait_for_workers(2, timeout=60)


@pytest.mark.cluster
def test_a_lost_scheduler_is_one_line_and_the_rerun_resumes_from_the_cache(tmp_path: Path) -> None:
    cluster = Cluster(tmp_path)
    cache = tmp_path / "c.sqlite"
    args = ["chain", "build", "--model", "2d", "--unit", str(coarse_unit(tmp_path)), "--pressure", "20", "--units",
            "7", "--heldout", "16", "--executor", "dask", "--scheduler", cluster.address, "--cache", str(cache),
            "--out", str(tmp_path / "t.json")]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    try:
        cluster.add_workers(1)
        run = subprocess.Popen([sys.executable, "-m", "pneumorph", *args], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)
        stored = 0
        deadline = time.monotonic() + 120
        while stored < 3 and time.monotonic() < deadline and run.poll() is None:
            time.sleep(0.05)
            if cache.exists():
                with sqlite3.connect(cache) as db:
                    try:
                        stored = db.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0]
                    except sqlite3.Error:
                        stored = 0
        assert stored >= 3, "the build never got going"
        cluster.scheduler.kill()  # kill -9
        _, err = run.communicate(timeout=60)
        assert run.returncode == 3
        lines = err.strip().splitlines()
        assert "Traceback" not in err and "internal error" not in err and "distributed." not in err  # no log lines
        assert lines[-1].startswith(f"error: lost the Dask scheduler at {cluster.address}")
        assert ("every design finished before is in the evaluation cache; resume with: pneumorph chain build"
                in lines[-1])
    finally:
        cluster.stop()
    with sqlite3.connect(cache) as db:
        kept = db.execute("SELECT COUNT(*) FROM evaluations").fetchone()[0]
    assert kept >= 3
    again = Cluster(tmp_path, port=cluster.port)  # the same address: the command it printed resumes
    try:
        again.add_workers(1)
        done = subprocess.run([sys.executable, "-m", "pneumorph", *args], capture_output=True, text=True, env=env,
                              cwd=tmp_path, timeout=300)
    finally:
        again.stop()
    assert done.returncode == 0, done.stderr[-500:]
    assert f"({kept} designs already in the evaluation cache)" in done.stderr.splitlines()[0]
    assert done.stderr.count("(cached ") >= kept


@pytest.mark.parametrize(("options", "message"), [
    (["--executor", "processes", "--scheduler", "tcp://127.0.0.1:8786"],
     "error: --scheduler only applies to --executor dask, not to processes"),
    (["--executor", "serial", "--workers", "2"], "error: --workers does not apply to --executor serial"),
    (["--executor", "dask", "--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"],
     "error: --workers does not apply with --scheduler"),
    (["--executor", "processes", "--workers", "1024"], "error: --workers 1024: more than 2 worker processes per core"),
    (["--executor", "dask", "--workers", "64"], "error: --workers 64: more than 2 worker processes per core"),
])
def test_options_that_would_be_ignored_are_refused_before_any_work(
        options: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    commands = [["chain", "build", "--model", "2d", "--out", str(tmp_path / "t.json")],
                ["sensitivity", "tolerances", "--model", "2d", "--units", "2"],
                ["study", "--seeds", "1", "--gen", "1", "--out", str(tmp_path / "s")],
                ["unit", "optimise", "--out", str(tmp_path / "u")],
                ["calibrate", "--out", str(tmp_path / "c")],
                ["design", "--out", str(tmp_path / "d")]]
    for command in commands:
        assert main([*command, *options, "--cache", str(tmp_path / "c.sqlite")]) == 2, command
        err = capsys.readouterr().err.strip()
        assert err.startswith(message) and len(err.splitlines()) == 1, (command, err)
    assert not (tmp_path / "c.sqlite").exists()  # refused before the cache was opened


@pytest.mark.cluster
def test_a_scheduler_lost_in_the_middle_of_a_batch_raises_cluster_lost(tmp_path: Path) -> None:
    cluster = Cluster(tmp_path)
    try:
        cluster.add_workers(1)
        with DaskEvaluator(cluster.address) as ev:
            ev.poll = 0.2
            got = []
            with pytest.raises(ClusterLostError, match="lost the Dask scheduler"):
                for i, _ in ev.iter_evaluate(SlowToy(seconds=1.0, n_units=6), DESIGNS):
                    got.append(i)
                    if len(got) == 1:
                        cluster.scheduler.kill()
            assert len(got) < len(DESIGNS)
    finally:
        cluster.stop()


@pytest.mark.cluster
def test_a_batch_without_any_worker_says_so_and_ends_after_the_timeout(tmp_path: Path) -> None:
    cluster = Cluster(tmp_path)  # a scheduler, no worker
    lines: list[str] = []
    try:
        with DaskEvaluator(cluster.address, on_message=lines.append) as ev:
            ev.poll, ev.no_worker_timeout = 0.2, 1.0
            with pytest.raises(ClusterLostError, match=r"no Dask worker at tcp://127\.0\.0\.1:\d+ for 1 s; every"):
                ev.evaluate_many(SlowToy(seconds=0.0, n_units=6), DESIGNS)
    finally:
        cluster.stop()
    assert len(lines) == 1 and lines[0].startswith(f"no Dask worker at {cluster.address}: waiting up to 1 s")


@pytest.mark.cluster
def test_a_design_run_builds_its_chain_table_on_the_cluster(tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    cluster = Cluster(tmp_path)
    try:
        cluster.add_workers(1)
        argv = ["design", "--model", "2d", "--unit", str(coarse_unit(tmp_path)), "--units", "7", "--pressure", "20",
                "--tolerance", "0", "--executor", "dask", "--scheduler", cluster.address, "--cache",
                str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"), "--json"]
        assert main(argv) == 0
        with distributed.Client(cluster.address, timeout=30) as client:
            from pneumorph.execution import cluster as dask_evaluator

            kept = client.run(lambda: len(dask_evaluator._DASK_MODELS))  # the models the worker solved designs of
    finally:
        cluster.stop()
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert "building the chain table of the 2d model" in captured.err and "executor dask" in captured.err
    assert report["status"] == "finished" and report["retried"] == 0 and report["solves"] >= 2
    assert list(kept.values()) == [2]  # the table's model and the verifications' (its levels)


@pytest.mark.cluster
def test_a_worker_killed_during_a_build_costs_nothing_but_the_retries(cluster: Cluster, tmp_path: Path) -> None:
    # a mesh fine enough that a solve takes about 3 s, and the kill only once a worker has held the same design for
    # longer than the evaluator's poll (1 s): it is then still solving it, and the run has seen it there (a design
    # counts as retried when the run knew the lost worker held it)
    unit = tmp_path / "fine.toml"
    unit.write_text("[unit]\nelement_size = 0.5\n")
    common = ["chain", "build", "--model", "2d", "--unit", str(unit), "--pressure", "20",
              "--units", "7", "--heldout", "12", "--window", "2", "--json"]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    build = subprocess.Popen([sys.executable, "-m", "pneumorph", *common, "--executor", "dask", "--scheduler",
                              cluster.address, "--cache", str(tmp_path / "d.sqlite"), "--out",
                              str(tmp_path / "dask.json")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             env=env, cwd=tmp_path)
    with distributed.Client(cluster.address, timeout=30) as client:
        pids = client.run(os.getpid)
        deadline = time.monotonic() + 120
        killed = False
        since: dict[tuple[str, str], float] = {}
        while not killed and time.monotonic() < deadline and build.poll() is None:
            now = time.monotonic()
            held = {(addr, key) for addr, keys in client.processing().items() for key in keys}
            since = {k: since.get(k, now) for k in held}
            ripe = [addr for (addr, _), t in since.items() if now - t > 1.3]
            if ripe:
                os.kill(pids[ripe[0]], signal.SIGKILL)  # kill -9 of a worker solving a design of the build
                killed = True
            time.sleep(0.02)
        out, err = build.communicate(timeout=300)
        client.wait_for_workers(2, timeout=60)  # the nanny's new worker, for the next tests
    assert killed and build.returncode == 0, err[-500:]
    report = json.loads(out)
    assert report["cluster"]["lost_workers"] == 1 and report["cluster"]["retried"] >= 1
    retried = report["cluster"]["retried"]
    lines = err.strip().splitlines()  # the run's summary of the lost worker, then the table written
    assert "lost; the " in err and lines[-2:] == [
        f"1 Dask worker(s) lost during the run; {retried} design(s) they were solving or held "
        "queued were retried on the others", f"writing the chain table to {tmp_path / 'dask.json'}"]
    assert main([*common, "--executor", "processes", "--workers", "2", "--cache", str(tmp_path / "p.sqlite"),
                 "--out", str(tmp_path / "pool.json")]) == 0
    dask, pool = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("dask", "pool"))
    for key in set(dask) - {"metadata"}:  # the same table as without the fault
        assert dask[key] == pool[key], key

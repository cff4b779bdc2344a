"""Killing a design run at any moment loses nothing: the command line end to end, in subprocesses.

A small GA run on the 2D model (7 units, 30 levels per solve, so that it is still running
when the signal arrives) is stopped by SIGTERM, Ctrl-C or SIGKILL after its first
generation; the same command then resumes it. Every design solved before the signal is
answered from the cache (the cache's count at the end equals the designs solved by both
runs), the folder describes one run, and no worker process outlives its parent.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pneumorph.execution import EvaluationCache

CONFIG = """[design]
objective = "sin"
units = 7
search = "ga"
seed = 3

[ga]
population = 10
generations = 8

[model]
fidelity = "2d"
pressure_kpa = 10.0
increments = 20
"""


def _command(tmp_path: Path, executor: str = "serial", *extra: str) -> list[str]:
    (tmp_path / "run.toml").write_text(CONFIG, encoding="utf-8")
    return [sys.executable, "-m", "pneumorph", "design", str(tmp_path / "run.toml"), "--executor", executor,
            "--cache", str(tmp_path / "cache.sqlite"), "--out", str(tmp_path / "run"), *extra]


def _env(tmp_path: Path) -> dict[str, str]:
    return {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "xdg"), "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg"}


def _default_sigint() -> None:
    """Start the run as a shell would, with Ctrl-C at its default: a process that inherits an ignored SIGINT keeps
    it ignored (Python installs its KeyboardInterrupt handler only where SIGINT is not ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start_and_wait(tmp_path: Path, command: list[str], marker: str = "generation  1/") -> subprocess.Popen[str]:
    """Start a run and return once its stderr shows ``marker`` (the run is then mid-way)."""
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=_env(tmp_path),
                            start_new_session=True, preexec_fn=_default_sigint)
    assert proc.stderr is not None
    deadline = time.monotonic() + 120
    for line in proc.stderr:
        if marker in line:
            return proc
        assert time.monotonic() < deadline, "the run did not reach its first generation"
    raise AssertionError(f"the run ended before {marker!r}: exit {proc.wait()}")


def _cached(tmp_path: Path) -> int:
    with EvaluationCache(tmp_path / "cache.sqlite") as cache:
        return cache.count()


def _resume(tmp_path: Path, command: list[str]) -> dict:
    done = subprocess.run([*command, "--json"], capture_output=True, text=True, env=_env(tmp_path), timeout=600)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    return json.loads(done.stdout)


def _one_run_in_the_folder(folder: Path) -> None:
    rows = list(csv.DictReader((folder / "generations.csv").open(encoding="utf-8")))
    assert [int(r["generation"]) for r in rows] == list(range(len(rows)))  # each generation logged once
    assert "interrupted" not in (folder / "report.md").read_text(encoding="utf-8").lower()
    assert not list(folder.glob(".*.tmp*")) and not (folder / ".pneumorph.lock").exists()


@pytest.mark.parametrize(("sig", "code"), [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_stopped_run_writes_its_report_and_resumes_without_solving_again(tmp_path: Path, sig: int,
                                                                          code: int) -> None:
    command = _command(tmp_path)
    proc = _start_and_wait(tmp_path, command)
    proc.send_signal(sig)
    assert proc.wait(timeout=120) == code
    assert "Traceback" not in (proc.stderr.read() if proc.stderr else "")
    report = (tmp_path / "run" / "report.md").read_text(encoding="utf-8")
    assert "interrupted" in report.lower()
    before = _cached(tmp_path)
    assert before >= 10  # the first generation's designs at least
    result = _resume(tmp_path, command)
    assert result["status"] == "finished"
    assert _cached(tmp_path) == before + result["solves"]  # nothing solved before was solved again
    _one_run_in_the_folder(tmp_path / "run")


def test_a_killed_run_leaves_no_worker_and_resumes(tmp_path: Path) -> None:
    command = _command(tmp_path, "processes", "--workers", "2")
    proc = _start_and_wait(tmp_path, command)
    children = _children(proc.pid)
    assert children, "the process pool has no workers"
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=60)
    deadline = time.monotonic() + 10
    while any(_alive(pid) for pid in children) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not [pid for pid in children if _alive(pid)], "a worker outlived its killed parent"
    before = _cached(tmp_path)
    result = _resume(tmp_path, command)  # the dead run's lock is no obstacle
    assert result["status"] == "finished"
    assert _cached(tmp_path) == before + result["solves"]
    _one_run_in_the_folder(tmp_path / "run")


def test_a_second_run_into_a_busy_folder_is_refused(tmp_path: Path) -> None:
    command = _command(tmp_path)
    first = _start_and_wait(tmp_path, command, marker="generation  0/")
    try:
        second = subprocess.run(command, capture_output=True, text=True, env=_env(tmp_path), timeout=120)
        lines = second.stderr.strip().splitlines()
        assert second.returncode == 2 and len(lines) == 1, second.stderr
        assert str(first.pid) in lines[0] and "run" in lines[0]
    finally:
        first.send_signal(signal.SIGTERM)
        first.wait(timeout=120)


def _children(pid: int) -> list[int]:
    found: list[int] = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        text = (task / "children").read_text() if (task / "children").exists() else ""
        found += [int(c) for c in text.split()]
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return False
    return state not in ("Z", "X")


pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")]

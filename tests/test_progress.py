"""The progress contract (pneumorph.io.progress): a long command says its plan first, then progress with
done/total and the time left at the measured rate, and never stays silent longer than the contract.

The reporter is tested on its own clock; the commands run in a pseudo-terminal (as a user sees them: stderr a
terminal, lines as they are written) with a short heartbeat (``PNEUMORPH_HEARTBEAT``), at reduced sizes.
"""

from __future__ import annotations

import os
import re
import select
import subprocess
import sys
import threading
import time
from itertools import pairwise
from pathlib import Path

import pytest

from pneumorph.io.progress import Progress, estimate_seconds, load_factor

SRC = Path(__file__).resolve().parents[1] / "src"
CONTRACT = 10.0  # seconds: no command silent for longer, in a terminal or a log file
BEAT = 0.5  # the heartbeat the commands run with here
SCALED = 5.0  # the contract at that heartbeat: a line at least this often once the first is said


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_the_time_left_is_at_the_measured_rate_not_the_estimate() -> None:
    clock, lines = Clock(), []
    progress = Progress(lines.append, clock=clock)
    progress.plan("search", 10, each=1.0, workers=1, load=0.0, cores=1, where="runs/x")
    assert lines == ["search: 10 solves, estimated 10 s (1.0 s each, 1 worker) -> runs/x"]
    clock.now = 12.0  # a loaded machine: 4 s a solve, not 1
    progress.count(3)
    assert lines[-1] == "  search: 3/10 after 12 s, 4.0 s each, about 28 s left"  # 7 more at 4 s


def test_counted_lines_are_throttled_but_the_last_and_failures_are_said() -> None:
    clock, lines = Clock(), []
    progress = Progress(lines.append, clock=clock, throttle=2.0)
    progress.plan("study", 4)
    for done, at in ((1, 0.5), (2, 1.0)):
        clock.now = at
        progress.count(done)
    assert len(lines) == 1  # within 2 s of the plan: nothing more
    progress.count(3, "case c: failed", always=True)
    clock.now = 1.2
    progress.count(4)
    assert [line.split(":")[1].split()[0] for line in lines[1:]] == ["3/4", "4/4"]
    assert lines[1].endswith("; case c: failed") and "left" not in lines[2]
    progress.count(4)  # the count ended with its last item: said once
    assert len(lines) == 3


def test_the_heartbeat_names_what_runs_and_for_how_long() -> None:
    clock, lines = Clock(), []
    progress = Progress(lines.append, clock=clock, heartbeat=7.0)
    progress.say("verifying 0110 by FE (3d, about 40 s) ...")
    clock.now = 6.9
    progress.beat()
    assert len(lines) == 1  # not yet
    clock.now = 7.0
    progress.beat()
    clock.now = 14.0
    progress.beat()
    assert lines[1:] == ["  still running, 7.0 s since: verifying 0110 by FE (3d, about 40 s) ...",
                         "  still running, 14 s since: verifying 0110 by FE (3d, about 40 s) ..."]
    progress.plan("refining", 2, each=60.0, workers=2, load=0.0, cores=2)  # both at once: 60 s
    progress.note("design 0110")
    clock.now = 35.0
    progress.beat()
    assert lines[-1] == "  still running: refining: 0/2 after 21 s, about 39 s left by the estimate (design 0110)"
    clock.now = 80.0
    progress.beat()
    assert lines[-1].startswith("  still running: refining: 0/2 after 66 s, longer than estimated")


def test_the_heartbeat_thread_speaks_in_a_silence_and_stops_with_its_block() -> None:
    lines: list[str] = []
    spoke = threading.Event()

    def write(line: str) -> None:
        lines.append(line)
        spoke.set()

    with Progress(write, heartbeat=0.05) as progress:
        progress.say("a long step")
        spoke.clear()
        assert spoke.wait(30)  # the thread wrote without being asked
    after = len(lines)
    assert lines[-1].startswith("  still running, ") and lines[-1].endswith(" since: a long step")
    time.sleep(0.2)
    assert len(lines) == after  # stopped on leaving the block


def test_estimates_count_the_machines_load_and_the_workers() -> None:
    assert load_factor(2, load=0.0, cores=2) == 1.0
    assert load_factor(2, load=2.0, cores=2) == 2.0  # two busy processes besides ours: half a core each
    assert estimate_seconds(65, 0.3, workers=2, load=0.0, cores=2) == pytest.approx(0.3 * 33)
    assert estimate_seconds(65, 0.3, workers=2, load=2.0, cores=2) == pytest.approx(0.3 * 33 * 2)
    assert estimate_seconds(0, 5.0) == 0.0


def run_in_terminal(args: list[str], cwd: Path, timeout: float = 600.0) -> tuple[int, list[tuple[float, str]], float]:
    """``pneumorph ARGS`` with its standard output and error on a pseudo-terminal: its exit code, each line with
    the seconds since the start when it arrived, and the wall time."""
    master, slave = os.openpty()
    env = dict(os.environ, PYTHONPATH=str(SRC), PNEUMORPH_HEARTBEAT=str(BEAT), COLUMNS="200")
    start = time.monotonic()
    process = subprocess.Popen([sys.executable, "-m", "pneumorph", *args], stdin=subprocess.DEVNULL, stdout=slave,
                               stderr=slave, cwd=cwd, env=env, close_fds=True)
    os.close(slave)
    lines, pending = [], b""
    try:
        while time.monotonic() - start < timeout:
            ready, _, _ = select.select([master], [], [], 0.1)
            if not ready:
                if process.poll() is not None:
                    break
                continue
            try:
                data = os.read(master, 65536)
            except OSError:  # the terminal closed with the process
                break
            if not data:
                break
            pending += data
            while b"\n" in pending:
                line, pending = pending.split(b"\n", 1)
                lines.append((time.monotonic() - start, line.decode(errors="replace").rstrip("\r")))
    finally:
        os.close(master)
        if process.poll() is None:
            process.kill()
    code = process.wait()
    return code, lines, time.monotonic() - start


def check_contract(code: int, lines: list[tuple[float, str]], wall: float) -> None:
    """Exit 0; the first line within the contract; from it on, no silence longer than the scaled contract."""
    text = "\n".join(f"{t:6.1f} {line}" for t, line in lines)
    assert code == 0, text
    assert lines and lines[0][0] <= CONTRACT, text
    times = [t for t, _ in lines] + [wall]
    gaps = [b - a for a, b in pairwise(times)]
    assert max(gaps) <= SCALED, f"silent for {max(gaps):.1f} s:\n{text}"


def counted(lines: list[tuple[float, str]], what: str) -> list[tuple[int, int]]:
    """The ``done/total`` of the counted lines of ``what``."""
    found = (re.search(rf"{what}: (\d+)/(\d+) after", line) for _, line in lines)
    return [(int(m[1]), int(m[2])) for m in found if m]


def test_the_exhaustive_search_says_its_plan_then_counts_as_it_solves(tmp_path: Path) -> None:
    code, lines, wall = run_in_terminal(["design", "--search", "exhaustive", "--units", "5", "--model", "2d",
                                         "--executor", "serial", "--tolerance", "0", "--cache",
                                         str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run")], tmp_path)
    check_contract(code, lines, wall)
    said = [line for _, line in lines]
    plan = next(i for i, line in enumerate(said) if line.startswith("exhaustive search: 32 designs"))
    assert said[plan - 1].startswith("designing 5 units") and " estimated " in said[plan]
    counts = counted(lines, "exhaustive search")
    assert counts[-1] == (32, 32) and counts == sorted(counts)
    # progress while it solves (or the heartbeat), not all at the end: a line before the last count's
    assert len(said) - plan > 2 and said.index(next(s for s in said if "32/32" in s)) > plan + 1


def test_simulate_and_a_sensitivity_study_keep_the_contract(tmp_path: Path) -> None:
    code, lines, wall = run_in_terminal(["simulate", "-o", "0110", "--model", "2d"], tmp_path)
    check_contract(code, lines, wall)
    assert lines[0][1].startswith("simulating design 0110 (2d model, 4 units, 45 kPa):")
    assert counted(lines, "design 0110")[-1][0] == counted(lines, "design 0110")[-1][1]
    code, lines, wall = run_in_terminal(["sensitivity", "bulk-modulus", "--model", "2d", "--units", "3",
                                         "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"),
                                         "--out", str(tmp_path / "study")], tmp_path)
    check_contract(code, lines, wall)
    assert counted(lines, "bulk-modulus study")[-1] == (3, 3)  # the reference and two factors


@pytest.mark.slow
def test_unit_optimise_counts_its_candidates_against_a_total(tmp_path: Path) -> None:
    code, lines, wall = run_in_terminal(["unit", "optimise", "--var", "cavity_height=4.5:7.5", "--var",
                                         "end_wall=2:3.5", "--element-size", "3", "--pressure", "10", "--pop", "4",
                                         "--gen", "1", "--resolution", "0.5", "--executor", "serial", "--cache",
                                         str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run")], tmp_path)
    check_contract(code, lines, wall)
    counts = counted(lines, "unit optimisation")
    assert counts and all(total == 1 + 4 * 2 for _, total in counts)  # the base unit and two generations of 4

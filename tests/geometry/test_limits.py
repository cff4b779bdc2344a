"""Limits on what a unit may be, from the command line: refused before any mesh, with the estimate."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path


def _run(*args: str) -> tuple[int, str, float]:
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "pneumorph", *args], capture_output=True, text=True, timeout=120)
    return done.returncode, done.stdout + done.stderr, time.perf_counter() - start


def test_a_simulation_past_the_memory_is_refused_with_its_estimate(tmp_path: Path) -> None:
    """The command line's limit is the memory available: 15 units at 0.4 mm elements would need ~100 GB."""
    unit = tmp_path / "fine.toml"
    unit.write_text("[unit]\nelement_size = 0.4\n")
    code, out, seconds = _run("simulate", "-o", "0" * 15, "--model", "3d", "--unit", str(unit))
    assert code == 2 and "nodes" in out and "GB for one solve" in out and "GB are available" in out
    assert "Traceback" not in out and seconds < 30


def test_a_unit_file_with_a_huge_pitch_is_refused(tmp_path: Path) -> None:
    unit = tmp_path / "big.toml"
    unit.write_text("[unit]\npitch = 1e9\n")  # the issue: a base block 1e9 mm long went past 6 GB
    code, out, _ = _run("simulate", "-o", "0" * 15, "--model", "2d", "--unit", str(unit))
    assert code == 2 and "MAX_LENGTH_MM" in out and "Traceback" not in out

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


def test_list_fields_of_a_unit_file_are_checked(tmp_path: Path) -> None:
    """Text in a unit's list fields is a one-line refusal naming the field, not an internal error."""
    for body, message in (('filler_coefficients = ["a", "b"]', "filler_coefficients must be a list of numbers"),
                          ('filler_range_kpa = "x"', "filler_range_kpa must be a list of 2 numbers"),
                          ("filler_range_kpa = [45, 0]", "must rise from its low to its high pressure"),
                          ("filler_coefficients = [true, 1]", "filler_coefficients must be a list of numbers")):
        unit = tmp_path / "u.toml"
        unit.write_text(f"[unit]\n{body}\n")
        code, out, _ = _run("simulate", "-o", "01", "--unit", str(unit))
        assert code == 2 and message in out and "internal error" not in out, out


def test_an_actuator_of_solid_units_only_is_refused(tmp_path: Path) -> None:
    unit = tmp_path / "solid.toml"
    unit.write_text("[unit]\nsolid = true\n")
    for command in (("simulate", "-o", "01", "--unit", str(unit)),
                    ("simulate", "-o", "01", "--model", "3d", "--unit", str(unit))):
        code, out, _ = _run(*command)
        assert code == 2 and "nothing to inflate" in out and "internal error" not in out, out

"""The code checks the project holds itself to ([tool.ruff] and [tool.mypy] in pyproject.toml)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", *args], cwd=REPO, capture_output=True, text=True)


def test_ruff_finds_nothing() -> None:
    done = _run("ruff", "check", "--output-format", "concise", "src", "tests", "benchmarks", "docs/scripts",
                "docs/conf.py")
    assert done.returncode == 0, done.stdout + done.stderr


def test_mypy_finds_nothing_in_the_package() -> None:
    done = _run("mypy", "--no-incremental")  # the files and settings of [tool.mypy]
    assert done.returncode == 0, done.stdout + done.stderr

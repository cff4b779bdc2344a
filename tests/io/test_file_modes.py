"""Files written atomically follow the umask, like any other file (a lab's shared folder can read them)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from pneumorph.io.files import atomic_path, atomic_write_text, current_umask


@pytest.mark.parametrize("mask", [0o022, 0o002, 0o077])
def test_atomic_writes_follow_the_umask(tmp_path: Path, mask: int) -> None:
    old = os.umask(mask)
    try:
        assert current_umask() == mask
        text = atomic_write_text(tmp_path / "report.md", "x")
        with atomic_path(tmp_path / "figure.png") as tmp:
            tmp.write_bytes(b"png")
    finally:
        os.umask(old)
    for path in (text, tmp_path / "figure.png"):
        assert path.stat().st_mode & 0o777 == 0o666 & ~mask


def test_a_run_folder_is_readable_by_the_group(tmp_path: Path) -> None:
    """A real command's outputs (JSON, PNG) under umask 002 are group-readable and -writable, as `touch` makes."""
    out = tmp_path / "sim"
    code = subprocess.run(
        [sys.executable, "-c", "import os, sys; os.umask(0o002); from pneumorph.cli import main; "
         f"sys.exit(main(['simulate', '-o', '01', '--pressure', '10', '--increments', '1', '--out', {str(out)!r}]))"],
        capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"}, timeout=300,
    )
    assert code.returncode == 0, code.stderr
    files = [p for p in out.rglob("*") if p.is_file()]
    assert files
    assert {oct(p.stat().st_mode & 0o777) for p in files} == {oct(0o664)}

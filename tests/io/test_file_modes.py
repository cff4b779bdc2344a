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


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs the proc pseudo-filesystem")
@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "-o", "01", "--out", "/proc/sx"],
        ["export", "0110", "--stl", "/proc/x"],
        ["export", "0110", "--inp", "/proc/deck.inp"],
        ["chain", "build", "--model", "2d", "--units", "4", "--out", "/proc/t.json"],
        ["sensitivity", "tolerances", "--out", "/proc/x"],
        ["unit", "optimise", "--out", "/proc/uo"],
        ["sensitivity", "mesh", "--out", "/proc/m"],
        ["design", "--out", "/proc/dx"],
    ],
)
def test_unwritable_outputs_are_refused_before_any_work(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """Permissions alone say /proc is writable to root; the check makes and removes a folder there instead."""
    from pneumorph.cli import main

    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "/proc" in err[0] and ("cannot be" in err[0] or "nothing can be created" in err[0])


@pytest.mark.parametrize("body", ["[design]\nobjective = " + "[" * 1000 + "]" * 1000,
                                  "[model]\nunit = " + "{a = " * 1000 + "1" + "}" * 1000,
                                  "[design]\nobjective = " + "[" * 40 + "]" * 40])
def test_a_deeply_nested_config_is_one_line(tmp_path: Path, body: str, capsys: pytest.CaptureFixture[str]) -> None:
    from pneumorph.cli import main

    config = tmp_path / "deep.toml"
    config.write_text(body + "\n")
    assert main(["design", str(config), "--out", str(tmp_path / "never")]) == 2
    err = capsys.readouterr().err
    assert "nested more than 32 levels deep" in err and "RecursionError" not in err

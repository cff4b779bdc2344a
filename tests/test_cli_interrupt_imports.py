"""Ctrl-C is the same at every moment of a run: inside a lazy import (one that a library swallows
too), while writing outputs, after the last line. Subprocesses with Ctrl-C at its default.

The signal lands where it should without timing luck: a ``sitecustomize`` hook in the child
(``PNEUMORPH_TEST_SLOW`` names a module, or a line the command prints) makes a marker file and
sleeps at that moment; the test waits for the marker, then sends SIGINT. Every case ends with the
one line "aborted", exit 130, and nothing in the output folder.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCAN = ROOT / "examples" / "data" / "scan-0110-30kpa.xyz"

HOOK = '''
import importlib.machinery, os, sys, time

_WHAT = os.environ.get("PNEUMORPH_TEST_SLOW", "")
_MARK = os.environ.get("PNEUMORPH_TEST_MARK", "")


def _stall():
    open(_MARK, "w").close()
    time.sleep(120)  # SIGINT lands here


class _SlowImport:
    def find_spec(self, name, path=None, target=None):
        if name != _WHAT[len("import:"):]:
            return None
        sys.meta_path.remove(self)
        spec = importlib.machinery.PathFinder.find_spec(name, path)
        real = spec.loader.exec_module

        def exec_module(module):
            _stall()
            real(module)

        spec.loader.exec_module = exec_module
        return spec


if _WHAT.startswith("import:"):
    sys.meta_path.insert(0, _SlowImport())
elif _WHAT.startswith("call:"):  # when a function is called: "call:module:name" or "call:module:Class.method"
    _, _MODULE, _NAME = _WHAT.split(":")

    class _SlowCall:
        def find_spec(self, name, path=None, target=None):
            if name != _MODULE:
                return None
            sys.meta_path.remove(self)
            spec = importlib.machinery.PathFinder.find_spec(name, path)
            real = spec.loader.exec_module

            def exec_module(module):
                real(module)
                owner_name, _, attr = _NAME.rpartition(".")
                owner = getattr(module, owner_name) if owner_name else module
                function = getattr(owner, attr)

                def stalled(*args, **kwargs):
                    _stall()
                    return function(*args, **kwargs)

                setattr(owner, attr, stalled)

            spec.loader.exec_module = exec_module
            return spec

    sys.meta_path.insert(0, _SlowCall())
elif _WHAT == "exit":  # after main returned: the last exit handler (registered first, run last)
    import atexit

    atexit.register(_stall)
elif _WHAT.startswith("echo:"):  # after the command prints a line holding this text
    import click

    _echo = click.echo

    def echo(message=None, *args, **kwargs):
        _echo(message, *args, **kwargs)
        if _WHAT[len("echo:"):] in str(message):
            _stall()

    click.echo = echo
'''


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)  # as a shell starts it: Ctrl-C at its default


def _interrupt(tmp_path: Path, slow: str, args: list[str],
               sig: int = signal.SIGINT) -> subprocess.CompletedProcess[str]:
    hook = tmp_path / "hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(HOOK, encoding="utf-8")
    mark = tmp_path / "mark"
    env = {**os.environ, "PYTHONPATH": str(hook), "PNEUMORPH_TEST_SLOW": slow, "PNEUMORPH_TEST_MARK": str(mark),
           "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg", "XDG_CACHE_HOME": str(tmp_path / "xdg")}
    proc = subprocess.Popen([sys.executable, "-m", "pneumorph", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path, start_new_session=True,
                            preexec_fn=_default_sigint)
    deadline = time.monotonic() + 120
    while not mark.exists():
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            out, err = proc.communicate()
            raise AssertionError(f"the run never reached {slow!r}: exit {proc.returncode}\n{err}")
        time.sleep(0.05)
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=120)
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


CORRELATE = ["correlate", str(SCAN), "--design", "0110", "--pressure", "30", "--model", "2d", "--out", "out"]
SIMULATE = ["simulate", "-o", "0110", "--model", "2d", "--pressure", "5", "--increments", "5", "--out", "out"]


@pytest.mark.parametrize(("slow", "args"), [
    ("import:trimesh", CORRELATE),  # the scan reader's lazy import
    ("import:trimesh.voxel", CORRELATE),  # one that trimesh imports under `except BaseException` (swallowed)
    ("import:matplotlib", SIMULATE),  # the figure's, after the solve and the first files
    ("echo:written to", SIMULATE),  # after the last line
], ids=["trimesh", "trimesh-swallowed", "matplotlib-after-solve", "after-last-line"])
def test_ctrl_c_at_any_moment_is_aborted_with_nothing_written(tmp_path: Path, slow: str, args: list[str]) -> None:
    done = _interrupt(tmp_path, slow, args)
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert done.returncode == 130, done.stderr
    assert lines[-1] == "aborted", done.stderr
    assert "Traceback" not in done.stderr and "rror" not in done.stderr
    if slow.startswith("import:"):
        assert not (tmp_path / "out").exists(), sorted(p.name for p in (tmp_path / "out").rglob("*"))


UNIT = "[unit]\nelement_size = 3.0\n"
TRACE = "x,y\n" + "".join(f"{42.0 * i / 119:.4f},{6.0 + 0.002 * (42.0 * i / 119) ** 2:.4f}\n" for i in range(120))


@pytest.mark.slow
@pytest.mark.parametrize(("slow", "args", "outputs"), [
    # the deck, the parts' STL files and the mould's are written; its drawing is next
    ("call:pneumorph.export:plot_mould",
     ["export", "0110", "--unit", "unit.toml", "--stl", "out", "--inp", "deck/a.inp", "--mould"], ["out", "deck"]),
    # study.json is written; the figure is next
    ("call:pneumorph.plot.sensitivity:plot_study",
     ["sensitivity", "tolerances", "--model", "2d", "--units", "2", "--pressure", "5", "--unit", "unit.toml",
      "--samples", "1", "--executor", "serial", "--out", "out"], ["out"]),
    # the table is built and is being written into a new folder
    ("call:pneumorph.models.chain.table:ChainTable.save",
     ["chain", "build", "--model", "2d", "--units", "4", "--pressure", "5", "--unit", "unit.toml", "--window", "1",
      "--heldout", "1", "--executor", "serial", "--out", "new/t.json"], ["new"]),
    # unit optimise, stopped during its search: its folder was made before the search began and stayed, empty
    ("call:pneumorph.unitopt.run:optimise",
     ["unit", "optimise", "--units", "3", "--pop", "4", "--gen", "1", "--element-size", "3.0", "--executor", "serial",
      "--out", "out"], ["out"]),
    # identify: the fit is done; its folder was made before the files
    ("call:pneumorph.identify:write_identified",
     ["identify", "trace.csv", "--design", "0110", "--model", "2d", "--pressure", "5", "--unit", "unit.toml",
      "--executor", "serial", "--out", "out"], ["out"]),
    # study: study.json is written; the figure is next
    ("call:pneumorph.design:plot_population_study",
     ["study", "run.toml", "--populations", "4", "--seeds", "1", "--gen", "1", "--units", "3", "--pressure", "5",
      "--executor", "serial", "--out", "out"], ["out"]),
    # bimodal: the JSON and the tip-path figure are written; the outline figure is next
    ("call:pneumorph.bimodal.figures:plot_outlines",
     ["bimodal", "-c", "0.3", "--voids", "1", "--element-size", "5", "--pmax", "5", "--step", "1.25",
      "--out", "out"], ["out"]),
    # composite coupon: the CSV, the JSON and two figures are written; the third is next
    ("call:pneumorph.composite.figures:plot_surface_strain",
     ["composite", "coupon", "--crimp-ratio", "0.3", "--length", "20", "--per-flute", "1", "--rows", "1", "--levels",
      "24", "--strain-max", "0.9", "--gauges", "20", "--out", "out"], ["out"]),
    # calibrate: calibration.png is written; calibration.json is next
    ("call:pneumorph.calibration.workflow:write_json",
     ["calibrate", "--units", "1", "--pressures", "5,10", "--runs", "1", "--validate", "0", "--out", "out"], ["out"]),
], ids=["export", "sensitivity", "chain-build", "unit-optimise", "identify", "study", "bimodal", "composite",
        "calibrate"])
def test_ctrl_c_while_writing_leaves_nothing(tmp_path: Path, slow: str, args: list[str], outputs: list[str]) -> None:
    """Every command that writes several files writes them all or nothing: stopped midway it leaves no deck,
    study.json, part of the figures or empty folder behind."""
    (tmp_path / "unit.toml").write_text(UNIT, encoding="utf-8")
    (tmp_path / "trace.csv").write_text(TRACE, encoding="utf-8")
    (tmp_path / "run.toml").write_text('[design]\nobjective = "sin"\n[model]\nunit = {element_size = 3.0}\n',
                                       encoding="utf-8")
    done = _interrupt(tmp_path, slow, args)
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert done.returncode == 130 and lines[-1] == "aborted", done.stderr
    assert "Traceback" not in done.stderr
    left = [str(p.relative_to(tmp_path)) for name in outputs if (tmp_path / name).exists()
            for p in [tmp_path / name, *(tmp_path / name).rglob("*")]]
    assert not left, left
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == [
        "hook", "mark", "run.toml", "trace.csv", "unit.toml", "xdg"]


def test_sigterm_inside_a_command_is_terminated_not_aborted(tmp_path: Path) -> None:
    """click turns a KeyboardInterrupt (the CLI's SIGTERM is one) inside a command into Abort: it said
    "aborted", exit 130, for every command but design."""
    done = _interrupt(tmp_path, "echo:simulating design", SIMULATE, signal.SIGTERM)
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert done.returncode == 143 and lines[-1] == "terminated", done.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("sig", "line", "code"), [(signal.SIGINT, "aborted", 130),
                                                  (signal.SIGTERM, "terminated", 143)], ids=["sigint", "sigterm"])
def test_a_signal_after_main_returned_ends_the_process_with_its_line(tmp_path: Path, sig: int, line: str,
                                                                     code: int) -> None:
    """While the interpreter shuts down (exit handlers, threads joined), Ctrl-C and SIGTERM end the run as at any
    other moment: they were ignored (exit 0, no line), and before that a traceback or a kill without a line."""
    done = _interrupt(tmp_path, "exit", SIMULATE, sig)
    lines = [text for text in done.stderr.splitlines() if text.strip()]
    assert done.returncode == code and lines[-1] == line, done.stderr
    assert "Traceback" not in done.stderr and "rror" not in done.stderr
    assert "written to out" in done.stdout  # what the run printed is kept, and its outputs are whole
    assert {"response.json"} <= {p.name for p in (tmp_path / "out").iterdir()}


pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")

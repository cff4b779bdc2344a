"""The fuzz round end to end: bad-but-plausible input on tiny real models, in subprocesses.

``tests/test_cli_fuzz.py`` replaces the solvers by tripwires, so nothing raised after a solve is
reached there. Here the cases of ``benchmarks/fuzz_round.py`` (its seeded generator, loaded from
its file) run with the real 2D solvers: writing, figures and photos after a solve are reached.
A seeded subset of the round runs here (the full round of 400 is the benchmark's); every case
ends with exit 0 (valid input), or exit 2 with one line on stderr, no "internal error" or
traceback and nothing written; a case that reaches a 3D solve is stopped and counts as accepted.
"""

from __future__ import annotations

import sys

import pytest

from tests.benchmark import load

FUZZ = load("fuzz_round")
SUBSET = FUZZ.cases(48, seed=28)
# Cases found by the round of 400 (BENCHMARKS.md), kept as regression cases whatever the seed draws.
_C = FUZZ.case
_BASE = FUZZ.BASE
_TOML = FUZZ.RUN_TOML
FOUND: list[object] = [
    # a photo whose header is whole over a truncated body: read after the solve (internal error, OSError)
    _C("correlate", "photo", "truncated", [*_BASE["correlate"], "--photo", "bad.png"],
       {"bad.png": "BYTES:" + FUZZ._png(64, 48)[:60].hex()}, "refuse"),
    # --plot into a new nested folder: the writer did not make the folder (internal error, FileNotFoundError)
    _C("materials", "out", "nested", ["materials", "fit", "stress.csv", "--model", "yeoh", "--plot",
                                      "deep/new/fit.png"], {}, "run"),
    # gravity of 1e300 mm/s^2: a design run finished on nan scores (exit 0), a study raised IndexError
    _C("design-config", "config", "gravity 1e300", _BASE["design-config"],
       {"run.toml": _TOML.replace("[model]\n", "[model]\ngravity = [1e300, 0]\n")}, "refuse"),
    _C("study", "config", "gravity 1e300", _BASE["study"],
       {"run.toml": _TOML.replace("[model]\n", "[model]\ngravity = [1e300, 0]\n")}, "refuse"),
    # gravity across the actuator breaks the mirror symmetry the exhaustive search assumed: refused after the
    # run had started (config.toml left), naming an API argument; it now solves every design
    _C("design-config", "config", "gravity across", _BASE["design-config"],
       {"run.toml": _TOML.replace("[model]\n", "[model]\ngravity = [0, -9810]\n")}, "run"),
    # a scan of 1e300 mm coordinates: refused, but with an overflow's RuntimeWarning on stderr beside the line
    *(_C(command, "scan", "1e300", _BASE[command], {"trace.csv": "x,y\n" + "1e300,1e300\n" * 50}, "refuse")
      for command in ("correlate", "identify")),
    # a scan spread over 1e305 mm: an overflow's warning and a scan that "spans inf mm"
    _C("correlate", "scan", "1e305 spread", _BASE["correlate"],
       {"trace.csv": "x,y\n" + "".join(f"{i * 1e305:g},{(i % 7) * 1e305:g}\n" for i in range(60))}, "refuse"),
]


def test_the_subset_covers_every_command_and_the_blind_spots() -> None:
    commands = {c.command for c in SUBSET}
    assert commands == set(FUZZ.BASE), set(FUZZ.BASE) - commands
    kinds = {c.mutation for c in SUBSET}
    assert {"out", "unit", "repeat", "valid"} <= kinds, kinds


@pytest.mark.slow
@pytest.mark.parametrize("case", [*SUBSET, *FOUND], ids=lambda c: f"{c.number}-{c.command}-{c.mutation}")
def test_a_fuzz_case_ends_cleanly(case: object) -> None:
    outcome = FUZZ.run_case(case)
    assert outcome.verdict in ("ok", "refused", "3d"), (
        f"{outcome.verdict} (exit {outcome.code}) for {outcome.argv} {case.files}: {outcome.stderr_tail}")


@pytest.mark.parametrize("command", sorted(c for c, argv in _BASE.items() if "--unit" in argv))
def test_a_bad_unit_file_is_blamed_on_the_option(command: str) -> None:
    """sensitivity and chain build named the factory's key ("[model] unit_file: ...") for a bad --unit file."""
    outcome = FUZZ.run_case(_C(command, "unit", "empty", _BASE[command], {"unit.toml": ""}, "refuse"))
    assert outcome.verdict == "refused" and "'--unit'" in outcome.stderr_tail[-1], outcome.stderr_tail


def test_a_base_block_past_the_length_limit_is_refused_before_meshing() -> None:
    """A study with a base block 1e9 mm long grew past 13 GB meshing it (not run as a case: it would again)."""
    from pneumorph.errors import SearchConfigError
    from pneumorph.models.factory import make_model

    with pytest.raises(SearchConfigError, match="MAX_LENGTH_MM"):
        make_model(3, {"fidelity": "2d", "base_block": {"length": 1e9}})


pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX paths (/proc)")

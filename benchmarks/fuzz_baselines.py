"""The command lines every fuzz case starts from: one baseline per command of the tree, and the files they name.

A baseline is a command line that runs, and runs in seconds where it solves (a 2D model of 2-4 units on the coarse
``unit.toml``, low pressures; export needs no solve); a fuzz case spoils one option, argument, file or config key
of it. Three users start from these lines: ``tests/test_cli_fuzz.py`` (in process, the solvers replaced by
tripwires), ``benchmarks/fuzz_inputs.py`` (hostile files and numbers, in subprocesses) and
``benchmarks/fuzz_round.py`` (bad-but-plausible input on the real 2D solvers). The module lives beside the two
benchmarks because a script of ``benchmarks/`` imports only its neighbours, and the tests load benchmark modules
by file (``tests/benchmark.py``); nothing in ``benchmarks/`` imports ``tests/``.

Each baseline writes under ``run`` (a folder, or ``run.json``/``run.png`` beside it), which a user renames to
spoil the output path.
"""

from __future__ import annotations

import os
from pathlib import Path

#: the checkout these benchmarks live in: a case runs its ``src``, whatever the working folder or installed copy
ROOT = Path(__file__).resolve().parents[1]

#: a unit of the built-in cross-section, meshed coarsely: a 2D solve of a few units takes seconds
UNIT = "[unit]\nelement_size = 3.0\n"
#: the design run of ``design run.toml`` and ``study run.toml``: the exhaustive search of 3 units in 2D
RUN_TOML = ('[design]\nobjective = "sin"\nunits = 3\nsearch = "exhaustive"\n\n[model]\nfidelity = "2d"\n'
            'pressure_kpa = 10.0\nincrements = 3\nunit_file = "unit.toml"\n\n[execution]\nexecutor = "serial"\n')
#: the files the baselines name, by name (the scan ``trace.csv`` is each user's own: what it fits differs)
FILES = {
    "unit.toml": UNIT,
    "run.toml": RUN_TOML,
    "stress.csv": "stretch,stress\n1.0,0.0\n1.5,0.2\n2.0,0.35\n2.5,0.5\n",
    "dic.csv": "axial_strain,transverse_strain\n0.1,-0.04\n0.2,-0.08\n",
    "thermal.csv": "temperature,strain\n20,0\n30,0.002\n40,0.004\n",
    "bilinear.csv": "strain,stress\n" + "".join(f"{0.01 * i},{0.1 * i if i < 10 else 1 + 0.01 * i}\n"
                                                 for i in range(40)),
}

#: the studies that vary options of the 3D model only (their --model takes 3d alone; the cases that run stop at
#: the 3D solve)
THREE_D_ONLY = {"simplifications": "3d", "temperature": "3d"}
_2D = ["--model", "2d", "--pressure", "5", "--unit", "unit.toml"]
#: the baseline of every command, by its path in the command tree (``design-config``: the design from a file)
BASE: dict[str, list[str]] = {
    "design": ["design", "--model", "2d", "--units", "3", "--search", "exhaustive", "--pressure", "10", "--unit",
               "unit.toml", "--executor", "serial", "--tolerance", "0", "--out", "run"],
    "design-config": ["design", "run.toml", "--out", "run"],
    "study": ["study", "run.toml", "--populations", "4", "--seeds", "1", "--gen", "1", "--units", "3", "--pressure",
              "5", "--executor", "serial", "--out", "run"],
    "simulate": ["simulate", "-o", "0110", "--model", "2d", "--pressure", "5", "--increments", "3", "--unit",
                 "unit.toml", "--out", "run"],
    "correlate": ["correlate", "trace.csv", "--design", "0110", *_2D, "--out", "run"],
    "identify": ["identify", "trace.csv", "--design", "0110", *_2D, "--executor", "serial", "--out", "run"],
    "export": ["export", "0110", "--unit", "unit.toml", "--stl", "run"],
    "chain build": ["chain", "build", "--model", "2d", "--units", "4", "--pressure", "5", "--unit", "unit.toml",
                    "--window", "1", "--heldout", "1", "--executor", "serial", "--out", "run.json"],
    "unit optimise": ["unit", "optimise", "--units", "3", "--pop", "4", "--gen", "1", "--element-size", "3.0",
                      "--executor", "serial", "--out", "run"],
    "calibrate": ["calibrate", "--units", "2", "--runs", "1", "--validate", "1", "--unit", "unit.toml", "--out",
                  "run"],
    **{f"sensitivity {study}": ["sensitivity", study, "--model", THREE_D_ONLY.get(study, "2d"), "--units", "2",
                                "--pressure", "5", "--unit",
                                "unit.toml", *(["--samples", "1"] if study == "tolerances" else []),
                                "--executor", "serial", "--out", "run"]
       for study in ("simplifications", "tolerances", "bulk-modulus", "calibration", "temperature", "mesh")},
    "scan synth": ["scan", "synth", "0110", *_2D, "--out", "run.csv"],
    "bimodal": ["bimodal", "-c", "0.2", "--out", "run"],
    "composite coupon": ["composite", "coupon", "-c", "0.2", "--out", "run"],
    "composite transition": ["composite", "transition", "-c", "0.2"],
    "materials fit": ["materials", "fit", "stress.csv", "--model", "yeoh", "--plot", "run.png"],
    "materials characterise poisson": ["materials", "characterise", "poisson", "dic.csv"],
    "materials characterise thermal": ["materials", "characterise", "thermal", "thermal.csv"],
    "materials characterise bilinear": ["materials", "characterise", "bilinear", "bilinear.csv"],
    "materials show": ["materials", "show", "mold_star_15"],
    "materials list": ["materials", "list"],
    "serve": ["serve", "--port", "18765", "--state", "run"],
}
#: the options of a baseline that may be given more than once (each value is kept)
REPEATABLE = {"materials fit": ("--model",)}
#: the short name a baseline gives an option
SHORT = {"--orientation": "-o", "--crimp-ratio": "-c"}
#: the options of a baseline that a spoiled option replaces, so that its value is what the command judges: a unit
#: library instead of the unit file, the certified search's options without the exhaustive search, a number of
#: workers with the command's own executor
EXCLUDES = {"--library": ("--unit",), "--refine": ("--search",), "--max-open": ("--search",),
            "--chain-table": ("--search",), "--workers": ("--executor",)}


def spoil(argv: list[str], option: str, value: str) -> list[str]:
    """``argv`` with ``option`` (or a positional file, named by its baseline value) set to ``value``.

    The baseline's value is replaced, or the option added; the options it excludes (:data:`EXCLUDES`) go with
    their values."""
    if not option.startswith("-"):
        return [value if a == option else a for a in argv]
    argv = list(argv)
    for other in EXCLUDES.get(option, ()):
        if other in argv:
            i = argv.index(other)
            del argv[i:i + 2]
    given = option if option in argv else SHORT.get(option, option)
    if given in argv:
        i = argv.index(given)
        return [*argv[:i + 1], value, *argv[i + 2:]]
    return [*argv, option, value]


def case_env(folder: Path) -> dict[str, str]:
    """The environment a case runs in: this checkout's sources first, one thread, no display, a cache and
    ``XDG_CACHE_HOME`` of the case's own folder, no debug tracebacks."""
    source = os.pathsep.join([str(ROOT / "src"), *filter(None, [os.environ.get("PYTHONPATH")])])
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg", "XDG_CACHE_HOME": str(folder / "xdg"),
           "PYTHONPATH": source}
    env.pop("PNEUMORPH_DEBUG", None)
    env.pop("PNEUMORPH_CACHE", None)
    return env

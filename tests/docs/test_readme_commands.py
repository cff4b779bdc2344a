"""Every README command that finishes in seconds runs as written, in order, in one fresh folder.

The commands are read from README.md's ``bash`` blocks of ``.venv/bin/pneumorph`` lines; each is
run through a shell in a temporary folder holding a copy of ``examples/`` (the README's commands
are given from a clone), with ``.venv/bin/`` replaced by this interpreter's bin folder. A command
not skipped by name below (with its reason) is run, so a new README command is tried unless
someone decides it is slow; a skipped name that is no longer in the README fails the test.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
BIN = Path(sys.executable).parent

# Commands that do not finish in seconds, by their text after `.venv/bin/pneumorph `: the reason.
SKIPPED = {
    "simulate -o aRRa --library builtin --model 3d": "a 3D solve",
    "simulate -o bbbbb --library modes --model 3d --pressure 40": "a 3D solve",
    "unit optimise --out runs/unitopt/": "unit optimisation: minutes",
    "design --target cos --amplitude 20 --certify": "a 3D design run: minutes",
    "design --units 8 --search ga --pressure 25": "a 3D GA run: minutes",
    "design --units 10 --pressure 25 --no-build": "a 3D design run with FE verification",
    "design --units 6": "64 designs by 3D FE: minutes",
    "design examples/cos-20.toml": "a 3D design run",
    "design --robust worst --tolerance 0.1": "a 3D design run",
    "design --refine 1.0 --out runs/refined": "a 3D design run and a finer mesh: minutes",
    'design --stage "18:y = 0.05*x" --stage 45:sin --out runs/stages': "a 3D design run at two stages",
    ('design --library examples/libraries/units-bending-bimodal.toml --chain-table '
     'examples/libraries/chain-3d-bending-bimodal-40kpa-far.json --pressure 40 --stage "16:y = 0.0015*x**2" '
     '--stage "40:y = -0.0015*x**2" --certify'): "a 3D design run with 6 FE verifications: minutes",
    "design --library spatial --target helix --amplitude 25 --certify": "full-width 3D verifications: minutes",
    "design --target hook": "a 3D design run: about a minute",
    "sensitivity tolerances --samples 30 --out runs/tol/": "30 3D solves: minutes",
    "sensitivity simplifications --design 001111010001001": "3D solves of a 15-unit design: minutes",
    "chain build --model 3d --out runs/chain-3d.json": "a chain table build: minutes in 3D",
    "chain build --model 3d --out runs/chain-3d-cluster.json --executor dask --scheduler tcp://ws1:8786":
        "needs a Dask cluster",
    "study --units 8 --populations 20,40 --seeds 3": "many GA runs: minutes",
    "bimodal --crimp-ratio 0.2 --end-cap 1.5 --bilinear-nu 0.495 --voids 5 --pmax 35 --out runs/bim/":
        "a 3D ramp: about 80 s",
    "calibrate --units 15 --out runs/cal/": "3D references: long",
    "correlate examples/data/scan-0110-30kpa.xyz --design 0110 --pressure 30 --out runs/corr/": "a 3D solve",
    "identify examples/data/scan-0110-30kpa.xyz --design 0110 --pressure 30 --out runs/ident/": "3D solves: minutes",
}
# The first lines of the README (install, test suite, the bench, the site) are not pneumorph runs.
NOT_RUNS = ("pip install", "pytest", "serve", "sphinx-build")


def readme_commands() -> list[str]:
    """The README's pneumorph command lines, in order, without their trailing comments."""
    text = README.read_text(encoding="utf-8")
    commands = []
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            line = re.sub(r"\s+#.*$", "", line).strip()
            if line.startswith(".venv/bin/pneumorph") and not any(word in line for word in NOT_RUNS):
                commands.append(line)
    return commands


def _key(command: str) -> str:
    return command.removeprefix(".venv/bin/pneumorph").strip()


def test_every_readme_command_is_run_or_skipped_with_a_reason() -> None:
    commands = [_key(c) for c in readme_commands()]
    assert len(commands) >= 20
    assert not set(SKIPPED) - set(commands), f"skipped but not in the README: {set(SKIPPED) - set(commands)}"


@pytest.mark.docs
def test_the_quick_readme_commands_run_as_written(tmp_path: Path) -> None:
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg", "XDG_CACHE_HOME": str(tmp_path / "xdg")}
    ran = []
    for command in readme_commands():
        if _key(command) in SKIPPED:
            continue
        line = command.replace(".venv/bin/", f"{BIN}/", 1)
        done = subprocess.run(line, shell=True, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, f"{command}\n{done.stderr}"
        assert "error" not in done.stderr.lower() and "Traceback" not in done.stderr, f"{command}\n{done.stderr}"
        ran.append(_key(command))
    assert "simulate --orientation 0110 --pressure 20 --out runs/sim/" in ran and len(ran) >= 9, ran
    # what the commands wrote is under runs/ (ignored by git), beside the examples and the test's own cache
    assert sorted(p.name for p in tmp_path.iterdir()) == ["examples", "runs", "xdg"]


class _Claimed(Exception):
    """Raised instead of a run, once its folder is chosen."""


def test_the_readme_design_runs_never_share_a_folder(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every README design command, in order, writes its own folder: a default folder names every setting that
    changes the answer, so no command meets another's run (each is refused there, naming the folder)."""
    import pneumorph.design
    from pneumorph.cli import main

    claimed: list[str] = []

    def claim(config, model, folder, **kwargs):
        claimed.append(str(folder))
        raise _Claimed(folder)

    monkeypatch.setattr(pneumorph.design, "run_design", claim)
    monkeypatch.chdir(ROOT)
    commands = [_key(c) for c in readme_commands() if _key(c).startswith("design")]
    for command in commands:
        main(shlex.split(command))
        assert len(claimed) == commands.index(command) + 1, f"{command} chose no folder"
    folders = dict(zip(commands, claimed, strict=True))
    assert len(commands) >= 12 and len(set(claimed)) == len(claimed), folders
    assert all(f.startswith("runs/") for f in claimed), folders

"""Every README command runs, in order, in one fresh folder: those that finish in seconds as written, the long ones
at reduced size (a slow test).

The commands are read from README.md's ``bash`` blocks of ``.venv/bin/pneumorph`` lines; each is
run through a shell in a temporary folder holding a copy of ``examples/`` (the README's commands
are given from a clone), with ``.venv/bin/`` replaced by this interpreter's bin folder. A command
not skipped by name below (with its reason) is run, so a new README command is tried unless
someone decides it is slow; a skipped name that is no longer in the README fails the test. The
slow test runs the skipped ones too, with the options of ``REDUCED``, in a git folder with the
clone's ``.gitignore``: no line rewrites another's files, and every file written is ignored.
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
     '--stage "40:y = -0.0015*x**2" --certify'): "a 3D design run with 6 FE verifications: minutes (its library's "
                                                  "only chain table is the 3D one given)",
    "design --library spatial --target helix --amplitude 25 --certify":
        "full-width 3D verifications: minutes (sideways units bend out of any 2D model's plane)",
    "design --target hook": "a 3D design run: about a minute",
    "sensitivity tolerances --samples 30 --out runs/tol/": "30 3D solves: minutes",
    "sensitivity simplifications --design 001111010001001": "3D solves of a 15-unit design: minutes",
    "chain build --model 3d --out runs/chain-3d.json": "a chain table build: minutes in 3D",
    "chain build --model 3d --out runs/chain-3d-cluster.json --executor dask --scheduler tcp://ws1:8786":
        "needs a Dask cluster",
    "study --units 8 --populations 20,40 --seeds 3": "many GA runs on the 3D model: minutes (no --model option)",
    "bimodal --crimp-ratio 0.2 --voids 5 --out runs/bim/":
        "a 3D ramp: about 30 s",
    "calibrate --units 15 --out runs/cal/": "3D references: long",
    "correlate examples/data/scan-0110-30kpa.xyz --design 0110 --pressure 30 --out runs/corr/": "a 3D solve",
    "identify examples/data/scan-0110-30kpa.xyz --design 0110 --pressure 30 --out runs/ident/": "3D solves: minutes",
}
# The long commands at reduced size, by one rule (:func:`reduce`): each option here replaces the README line's own
# value, or is added; the 3D model becomes the 2D model where the command has one, else a coarse unit
# (``{coarse}``: a unit meshed at 4 mm) and fewer units, samples, generations or pressures. Commands the rule
# cannot shrink stay skipped, with their reason, in ``STILL_SKIPPED``.
REDUCED = {
    "simulate -o aRRa --library builtin --model 3d": "--model 2d",
    "simulate -o bbbbb --library modes --model 3d --pressure 40": "--model 2d",
    "unit optimise --out runs/unitopt/": "--element-size 4 --pressure 10 --pop 4 --gen 1 --executor serial",
    "design --target cos --amplitude 20 --certify": "--model 2d",
    "design --units 8 --search ga --pressure 25": "--model 2d --pop 8 --gen 2",
    "design --units 10 --pressure 25 --no-build": "--model 2d",
    "design --units 6": "--model 2d --units 4",
    "design examples/cos-20.toml": "--model 2d",
    "design --robust worst --tolerance 0.1": "--model 2d --robust-samples 4",
    "design --refine 1.0 --out runs/refined": "--model 2d",
    'design --stage "18:y = 0.05*x" --stage 45:sin --out runs/stages': "--model 2d",
    "design --target hook": "--model 2d",
    "sensitivity tolerances --samples 30 --out runs/tol/": "--model 2d --units 4 --samples 2",
    "sensitivity simplifications --design 001111010001001": "--design 0110 --unit {coarse}",
    "chain build --model 3d --out runs/chain-3d.json": "--model 2d --window 2 --heldout 2",
    "bimodal --crimp-ratio 0.2 --voids 5 --out runs/bim/":
        "--voids 2 --element-size 4",
    "calibrate --units 15 --out runs/cal/": "--units 4 --pressures 10,20 --runs 1 --validate 1 --unit {coarse}",
    "correlate examples/data/scan-0110-30kpa.xyz --design 0110 --pressure 30 --out runs/corr/": "",
    "identify examples/data/scan-0110-30kpa.xyz --design 0110 --pressure 30 --out runs/ident/": "--fit wall",
}
STILL_SKIPPED = {
    key: reason for key, reason in SKIPPED.items() if key not in REDUCED
}
COARSE_UNIT = "[unit]\nelement_size = 4.0\n"
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


def reduce(command: str, options: str) -> str:
    """``command`` with each of ``options`` (``--name value...`` or a flag) replacing its own value, or added.

    >>> reduce('pneumorph design --units 6 --target "y = x"', "--units 4 --model 2d")
    "pneumorph design --units 4 --target 'y = x' --model 2d"
    >>> reduce("pneumorph correlate scan.xyz", "")
    'pneumorph correlate scan.xyz'
    """
    words = shlex.split(command)
    given = shlex.split(options)
    starts = [i for i, w in enumerate(given) if w.startswith("--")]
    for start, end in zip(starts, [*starts[1:], len(given)][:len(starts)], strict=True):
        name, values = given[start], given[start + 1:end]
        if name in words:
            at = words.index(name)
            words[at + 1:at + 1 + len(values)] = values
        else:
            words += [name, *values]
    return shlex.join(words)


def _key(command: str) -> str:
    return command.removeprefix(".venv/bin/pneumorph").strip()


def test_every_readme_command_is_run_or_skipped_with_a_reason() -> None:
    commands = [_key(c) for c in readme_commands()]
    assert len(commands) >= 20
    assert not set(SKIPPED) - set(commands), f"skipped but not in the README: {set(SKIPPED) - set(commands)}"
    assert set(REDUCED) <= set(SKIPPED), set(REDUCED) - set(SKIPPED)


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


def _files(folder: Path) -> dict[str, tuple[int, int]]:
    """Every file under ``folder`` (its ``.git`` left out): its size and modification time."""
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns) for p in folder.rglob("*")
            if p.is_file() and ".git" not in p.relative_to(folder).parts}


@pytest.mark.slow
@pytest.mark.docs
def test_every_readme_line_runs_in_order_at_reduced_size(tmp_path: Path) -> None:
    """Every README line in order in a fresh clone (git, with the README's examples and .gitignore), the long ones
    at reduced size (``REDUCED``): exit 0, no line rewrites what an earlier one wrote, and every file written is
    ignored by git."""
    clone = tmp_path / "clone"
    clone.mkdir()
    shutil.copytree(ROOT / "examples", clone / "examples")
    shutil.copy(ROOT / ".gitignore", clone / ".gitignore")
    subprocess.run(["git", "init", "-q"], cwd=clone, check=True)
    coarse = tmp_path / "coarse-unit.toml"
    coarse.write_text(COARSE_UNIT, encoding="utf-8")
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg", "XDG_CACHE_HOME": str(tmp_path / "xdg")}
    before = _files(clone)
    written: dict[str, str] = {}
    for command in readme_commands():
        key = _key(command)
        if key in STILL_SKIPPED:
            continue
        line = command.replace(".venv/bin/", f"{BIN}/", 1)
        if key in REDUCED:
            line = reduce(line, REDUCED[key].format(coarse=coarse))
        done = subprocess.run(line, shell=True, cwd=clone, env=env, capture_output=True, text=True, timeout=900)
        assert done.returncode == 0, f"{line}\n{done.stderr}"
        after = _files(clone)
        rewritten = [f for f in after if f in before and after[f] != before[f]]
        assert not rewritten, f"{line} rewrote {[(f, written.get(f, 'the clone')) for f in rewritten]}"
        written.update((f, key) for f in after if f not in before)
        before = after
    assert len(set(written.values())) > 10, written  # the commands wrote their outputs, each its own
    ignored = subprocess.run(["git", "check-ignore", "--stdin"], cwd=clone, input="\n".join(written),
                             capture_output=True, text=True).stdout.split()
    assert not set(written) - set(ignored), {f: written[f] for f in set(written) - set(ignored)}

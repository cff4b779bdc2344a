"""The loop tutorial (docs/tutorials/loop.md) runs as written: its commands in order in a fresh folder, each
printing what the page shows (timings and cache counts aside), and the loop finds the cast that was put in."""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

PAGE = Path(__file__).resolve().parents[2] / "docs" / "tutorials" / "loop.md"
BIN = Path(sys.executable).parent


def steps() -> list[tuple[str, str, list[str]]]:
    """The page's blocks in order: ("file", path, lines) for a TOML block whose first line names its file, and
    ("run", command, printed lines) for each command of a console block."""
    out: list[tuple[str, str, list[str]]] = []
    for kind, body in re.findall(r"```(console|toml)\n(.*?)```", PAGE.read_text(encoding="utf-8"), flags=re.S):
        lines = body.splitlines()
        if kind == "toml":
            assert lines[0].startswith("# "), "a TOML block names its file on its first line"
            out.append(("file", lines[0][2:].strip(), lines[1:]))
            continue
        for line in lines:
            if line.startswith("$ "):
                out.append(("run", line[2:], []))
            else:
                out[-1][2].append(line)
    return out


def comparable(line: str) -> str | None:
    """A printed line as the page may show it, or None for lines whose numbers depend on the machine or cache."""
    if line.strip().startswith("...") or "..." in line or "cache hits" in line:
        return None
    return re.sub(r"\s+", " ", line).strip()


def test_the_page_has_the_whole_loop() -> None:
    commands = [s[1].split()[1] for s in steps() if s[0] == "run"]
    assert commands == ["design", "export", "scan", "scan", "identify", "identify", "design"]


@pytest.mark.docs
def test_the_loop_runs_as_written_and_finds_the_cast(tmp_path: Path) -> None:
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg", "XDG_CACHE_HOME": str(tmp_path / "xdg")}
    for kind, text, lines in steps():
        if kind == "file":
            path = tmp_path / text
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text("\n".join(lines) + "\n", encoding="utf-8")
            continue
        argv = shlex.split(text)
        argv[0] = str(BIN / "pneumorph")
        done = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, f"{text}\n{done.stderr}"
        printed = {comparable(line) for line in done.stdout.splitlines()}
        for line in lines:
            shown = comparable(line)
            if shown is not None:
                assert shown in printed, f"{text}: the page shows\n{line}\nbut it printed\n{done.stdout}"
    # what identify found, against the truth the scans were made with
    truth = json.loads((tmp_path / "runs/loop/scans/00101-30kpa.csv.json").read_text())["changes"]
    result = json.loads((tmp_path / "runs/loop/identified/identify.json").read_text())
    found = result["parameters"]
    for name, value in (("body_shear_scale", truth["body_shear_scale"]), ("wall", truth["wall"]), ("layer", 3.0)):
        p = found[name]
        assert p["identified"] and abs(p["value"] - value) < 3 * p["standard_error"], (name, p, value)

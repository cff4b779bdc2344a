"""A documentation page's console blocks run as written: each command in order in one folder, printing what the
page shows (durations, cache counts and round-off aside)."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

BIN = Path(sys.executable).parent

#: a duration ("0.33 s", "about 15 s each"): the machine's, not the command's
_DURATION = re.compile(r"\b\d+(?:\.\d+)? s\b")
#: a number in scientific notation below 1e-9: round-off, whose digits depend on the machine's arithmetic
_ROUND_OFF = re.compile(r"\b\d(?:\.\d+)?e-(?:\d{3}|[1-9]\d)\b")


def steps(page: Path) -> list[tuple[str, str, list[str]]]:
    """The page's blocks in order: ("file", path, lines) for a TOML block whose first line names its file, and
    ("run", command, printed lines) for each command of a console block."""
    out: list[tuple[str, str, list[str]]] = []
    for kind, body in re.findall(r"```(console|toml)\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S):
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
    line = _ROUND_OFF.sub("0", _DURATION.sub("T s", line))
    return re.sub(r"\s+", " ", line).strip()


def run_page(page: Path, folder: Path) -> None:
    """Run every step of ``page`` in ``folder`` (a fresh evaluation cache in it): each command exits 0, or 2 where
    the page shows an ``error:`` line, and prints every comparable line the page shows."""
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg", "XDG_CACHE_HOME": str(folder / "xdg")}
    for kind, text, lines in steps(page):
        if kind == "file":
            path = folder / text
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text("\n".join(lines) + "\n", encoding="utf-8")
            continue
        argv = shlex.split(text)
        argv[0] = str(BIN / "pneumorph")
        done = subprocess.run(argv, cwd=folder, env=env, capture_output=True, text=True, timeout=900)
        expected = 2 if any(line.startswith("error:") for line in lines) else 0
        assert done.returncode == expected, f"{text}\n{done.stderr}"
        printed = {comparable(line) for line in (done.stdout + done.stderr).splitlines()}
        for line in lines:
            shown = comparable(line)
            if shown is not None:
                assert shown in printed, f"{text}: the page shows\n{line}\nbut it printed\n{done.stdout}{done.stderr}"

"""Every ``python`` block of the documentation's pages runs as written, and prints what the page shows.

A page's ``python`` blocks run in order as one script (``python page.py``, so a block's
``if __name__ == "__main__":`` guard holds), in a fresh folder holding a copy of
``examples/``, with a fresh evaluation cache: what a reader who pastes them gets. A ``text``
block that is the next block after a ``python`` one is what that block prints; it is
compared with the real output line by line, numbers to a relative 1e-3 (the last digit
printed of an FE value may differ between machines' linear algebra).

A page whose blocks take more than a few seconds carries a marker, with its cost, in
:data:`COST`; a page whose example is a long run is run as its cheaper twin, with the
edits and their reason in :data:`TWINS`.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
SEPARATOR = "---- next block ----"

# pages whose blocks are not quick: the marker and the cost
COST = {
    "api.md": ("docs", "a certified design run (its 2D twin: about 10 s)"),
    "extending.md": ("docs", "a design run of 16 designs by 2D FE"),
    "tutorials/certified-design.md": ("docs", "a certified 3D design run: about a minute"),
    "bimodal.md": ("slow", "a 3-void bimodal actuator's volume ramp, 11,361 dofs: 10-34 s on 2 busy cores"),
    "composite.md": ("slow", "a 3D coupon's tension test, 27 s"),
    "unit-library.md": ("slow", "a full-width 3D solve, 108,894 unknowns"),
}
# edits that turn a page's long example into a quick twin: (old, new), and why
TWINS = {
    "api.md": ([("units=15)", 'units=15, model={"fidelity": "2d"})')],
               "the page's run is the 3D run of the defaults; its 2D twin runs the same calls"),
}


def blocks(page: Path) -> list[tuple[str, str | None]]:
    """Each ``python`` block of ``page`` and the ``text`` block right after it (what it prints), or None."""
    fenced = re.findall(r"^```(\w*)\n(.*?)^```$", page.read_text(encoding="utf-8"), flags=re.M | re.S)
    return [(code, fenced[i + 1][1] if i + 1 < len(fenced) and fenced[i + 1][0] == "text" else None)
            for i, (lang, code) in enumerate(fenced) if lang == "python"]


def pages() -> list[str]:
    return sorted(str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md") if "_build" not in p.parts and blocks(p))


def same_output(shown: str, printed: str) -> list[str]:
    """Lines of ``shown`` that ``printed`` does not match: the same words, numbers to 1e-3 relative."""
    number = r"-?\d+(?:\.\d+)?(?:e-?\d+)?"
    want, got = shown.strip().splitlines(), printed.strip().splitlines()
    if len(want) != len(got):
        return [f"{len(want)} lines shown, {len(got)} printed: {got}"]
    out = []
    for a, b in zip(want, got, strict=True):
        words_a, words_b = re.sub(number, "#", a).split(), re.sub(number, "#", b).split()
        close = all(math.isclose(float(x), float(y), rel_tol=1e-3, abs_tol=1e-9)
                    for x, y in zip(re.findall(number, a), re.findall(number, b), strict=False))
        if words_a != words_b or not close or len(re.findall(number, a)) != len(re.findall(number, b)):
            out.append(f"shown {a!r}, printed {b!r}")
    return out


def test_the_output_comparison_can_fail() -> None:
    assert not same_output("winner 0011 at 9 kPa: 1.004 mm\n", "winner 0011 at 9 kPa: 1.0041 mm")
    assert same_output("winner 0011 at 9 kPa: 1.004 mm", "winner 0011 at 9 kPa: 1.104 mm")
    assert same_output("certified True", "certified False")
    assert same_output("a\nb", "a")


def test_every_marked_page_has_blocks() -> None:
    found = pages()
    assert {"api.md", "tutorials/parts-and-moulds.md"} <= set(found)
    assert set(COST) <= set(found) and set(TWINS) <= set(found), set(COST) - set(found)


def run_page(name: str, folder: Path) -> list[str]:
    """Run the page's blocks in ``folder``; what each block printed."""
    pairs = blocks(DOCS / name)
    script = f"\nprint({SEPARATOR!r}, flush=True)\n".join(code for code, _ in pairs)
    edits, _why = TWINS.get(name, ([], ""))
    for old, new in edits:
        assert old in script, f"{name}: the twin's edit {old!r} no longer applies"
        script = script.replace(old, new)
    shutil.copytree(ROOT / "examples", folder / "examples")
    (folder / "page.py").write_text(script, encoding="utf-8")
    env = {**os.environ, "MPLBACKEND": "Agg", "OMP_NUM_THREADS": "1", "PNEUMORPH_CACHE": str(folder / "cache.sqlite")}
    done = subprocess.run([sys.executable, "page.py"], cwd=folder, capture_output=True, text=True, env=env,
                          timeout=1200)
    assert done.returncode == 0, f"{name}:\n{done.stderr[-3000:]}"
    printed = done.stdout.split(SEPARATOR + "\n")
    assert len(printed) == len(pairs)
    for (_, shown), out in zip(pairs, printed, strict=True):
        if shown is not None and name not in TWINS:
            assert not same_output(shown, out), (name, same_output(shown, out))
    return printed


@pytest.mark.parametrize("name", [pytest.param(name, marks=getattr(pytest.mark, COST[name][0]) if name in COST else ())
                                  for name in pages()])
def test_the_pages_python_runs_and_prints_what_it_shows(name: str, tmp_path: Path) -> None:
    printed = run_page(name, tmp_path)
    if name == "api.md":  # the 2D twin prints the page's lines with its own numbers, and writes the run folder
        lines = printed[0].splitlines()
        assert re.fullmatch(r"[01]{15}: Eq 4\.1 error \d+\.\d+ mm at \d+(\.\d+)? kPa", lines[0]), lines
        assert lines[1] == "certified: True"
        assert lines[2].startswith("Certified: of the 32,768 designs scored by the chain model, none can beat ")
        assert lines[4].startswith("Verified by FE (2d): ")
        assert (tmp_path / "runs" / "api-sin" / "report.md").is_file()

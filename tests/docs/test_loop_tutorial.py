"""The loop tutorial (docs/tutorials/loop.md) runs as written: its commands in order in a fresh folder, each
printing what the page shows (timings and cache counts aside), and the loop finds the cast that was put in."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.docs.console import run_page, steps

PAGE = Path(__file__).resolve().parents[2] / "docs" / "tutorials" / "loop.md"


def test_the_page_has_the_whole_loop() -> None:
    commands = [s[1].split()[1] for s in steps(PAGE) if s[0] == "run"]
    assert commands == ["design", "export", "scan", "scan", "identify", "identify", "design"]


@pytest.mark.docs
def test_the_loop_runs_as_written_and_finds_the_cast(tmp_path: Path) -> None:
    run_page(PAGE, tmp_path)
    # what identify found, against the truth the scans were made with
    truth = json.loads((tmp_path / "runs/loop/scans/00101-30kpa.csv.json").read_text())["changes"]
    result = json.loads((tmp_path / "runs/loop/identified/identify.json").read_text())
    found = result["parameters"]
    for name, value in (("body_shear_scale", truth["body_shear_scale"]), ("wall", truth["wall"]), ("layer", 3.0)):
        p = found[name]
        assert p["identified"] and abs(p["value"] - value) < 3 * p["standard_error"], (name, p, value)

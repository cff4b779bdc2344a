"""The tutorials other than the loop (tests/docs/test_loop_tutorial.py) run as written: each page's commands in
order in a fresh folder, printing what the page shows."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.docs.console import comparable, run_page, steps

TUTORIALS = Path(__file__).resolve().parents[2] / "docs" / "tutorials"
PAGES = ["first-design.md", "certified-design.md", "parts-and-moulds.md"]


def test_every_tutorial_with_commands_is_run_by_a_test() -> None:
    pages = {p.name for p in TUTORIALS.glob("*.md") if any(s[0] == "run" for s in steps(p))}
    assert pages == {*PAGES, "loop.md"}


def test_durations_and_round_off_are_what_a_page_may_show_differently() -> None:
    assert comparable("chain: 32,768 designs scored in 0.33 s; best 1") == \
        "chain: 32,768 designs scored in T s; best 1"
    assert comparable("largest overlap 2.2e-16 mm^3") == comparable("largest overlap 7.1e-15 mm^3")
    assert comparable("error 1.004 mm") != comparable("error 1.005 mm")  # results are compared digit for digit
    assert comparable("a wall 1e-3 mm") != comparable("a wall 2e-3 mm")


@pytest.mark.docs
@pytest.mark.parametrize("page", PAGES)
def test_the_tutorial_runs_as_written(page: str, tmp_path: Path) -> None:
    run_page(TUTORIALS / page, tmp_path)

"""Designs that clear an obstacle at a lower pressure and grip it at a higher one: the clearance the FE model reports,
the chain's screen of the designs that cannot clear (:mod:`pneumorph.design.certified.clearing`) and the goal in a
run (:class:`~pneumorph.design.objectives.contact.Clearance`)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pneumorph.design import DesignConfig, run_design
from pneumorph.design.certified.clearing import ClearingScreen, chain_clearance, clearing_screen
from pneumorph.design.objectives.contact import Clearance, ContactGoal, contact_values
from pneumorph.design.search.scoring import ScoreBook
from pneumorph.errors import SearchConfigError
from pneumorph.execution import EvaluationCache, SerialEvaluator
from pneumorph.models.fe import Reduced2D

ROOT = Path(__file__).resolve().parents[2]
#: the object of examples/grasp/clear-2d.toml: in the path of a five-unit finger that bends up
CYLINDER = {"kind": "cylinder", "centre": [50.0, 24.0], "radius": 5.0}
#: clear it by 1 mm at 27 kPa (level 5 of 4.5-45 kPa), grip it above
CLEAR = {"pressure_kpa": 27.0, "clearance_mm": 1.0}


def config(**changes: object) -> DesignConfig:
    settings = {"objective": "grip", "units": 5, "search": "exhaustive", "executor": "serial", "tolerance": 0.0,
                "model": {"fidelity": "2d", "obstacle": [CYLINDER]}, "clear": CLEAR, **changes}
    return DesignConfig(**settings)  # type: ignore[arg-type]


@pytest.mark.parametrize(("changes", "match"), [
    ({"objective": "max-y"}, r"\[design.clear\] applies to a contact goal"),
    ({"clear": {"pressure_kpa": 27.0, "clearance": 1.0}}, r"must be a table of pressure_kpa"),
    ({"clear": {"clearance_mm": 1.0}}, r"must be a table of pressure_kpa"),
    ({"clear": {"pressure_kpa": float("nan")}}, r"pressure_kpa must be a finite number > 0 \(kPa\), got nan"),
    ({"clear": {"pressure_kpa": 27.0, "clearance_mm": -0.5}}, r"clearance_mm must be a finite number >= 0"),
    ({"clear": {"pressure_kpa": 27.0, "clearance_mm": True}}, r"clearance_mm must be a finite number"),
])
def test_a_bad_clearance_is_refused_in_the_settings(changes: dict[str, object], match: str) -> None:
    with pytest.raises(SearchConfigError, match=match):
        config(**changes)


@pytest.mark.parametrize("kpa", [25.0, 45.0])
def test_a_clearance_off_the_levels_below_the_top_is_refused_before_the_folder(tmp_path: Path, kpa: float) -> None:
    c = config(clear={"pressure_kpa": kpa})
    with pytest.raises(SearchConfigError, match=rf"pressure_kpa = {kpa:g}: must be a level of the model's ramp below "
                                                r"its top, one of 4\.5, 9, .*, 40\.5 kPa"):
        run_design(c, c.make_model(), tmp_path / "run")
    assert not (tmp_path / "run").exists()


def test_the_settings_keep_the_clearance() -> None:
    c = config()
    assert c.make_objective() == ContactGoal("grip", Clearance(0.027, 1.0))
    assert DesignConfig.from_dict(c.to_dict()).clear == CLEAR


def test_the_chain_rejects_only_designs_fe_finds_too_close() -> None:
    """The screen's certificate against FE with contact: the design it rejects does not clear by FE, and its free
    shape comes within the clearance; a design it keeps is solved, clears by FE and grips above the clearing level.
    The clearance FE reports is the least distance of any node to the cylinder, computed here from the fields."""
    model = Reduced2D(5, obstacles=[CYLINDER])
    goal = config().make_objective()
    assert isinstance(goal, ContactGoal) and goal.clear is not None

    solved: list[str] = []

    class Counting:
        def iter_evaluate(self, m: object, designs: list[str]):  # type: ignore[no-untyped-def]
            solved.extend(designs)
            return iter(())

    screen, note = clearing_screen(Counting(), model, goal)
    assert isinstance(screen, ClearingScreen) and "rejected without a solve" in note
    assert screen.level == 5 and 0.0 < screen.error < 0.1  # mm: the 2D table's validated error at 27 kPa
    outcomes = screen.evaluate_many(model, ["00000", "00110"])
    assert outcomes[0] is not None and "does not clear at 27 kPa" in (outcomes[0].failure or "")
    assert solved == ["00110"]  # only the kept design goes on to FE
    assert outcomes[0].screened and not outcomes[0].solved
    book = ScoreBook(model, goal, screen)  # a search's count of solves leaves out what the screen answered
    book.score_many(["00000"])
    assert (book.solves, book.hits) == (0, 0) and solved == ["00110"]
    assert chain_clearance(screen.chain, "00000", 5, screen.obstacles) < 1.0 - screen.error
    c = np.array(CYLINDER["centre"])
    for design, clears in (("00000", False), ("00110", True)):
        solution = model.solve(design)
        contact = solution.response.metadata["contact"]
        gaps = [level["obstacles"][0]["clearance_mm"] for level in contact["levels"]]
        x = solution.mesh.points[None] + solution.displacements
        nodes = np.linalg.norm(x - c, axis=2).min(axis=1) - CYLINDER["radius"]
        free = [k for k, level in enumerate(contact["levels"]) if not level["obstacles"][0]["nodes_in_contact"]]
        assert free and np.allclose(np.array(gaps)[free], nodes[free], rtol=0, atol=1e-9)
        values = contact_values(solution.response, goal)
        assert (gaps[5] >= 1.0) == clears
        if clears:  # the grip counts above 27 kPa only, and the finger presses on the cylinder at 45 kPa
            assert np.isnan(values[:6]).all() and values[-1] > 0.1  # N
        else:
            assert np.isnan(values).all()


@pytest.mark.slow
def test_a_clearing_design_in_2d_end_to_end(tmp_path: Path) -> None:
    """Every one of the 32 designs scored: the chain rejects two without a solve, FE with contact solves the other
    30; the winner clears at 27 kPa and grips at 45 kPa, and the report says what is certified and what searched."""
    c = config()
    with EvaluationCache(tmp_path / "cache.sqlite") as cache:
        result = run_design(c, c.make_model(), tmp_path / "run", evaluator=SerialEvaluator(), cache=cache,
                            figures=False)
    assert result.solves == 30
    best = result.best
    assert best is not None and best.response is not None and best.design == "00110"
    levels = best.response.metadata["contact"]["levels"]
    assert levels[5]["obstacles"][0]["clearance_mm"] >= 1.0
    assert best.value == pytest.approx(levels[-1]["obstacles"][0]["force_magnitude_n"], rel=1e-12) and best.value > 0.1
    report = (tmp_path / "run" / "report.md").read_text(encoding="utf-8")
    assert "Certified by the chain's bound" in report and "Searched by FE with contact" in report
    # the example, by the command line, finds the same winner (its 30 designs from the cache)
    done = subprocess.run([sys.executable, "-m", "pneumorph", "design", str(ROOT / "examples" / "grasp" /
                           "clear-2d.toml"), "--out", str(tmp_path / "example"), "--cache",
                           str(tmp_path / "cache.sqlite")], capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "best design 00110" in done.stdout


def test_the_command_line_takes_the_clearance_to_the_run(tmp_path: Path) -> None:
    """``--clear KPA:MM`` reaches the run: a pressure off the ramp's levels is refused there, before any solve."""
    model = tmp_path / "model.toml"
    model.write_text('[model]\nfidelity = "2d"\n\n[[model.obstacle]]\nkind = "cylinder"\ncentre = [50.0, 24.0]\n'
                     'radius = 5.0\n', encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "pneumorph", "design", "--objective", "grip", "--clear", "25:1",
                           "--model-file", str(model), "--units", "5", "--search", "exhaustive", "--out",
                           str(tmp_path / "run"), "--cache", str(tmp_path / "cache.sqlite")],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 2, done.stderr[-2000:]
    assert "[design.clear] pressure_kpa = 25: must be a level of the model's ramp below its top" in done.stderr
    assert "Traceback" not in done.stderr and not (tmp_path / "run").exists()

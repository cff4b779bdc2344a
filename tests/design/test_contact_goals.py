"""Designs for a task with contact: the grip force on an obstacle and the wrap, maximised over designs solved by FE with
contact (:mod:`pneumorph.design.objectives.contact`)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pneumorph.design import DesignConfig, run_design
from pneumorph.design.objectives.contact import ContactGoal
from pneumorph.design.objectives.targets import make_objective
from pneumorph.errors import SearchConfigError
from pneumorph.execution import EvaluationCache, SerialEvaluator

ROOT = Path(__file__).resolve().parents[2]
CYLINDER = {"kind": "cylinder", "centre": [38.0, 22.0], "radius": 4.0}


def test_grip_and_wrap_are_objectives_that_need_obstacles(tmp_path: Path) -> None:
    assert make_objective("grip") == ContactGoal("grip") and make_objective("wrap").sense == "max"
    with pytest.raises(SearchConfigError, match="tip point"):
        make_objective("grip", point=(1.0, 2.0))
    config = DesignConfig(objective="grip", units=3, search="exhaustive", executor="serial", tolerance=0.0,
                          model={"fidelity": "2d"})
    with pytest.raises(SearchConfigError, match=r"needs obstacles .*\[\[model.obstacle\]\]"):
        run_design(config, config.make_model(), tmp_path / "run")
    assert not (tmp_path / "run").exists()  # refused before the folder is touched


def test_a_grip_design_on_a_cylinder_in_2d(tmp_path: Path) -> None:
    """Every design solved with contact; the winner presses hardest on the cylinder, and its report says how."""
    config = DesignConfig(objective="grip", units=3, search="exhaustive", executor="serial", tolerance=0.0,
                          model={"fidelity": "2d", "obstacle": [CYLINDER]})
    model = config.make_model()
    with EvaluationCache(tmp_path / "cache.sqlite") as cache:
        result = run_design(config, model, tmp_path / "run", evaluator=SerialEvaluator(), cache=cache, figures=False)
    assert result.solves == 8  # no mirror symmetry over an obstacle: all 2^3 designs
    best = result.best
    assert best is not None and best.response is not None
    forces = {c.design: c.value for c in result.hall_of_fame}
    levels = best.response.metadata["contact"]["levels"]
    assert best.value == pytest.approx(levels[-1]["obstacles"][0]["force_magnitude_n"], rel=1e-12)
    assert best.value == max(forces.values()) > 0.05  # N: the winner presses on the cylinder at 45 kPa
    assert best.level == len(levels) - 1  # pressing harder as the pressure rises
    # designs that curl away from the cylinder (down: units of 1 near the base) never touch it
    assert min(forces.values()) == 0.0
    report = (tmp_path / "run" / "report.md").read_text(encoding="utf-8")
    assert "solved by FE with contact" in report and "nothing is certified" in report
    assert "maximum grip force on the obstacles (N)" in report
    # the wrap of the same designs, from the cache
    wrap = DesignConfig(**{**config.__dict__, "objective": "wrap"})
    with EvaluationCache(tmp_path / "cache.sqlite") as cache:
        result = run_design(wrap, model, tmp_path / "wrap", evaluator=SerialEvaluator(), cache=cache, figures=False)
    assert result.solves == 0
    assert result.best is not None and np.isfinite(result.best.value) and result.best.value > 0.0  # mm


@pytest.mark.slow
@pytest.mark.parametrize("name", ["grip-2d", "grip-3d"])
def test_the_grip_examples_run_end_to_end(tmp_path: Path, name: str) -> None:
    config = ROOT / "examples" / "grasp" / f"{name}.toml"
    done = subprocess.run([sys.executable, "-m", "pneumorph", "design", str(config), "--out", str(tmp_path / name),
                           "--cache", str(tmp_path / "cache.sqlite")], capture_output=True, text=True, timeout=1800)
    assert done.returncode == 0, done.stderr[-2000:]
    report = (tmp_path / name / "report.md").read_text(encoding="utf-8")
    assert "- search: exhaustive search" in report and "nothing is certified" in report

"""The profile figure of a run: a y-axis that fits the target and the shape, a target named in words."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from pneumorph.design.objectives.fitness import score
from pneumorph.design.objectives.targets import make_objective
from pneumorph.design.runs import figures
from pneumorph.design.search.scoring import Candidate
from tests.design.toy_model import ToyModel


def test_the_profile_spans_the_target_not_five_times_it(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """A +-10 mm target was drawn on a y-axis of +-50 mm (half the plot empty), labelled `2*pi*1*x/L`."""
    drawn: list[Any] = []
    monkeypatch.setattr(figures, "save_figure", lambda fig, path: drawn.append(fig) or Path(path))
    model = ToyModel(n_units=15, turn=4.0)
    design = "000011111110000"
    response = model.evaluate(design)
    objective = make_objective("sin", 10.0, length=float(response.reference_tip[0]))
    s = score(response, objective)
    figures.plot_profile(Candidate(design, float(s.value), s.level, float(response.pressures[s.level]), None,
                                   response), objective, tmp_path / "profile.png")
    ax = drawn[0].axes[0]
    lo, hi = ax.get_ylim()
    shape = next(line.get_ydata() for line in ax.get_lines() if line.get_label() == "actuator centreline")
    reach = max(10.0, float(abs(shape).max()))
    assert -1.5 * reach - 10 <= lo <= -reach and reach <= hi <= 1.5 * reach + 10, (lo, hi, reach)
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    target = next(label for label in labels if label.startswith("target"))
    assert "A = 10 mm" in target and "2*pi*1*x/L" not in target, labels  # the formula, not the raw expression

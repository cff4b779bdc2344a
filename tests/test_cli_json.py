"""A long command's ``--json``: standard output holds the JSON alone, standard error keeps the plan and the progress.

Each command runs with its solver replaced by a stub that reports every level as it converges (as the real one
does) and returns a result of the shape the command prints; its output must parse as JSON, and standard error
must hold the plan line and the count of the last level.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import pytest

from pneumorph.cli import main


def _stub_simulate(monkeypatch: pytest.MonkeyPatch) -> None:
    """FEModel.solve: the undeformed shape at every level, each level reported."""
    from pneumorph.models.fe.base import FEModel

    def solved(self: FEModel, orientation: str, on_level: Any = None) -> Any:
        response = self.empty_response(self.mesh(orientation), orientation)
        for k, p in enumerate(self.pressures()):
            response.centres[k], response.tip[k], response.curl[k] = response.reference_centres, \
                response.reference_tip, 0.0
            on_level(k, p)
        return SimpleNamespace(response=replace(response, converged=True, reached=float(response.pressures[-1])))

    monkeypatch.setattr(FEModel, "solve", solved)


def _stub_bimodal(monkeypatch: pytest.MonkeyPatch) -> None:
    """BimodalModel.solve: each level reported, a completed ramp's result."""
    from pneumorph.bimodal.model import BimodalModel

    def solved(self: BimodalModel, on_level: Any = None) -> Any:
        for k in range(2):
            on_level(k, 0.0025 * (k + 1), 0.1 * k)
        return SimpleNamespace(completed=True, to_dict=lambda: {"crimp_ratio": 0.2, "tip_uy_mm": [0.0, 0.1]})

    monkeypatch.setattr(BimodalModel, "solve", solved)


#: command line, its solver's stub, what its plan line starts with, the count of its last level
COMMANDS: dict[str, tuple[list[str], Callable[[pytest.MonkeyPatch], None], str, str]] = {
    "simulate": (["simulate", "-o", "0110", "--increments", "2", "--json"], _stub_simulate, "simulating design 0110",
                 "2/2"),
    "bimodal": (["bimodal", "-c", "0.2", "--voids", "1", "--element-size", "5", "--pmax", "5", "--step", "2.5",
                 "--control", "pressure", "--json"], _stub_bimodal, "bimodal ramp to 5 kPa", "2/2"),
}


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_json_on_standard_output_and_the_progress_on_standard_error(
        name: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    args, stub, plan, last = COMMANDS[name]
    stub(monkeypatch)
    monkeypatch.setattr("pneumorph.io.progress.os.getloadavg", lambda: (0.0, 0.0, 0.0))  # a quiet machine
    code = main(args)
    out, err = capsys.readouterr()
    assert code == 0, err
    data = json.loads(out)
    assert isinstance(data, dict) and data
    lines = err.splitlines()
    assert lines and lines[0].startswith(plan), lines
    assert any(last in line for line in lines[1:]), lines


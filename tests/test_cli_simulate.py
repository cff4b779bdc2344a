"""``pneumorph simulate``: outputs, JSON, errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.models import Response


def test_simulate_writes_every_output_and_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    code = main(["simulate", "-o", "01", "--pressure", "10", "--increments", "2", "--out", str(out), "--json"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert [lvl["pressure_kpa"] for lvl in data["levels"]] == [5.0, 10.0]
    assert len(data["levels"][1]["unit_centres_mm"]) == 2
    for name in ("response.npz", "response.json", "shape.png", "provenance.json", "vtk/actuator.pvd", "vtk/actuator_01.vtu"):
        assert (out / name).is_file(), name
    saved = Response.load(out / "response")
    np.testing.assert_allclose(saved.tip[-1], data["levels"][1]["tip_mm"])
    prov = json.loads((out / "provenance.json").read_text())
    assert prov["model"]["unit"]["pitch"] == 10.5 and "felupe" in prov["dependencies"]
    assert '<DataSet timestep="10"' in (out / "vtk" / "actuator.pvd").read_text()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["-o", "01x1"], "only the digits 0 and 1"),
        (["-o", "01", "--pressure", "60"], "outside the calibrated range"),
        (["-o", ""], "empty"),
    ],
)
def test_simulate_rejects_bad_input(args: list[str], message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", *args]) == 2
    assert message in capsys.readouterr().err

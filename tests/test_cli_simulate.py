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
    for name in ("response.npz", "response.json", "shape.png", "provenance.json", "vtk/actuator.pvd",
                 "vtk/actuator_01.vtu"):
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


def test_simulate_with_gravity_applies_the_weight_first(capsys: pytest.CaptureFixture[str]) -> None:
    args = ["simulate", "-o", "01", "--pressure", "10", "--increments", "2", "--json"]
    assert main(args) == 0
    plain = json.loads(capsys.readouterr().out)
    assert main([*args, "--gravity", "horizontal"]) == 0
    lying = json.loads(capsys.readouterr().out)
    assert lying["metadata"]["gravity_mm_s2"] == [0.0, -9806.65]
    assert "gravity_mm_s2" not in plain["metadata"]
    # the weight pulls the tip down (-y) at every level
    for a, b in zip(lying["levels"], plain["levels"], strict=False):
        assert a["tip_mm"][1] < b["tip_mm"][1]


def test_simulate_builds_the_same_model_as_design_and_the_api(tmp_path: Path) -> None:
    from dataclasses import replace

    from pneumorph.models import RampSpec, Reduced2D, make_model

    assert main(["simulate", "-o", "0110", "--pressure", "10", "--increments", "2", "--out", str(tmp_path / "s")]) == 0
    written = json.loads((tmp_path / "s" / "provenance.json").read_text(encoding="utf-8"))["fingerprint"]
    api = Reduced2D(4, ramp_spec=RampSpec(0.01, replace(Reduced2D.default_steps, increments=2)))
    assert written == make_model(4, {"fidelity": "2d", "pressure_kpa": 10, "increments": 2}).fingerprint()
    assert written == api.fingerprint()  # one source of defaults: the cache entries are shared


def test_written_line_has_one_slash(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "-o", "01", "--pressure", "10", "--increments", "1", "--out", f"{tmp_path / 'sim'}/"]) == 0
    line = next(t for t in capsys.readouterr().out.splitlines() if t.startswith("written to"))
    assert f"written to {tmp_path / 'sim'}/ (" in line and "//" not in line


def test_without_out_the_table_says_nothing_was_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "-o", "01", "--pressure", "10", "--increments", "2", "--gravity", "hanging"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-1] == "nothing written: --out DIR keeps the response, the VTK series and the shape figure"
    assert not list(tmp_path.iterdir())


def test_a_unit_with_a_bottom_wall_of_another_material_writes_its_region(tmp_path: Path) -> None:
    import meshio

    unit = tmp_path / "unit.toml"
    unit.write_text('[unit]\nbottom_material = "smooth_sil_950"\n')
    out = tmp_path / "sim"
    assert main(["simulate", "-o", "01", "--unit", str(unit), "--pressure", "10", "--increments", "2",
                 "--out", str(out)]) == 0
    pvd = (out / "vtk" / "actuator.pvd").read_text()
    assert '"regions": {"body": 0, "layer": 1, "filler": 2, "bottom:smooth_sil_950": 3}' in pvd
    region = meshio.read(out / "vtk" / "actuator_01.vtu").cell_data["region"][0]
    assert sorted(set(region.tolist())) == [0, 1, 2, 3]


@pytest.mark.slow
def test_a_ramp_stopped_by_ballooning_says_so_and_names_the_volume_control(tmp_path: Path,
                                                                          capsys: pytest.CaptureFixture[str]) -> None:
    """A 4-unit 2D actuator of Ecoflex 00-30 balloons near 26 kPa: the cavity volume falls under a higher pressure,
    the ramp stops, and the one-line error says what that means and what follows past it; nothing is written."""
    settings = tmp_path / "soft.toml"
    settings.write_text('[model]\nfidelity = "2d"\n[model.unit]\nbody_material = "ecoflex_00_30"\n')
    out = tmp_path / "out"
    code = main(["simulate", "-o", "0110", "--model-file", str(settings), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert code != 0 and err.startswith("error: design 0110: simulation failed, converged up to 26.")
    assert "the cavity volume fell from" in err and "--volume-change" in err
    assert not out.exists()


def _soft_plan(tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
               *options: str) -> list[str]:
    """The lines ``simulate -o 0110`` writes for a 4-unit 2D Ecoflex 00-30 actuator with ``options`` on a quiet
    machine, its solve stubbed to report its first level and be interrupted; asserts exit 130 and nothing written."""
    from pneumorph.models.fe.base import FEModel

    def first_level_then_interrupted(self: FEModel, orientation: str, on_level: object = None) -> None:
        on_level(0, 0.01)  # type: ignore[operator]
        raise KeyboardInterrupt

    monkeypatch.setattr(FEModel, "solve", first_level_then_interrupted)
    monkeypatch.setattr("pneumorph.io.progress.os.getloadavg", lambda: (0.0, 0.0, 0.0))  # a quiet machine
    settings = tmp_path / "soft.toml"
    settings.write_text('[model]\nfidelity = "2d"\n[model.unit]\nbody_material = "ecoflex_00_30"\n')
    out = tmp_path / "out"
    code = main(["simulate", "-o", "0110", "--model-file", str(settings), *options, "--out", str(out)])
    lines = capsys.readouterr().err.splitlines()
    assert code == 130 and not out.exists()
    return lines


def test_the_plan_of_a_volume_ramp_of_a_soft_body_is_estimated_from_its_measured_cost(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """A 4-unit Ecoflex 00-30 actuator in a Smooth-Sil 950 layer (34.5 times stiffer) volume-controlled to 5 V0:
    the plan says the volume ramp, estimates it at the measured factor 601 of the built-in pressure ramp (0.139 s on a
    quiet machine, 0.83 s (4 / 15) ** 1.35: 84 s) and that it may need many cut-backs; interrupted after its
    first level (the solve stubbed), it writes nothing."""
    from pneumorph.io.progress import duration_text

    lines = _soft_plan(tmp_path, capsys, monkeypatch, "--volume-change", "4")
    plan = lines[0]
    assert plan.startswith("simulating design 0110 (2d model, 4 units, the cavities' volume to 5 V0): 10 levels, "
                           "estimated ")
    seconds = (9.2 + 169 * 3.5) * 0.83 * (4 / 15) ** 1.35
    assert seconds == pytest.approx(83.7, abs=0.1)
    assert plan.split("estimated ")[1].startswith(f"{duration_text(seconds)} ({duration_text(seconds / 10)} each")
    assert lines[1] == ("  volume control of a body 34.5 times softer than its layer may need many cut-backs where "
                        "its walls balloon (about 601 times the built-in unit's pressure ramp, measured in 2D; the "
                        "count below gives the real rate)")


@pytest.mark.parametrize("pressure", [45.0, 20.0])
def test_the_plan_of_a_pressure_ramp_of_a_soft_body_says_what_its_limit_point_may_cost(
        pressure: float, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """A 4-unit Ecoflex 00-30 actuator (34.5 times softer than its layer) ramped to 45 kPa passes the lowest limit
    point measured (24.2 kPa): its plan keeps the converged ramp's estimate (0.139 s on a quiet machine) and says
    that creeping to the limit point took up to 40 times that; ramped to 20 kPa (measured: as fast as the built-in
    unit) nothing is added. The solve is stubbed: interrupted after its first level, it writes nothing."""
    from pneumorph.io.progress import duration_text

    lines = _soft_plan(tmp_path, capsys, monkeypatch, "--pressure", str(pressure))
    out = tmp_path / "out"
    seconds = 0.83 * (4 / 15) ** 1.35
    assert lines[0] == (f"simulating design 0110 (2d model, 4 units, {pressure:g} kPa): 10 levels, estimated "
                        f"{duration_text(seconds)} ({duration_text(seconds / 10)} each, 1 worker) -> {out}")
    note = ("  a body 34.5 times softer than its layer may reach a limit point (its walls balloon) past 24 kPa: the "
            "ramp then creeps to it with cut-backs and stops, which took up to 40 times the estimate (measured in 2D)")
    assert (lines[1] == note) if pressure == 45.0 else not lines[1].startswith("  a body")


def test_volume_change_typed_wins_over_a_model_files(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    """``--volume-change`` given on the command line wins over the model file's ``volume_change``, as the other
    options do (the file's 30 V0 in 10 increments would be refused: 3 V0 a step). The solve is stubbed."""
    from pneumorph.models.fe.base import FEModel

    def interrupted(self: FEModel, orientation: str, on_level: object = None) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(FEModel, "solve", interrupted)
    settings = tmp_path / "model.toml"
    settings.write_text('[model]\nfidelity = "2d"\nvolume_change = 30\n')
    code = main(["simulate", "-o", "0110", "--model-file", str(settings), "--volume-change", "1"])
    lines = capsys.readouterr().err.splitlines()
    assert code == 130 and lines[0].startswith("simulating design 0110 (2d model, 4 units, the cavities' volume to "
                                               "2 V0): 10 levels")

"""``pneumorph identify``: bad input refused in one line, exit 2, nothing written, before any solve;
the identified model read back by ``simulate --model-file``."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.geometry.unit import UnitSpec
from pneumorph.identify import ParameterSet, read_manifest
from pneumorph.models.factory import make_model, read_model_file
from tests.identify.conftest import synthetic


@pytest.fixture(scope="module")
def trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A photo trace (CSV, mm) of a 6-unit 2D actuator with its wall 0.08 mm thick and bulk modulus x1.06."""
    params = ParameterSet(UnitSpec(element_size=3.0))
    obs = synthetic(params, params.nominal + np.array([0.06, 0, 0, 0.08, 0]), "011001", "2d", seed=5)
    path = tmp_path_factory.mktemp("trace") / "trace.csv"
    np.savetxt(path, obs.scan.points, delimiter=",", header="x,y", comments="")
    return path


@pytest.fixture()
def unit(tmp_path: Path) -> Path:
    path = tmp_path / "unit.toml"
    path.write_text("[unit]\nelement_size = 3.0\n")
    return path


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def refused(args: list[str], capsys: pytest.CaptureFixture[str], out: Path, *words: str) -> None:
    code, _, err = run([*args, "--out", str(out), "--executor", "serial"], capsys)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    assert "solving" not in err and all(w in lines[0] for w in words), lines[0]
    assert not out.exists()


def test_bad_input_is_refused_before_any_solve(trace: Path, unit: Path, tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    common = ["--model", "2d", "--unit", str(unit)]
    refused(["identify", str(trace), "--design", "011001", "--pressure", "80", *common], capsys, out,
            "outside the calibrated range")  # above the 2D model's ramp (its filler law)
    refused(["identify", str(trace), "--design", "011001", "--pressure", "36", "--scan-unit", "m", *common], capsys,
            out, "--scan-unit")
    refused(["identify", str(trace), "--design", "011001", "--pressure", "36", "--fit", "wall,colour", *common],
            capsys, out, "colour")
    refused(["identify", str(trace), "--pressure", "36", *common], capsys, out, "--design")
    refused(["identify", str(trace), "--design", "0110x1", "--pressure", "36", *common], capsys, out, "--design")
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    refused(["identify", str(empty), "--design", "011001", "--pressure", "36", *common], capsys, out, "empty")
    manifest = tmp_path / "scans.toml"
    manifest.write_text(f'[[scan]]\nfile = "{trace}"\ndesign = "011001"\n')
    refused(["identify", "--manifest", str(manifest), *common], capsys, out, "missing pressure_kpa")
    manifest.write_text(f'[[scan]]\nfile = "{trace}"\ndesign = "011001"\npressure_kpa = 36\nscan_unit = "mm"\n'
                        'scale = 2.0\n')
    refused(["identify", "--manifest", str(manifest), *common], capsys, out, "not both")


def test_a_design_of_another_unit_count_is_refused_before_the_fit(trace: Path, unit: Path, tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    code, _, err = run(["identify", str(trace), "--design", "0110011001", "--pressure", "36", "--model", "2d",
                        "--unit", str(unit), "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"),
                        "--out", str(out)], capsys)
    assert code == 2 and "is it the design scanned" in err.strip().splitlines()[-1] and "iteration" not in err
    assert not out.exists()


def test_identify_writes_a_model_that_simulate_reads(trace: Path, unit: Path, tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    manifest = tmp_path / "scans.toml"
    manifest.write_text(f'[[scan]]\nfile = "{trace.name}"\ndesign = "011001"\npressure_kpa = 36\n')
    (tmp_path / trace.name).write_bytes(trace.read_bytes())  # relative to the manifest
    assert Path(read_manifest(manifest)[0].file) == tmp_path / trace.name
    out = tmp_path / "out"
    code, stdout, err = run(["identify", "--manifest", str(manifest), "--model", "2d", "--unit", str(unit),
                             "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"), "--out", str(out),
                             "--json"], capsys)
    assert code == 0, err
    result = json.loads(stdout)
    wall = result["parameters"]["wall"]
    assert set(result["parameters"]) == {"body_bulk_scale", "body_shear_scale", "side_wall", "wall", "layer"}
    assert wall["value"] == pytest.approx(1.58, abs=0.02) and 0 < wall["standard_error"] < 0.01
    assert result["parameters"]["side_wall"]["identified"] is False
    assert result["residual_rms"]["after"]["all_mm"] < 0.5 * result["residual_rms"]["before"]["all_mm"]
    data = tomllib.loads((out / "identified.toml").read_text())
    assert data["model"]["unit"]["wall"] == pytest.approx(wall["value"], abs=1e-8)
    assert data["provenance"]["designs"] == ["011001"] and data["provenance"]["pneumorph"]
    # the identified model is the fit's model: simulate --model-file solves it (2D, from the file)
    settings = read_model_file(out / "identified.toml")
    expected = make_model(6, {**settings, "pressure_kpa": 36}).evaluate("011001").tip[-1]
    code, stdout, err = run(["simulate", "-o", "011001", "--pressure", "36", "--model-file",
                             str(out / "identified.toml"), "--json"], capsys)
    assert code == 0, err
    simulated = json.loads(stdout)
    assert simulated["model"] == "2d"
    assert simulated["levels"][-1]["tip_mm"] == pytest.approx(expected.tolist(), abs=1e-9)
    nominal = make_model(6, {"pressure_kpa": 36, "unit": {"element_size": 3.0}}).evaluate("011001").tip[-1]
    assert np.linalg.norm(np.array(simulated["levels"][-1]["tip_mm"]) - nominal) > 0.1
    # the folder now holds an identification: a second one is refused before any solve, the first kept
    written = (out / "identified.toml").read_bytes()
    again = ["identify", "--manifest", str(manifest), "--model", "2d", "--unit", str(unit), "--executor", "serial",
             "--cache", str(tmp_path / "c.sqlite"), "--out", str(out), "--fit", "wall"]
    code, _, err = run(again, capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--overwrite" in err and "identifying" not in err
    assert (out / "identified.toml").read_bytes() == written
    code, _, err = run([*again, "--overwrite"], capsys)  # replaced: the wall alone, the moduli at nominal
    assert code == 0, err
    assert tomllib.loads((out / "identified.toml").read_text())["model"]["unit"]["wall"] == pytest.approx(
        wall["value"], abs=0.02)


def test_the_command_names_what_it_cannot_identify_and_what_to_scan_next(trace: Path, unit: Path, tmp_path: Path,
                                                                         capsys: pytest.CaptureFixture[str]) -> None:
    """One trace: the walls identified, the moduli's combination named, the further scans weighed; one name per
    parameter in the printed table, identify.json and identified.toml."""
    out = tmp_path / "out"
    code, stdout, err = run(["identify", str(trace), "--design", "011001", "--pressure", "36", "--model", "2d",
                             "--unit", str(unit), "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"),
                             "--out", str(out)], capsys)
    assert code == 0, err
    lines = stdout.splitlines()
    assert lines[0].split() == ["parameter", "unit", "nominal", "value", "std", "err", "confounded", "identified"]
    rows = {line.split()[0]: line.split() for line in lines[1:6]}
    assert rows["wall"][1] == "mm" and rows["wall"][5] == "0.0054" and rows["wall"][6] == "yes"
    assert rows["body_bulk_scale"][1] == "-" and rows["body_bulk_scale"][6] == "no"
    held = next(line for line in lines if line.startswith("not determined by these scans: "))
    assert held.startswith("not determined by these scans: body_bulk_scale +0.047 with body_shear_scale -0.01"), held
    advice = next(line for line in lines if line.startswith("scan next: "))
    assert "cannot tell body_bulk_scale and body_shear_scale apart: a scan of design 011001 again at 18 kPa " \
           "would identify body_bulk_scale and body_shear_scale" in advice  # a second pressure, as it predicts
    assert not any("none of the" in line for line in lines)
    saved = json.loads((out / "identify.json").read_text())
    model = tomllib.loads((out / "identified.toml").read_text())
    assert list(saved["parameters"]) == list(rows) == list(model["provenance"]["value"])
    assert {"body_bulk_scale", "body_shear_scale"} <= set(model["model"])
    assert model["provenance"]["identified"] == ["wall", "layer"]
    assert model["provenance"]["next_scans"] == [advice.removeprefix("scan next: ")]

"""``pneumorph materials fit`` end to end."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.checks import MODEL_NAMES
from pneumorph.cli import main

SORO = "marechal2021_SoRo-Materials-DB/Tensile-Tests-Data"


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(["materials", "fit", *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_dataset_human_output(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "treloar1944", "--model", "yeoh", "-m", "neo-hooke")
    assert code == 0, err
    assert "yeoh-3 fitted to treloar1944" in out and "C30" in out
    assert "R^2 equibiaxial" in out and "mu0 =" in out and "Drucker stability" in out
    assert "R^2 overall" in out.splitlines()[-4]  # comparison table at the end
    assert out.splitlines()[-1].startswith("neo-hooke")


def test_json_output(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    png = tmp_path / "fit.png"
    code, out, _ = run(capsys, "treloar1944", "-m", "ogden-3", "--starts", "2", "--seed", "3",
                       "--json", "--plot", str(png))
    assert code == 0
    doc = json.loads(out)
    assert doc["data"]["datasets"] == ["treloar1944"] and doc["plot"] == str(png)
    (f,) = doc["fits"]
    assert f["model"] == "ogden-3" and f["starts"] == 2 and f["seed"] == 3
    assert set(f["r2"]) == {"uniaxial", "equibiaxial", "planar"}
    assert set(f["parameters"]) == {"mu1", "alpha1", "mu2", "alpha2", "mu3", "alpha3"}
    assert doc["table"][0]["r2_overall"] == f["r2_overall"]
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"


def test_reversed_columns_files(capsys: pytest.CaptureFixture[str], reference_dir: Path) -> None:
    base = reference_dir / "meunier2008-silicone_Chongran-Zhao/Meunier_2008"
    files = [str(base / m / "stress_stretch.txt") for m in ("UT", "ET", "PS")]
    code, out, _ = run(capsys, *files, "--columns", "stress,stretch", "-m", "mooney-rivlin-2", "--json")
    assert code == 0
    fit = json.loads(out)["fits"][0]
    assert fit["n_points"] == {"uniaxial": 33, "equibiaxial": 14, "planar": 19}
    assert fit["stretch_range"]["uniaxial"][0] == pytest.approx(0.49)  # compression kept
    # without the column order the first column (stress) is not a stretch
    code, _, err = run(capsys, files[0])
    assert code == 2 and err.startswith("error: ") and "row 1" in err and "stress_stretch.txt" in err


def test_soro_markdown_and_range(capsys: pytest.CaptureFixture[str], reference_dir: Path) -> None:
    f = str(reference_dir / SORO / "Dragon Skin 30.csv")
    code, out, _ = run(capsys, f, "-m", "yeoh", "-m", "neo-hooke", "--markdown", "--max-stretch", "3")
    assert code == 0
    lines = out.strip().splitlines()
    assert lines[0] == "| model | R^2 uniaxial | mu0 [MPa] | Drucker-stable |" and len(lines) == 4
    code, out, _ = run(capsys, f, "--mode", "uniaxial", "-m", "neo-hooke", "--json", "--truncate", "none")
    assert json.loads(out)["fits"][0]["n_points"]["uniaxial"] == 311


def test_errors_exit_2(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = run(capsys, "treloar1944", "--model", "arruda-boyce")
    assert code == 2
    assert err.count("\n") == 1 and "unknown model 'arruda-boyce'" in err
    assert all(n in err for n in MODEL_NAMES)
    code, _, err = run(capsys, "no-such-thing")
    assert code == 2 and "no data file or bundled data set named 'no-such-thing'" in err
    bad = tmp_path / "bad.csv"
    bad.write_text("1.0,0\n1.1,0.1\n1.2\n")
    code, _, err = run(capsys, str(bad))
    assert code == 2 and "bad.csv, row 3: expected 2 columns, found 1" in err
    code, _, err = run(capsys, "treloar1944", "--starts", "0")
    assert code == 2 and "--starts" in err

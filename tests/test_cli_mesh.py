"""``pneumorph sensitivity mesh``: a real refinement study end to end, its files, and refusals before any solve."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main


def test_mesh_study_of_a_short_section(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                       monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PNEUMORPH_CACHE", str(tmp_path / "cache.sqlite"))
    out = tmp_path / "mesh"
    code = main(["sensitivity", "mesh", "--model", "2d", "--units", "1", "--size", "0.75", "--size", "1.5",
                 "--size", "0.375", "--out", str(out), "--json"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert [p["element_size_mm"] for p in data["points"]] == [1.5, 0.75, 0.375]
    assert [p["cell_size_mm"] for p in data["points"]] == pytest.approx([1.5, 0.75, 0.375])
    cells = [p["cells"] for p in data["points"]]
    assert cells[1] == 4 * cells[0] and cells[2] == 4 * cells[1]  # nested: every quad8 cell in four
    curl = data["convergence"]["0"]["curl"]
    assert curl["method"] == "three meshes" and 1.0 < curl["order"] < 2.5
    # the coarse mesh is stiffer: the curl grows towards its limit
    values = curl["values"]
    assert values[0] < values[1] < values[2] < curl["extrapolated"]
    assert (out / "mesh.png").stat().st_size > 10_000
    saved = json.loads((out / "mesh.json").read_text())
    assert saved["provenance"]["model"]["fidelity"] == "2d" and saved["convergence"] == data["convergence"]
    # tips and curls are the last level's (the top of the ramp), the objective's pressure its own level's
    top = saved["provenance"]["model"]["pressure_mpa"] * 1e3
    assert [p["tip_pressure_kpa"] for p in saved["points"]] == pytest.approx([top] * 3)
    # a rerun answers from the cache, with the same numbers
    assert main(["sensitivity", "mesh", "--model", "2d", "--units", "1", "--size", "0.75", "--size", "1.5",
                 "--size", "0.375", "--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["convergence"] == data["convergence"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--design", "01", "--design", "011"], "different lengths"),
        (["--size", "0.3", "--size", "0.2"], "GB for one solve"),
        (["--size", "1.0", "--order", "2"], "one element size (1 mm) shows no convergence; give two or more"),
        (["--size", "1.0", "--size", "0.75", "--size", "1"], "1 mm given more than once"),
        (["--design", "0" * 15, "--design", "1" * 15, "--size", "1.0", "--size", "0.9", "--executor", "processes",
          "--workers", "4"], "GB for one solve x 4 at once"),
        (["--target", "max-q"], "unknown objective"),
        (["--scheduler", "tcp://127.0.0.1:1"], "--scheduler only applies"),
    ],
)
def test_mesh_study_refuses_before_solving(args: list[str], message: str, tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "never"
    code = main(["sensitivity", "mesh", *args, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


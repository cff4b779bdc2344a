"""``design --refine``: the verified designs on a finer mesh, their extrapolated gap, and refusals."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main
from pneumorph.design import DesignConfig
from pneumorph.design.certified.refine import MESH_ORDERS, refined_row, verdict
from pneumorph.design.objectives.fitness import score
from pneumorph.design.objectives.targets import make_objective
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Reduced2D
from pneumorph.sensitivity.mesh import refined


def test_gap_is_extrapolated_not_the_values() -> None:
    """Both designs move by +0.27 on the finer mesh: each value is uncertain by ~0.5, their gap by far less."""
    rows = [refined_row("w", 7.51, 7.789, 1.5, 0.75, "min", 1.4), refined_row("r", 7.569, 7.843, 1.5, 0.75, "min", 1.4)]
    v = verdict(rows, "w", "min", 1.4, 2.0)
    assert v["holds"] and v["could_overtake"] == []
    gap = v["gaps"]["r"]
    assert gap["gap"] == pytest.approx(0.059) and gap["refined_gap"] == pytest.approx(0.054)
    assert gap["limit"] == pytest.approx(0.054 - 0.005 / (2**1.4 - 1))
    assert rows[0]["error"] > 10 * gap["error"]


def test_a_gap_that_closes_and_a_swap() -> None:
    rows = [refined_row("w", 5.0, 5.3, 1.5, 0.75, "min", 1.0), refined_row("r", 5.1, 5.25, 1.5, 0.75, "min", 1.0)]
    v = verdict(rows, "w", "min", 1.0, 2.0)
    assert not v["holds"] and v["refined_best"] == "r" and v["could_overtake"] == ["r"]
    # maximised objectives: the sign turns
    up = [refined_row("w", 30.0, 31.0, 1.5, 0.75, "max", 1.0), refined_row("r", 29.0, 29.9, 1.5, 0.75, "max", 1.0)]
    assert verdict(up, "w", "max", 1.0, 2.0) == {"holds": True, "refined_best": "w", "could_overtake": [],
                                                 "gaps": {"r": pytest.approx({"gap": 1.0, "refined_gap": 1.1,
                                                                              "limit": 1.2, "error": 0.3})}}


def test_refine_is_left_out_of_default_settings() -> None:
    assert "refine" not in DesignConfig().to_dict()["design"]
    c = DesignConfig(refine=0.75)
    assert DesignConfig.from_dict(c.to_dict()).refine == 0.75
    with pytest.raises(Exception, match="only appl"):
        DesignConfig(search="ga", refine=1.0)


@pytest.mark.slow
def test_design_refine_in_2d(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                             monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PNEUMORPH_CACHE", str(tmp_path / "cache.sqlite"))
    out = tmp_path / "run"
    code = main(["design", "--model", "2d", "--refine", "0.75", "--tolerance", "0", "--executor", "serial",
                 "--out", str(out), "--json"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    mesh = data["mesh"]
    assert mesh["element_size_mm"] == [1.5, 0.75] and mesh["order"] == MESH_ORDERS["2d"]
    cert = json.loads((out / "certificate.json").read_text())
    assert cert["mesh"] == mesh
    verified = {d: c["value"] for d, c in cert["verified"].items()}
    assert {r["design"] for r in mesh["rows"]} == set(verified)
    # every refined value is the objective of an independent solve on the 0.75 mm mesh
    objective = make_objective("sin", 10.0)
    fine = refined(Reduced2D(15), 0.75)
    for row in mesh["rows"]:
        assert row["value"] == pytest.approx(verified[row["design"]])
        assert row["refined"] == pytest.approx(score(fine.evaluate(row["design"]), objective).value, abs=1e-6)
    winner = cert["winner"]["design"]
    best_fine = min(mesh["rows"], key=lambda r: r["refined"])["design"]
    assert mesh["holds"] == (best_fine == winner)
    report = (out / "report.md").read_text()
    assert "## Mesh" in report and "0.75 mm elements" in report
    # the value in words and units: Eq 4.1 and its RMS per centre (sqrt(15) smaller)
    value = cert["winner"]["value"]
    assert f"{value / 15**0.5:.3g} mm RMS per centre" in report


@pytest.mark.slow
def test_summary_line_names_the_value(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PNEUMORPH_CACHE", str(tmp_path / "cache.sqlite"))
    assert main(["design", "--model", "2d", "--units", "4", "--search", "exhaustive", "--objective", "max-y",
                 "--executor", "serial", "--out", str(tmp_path / "run")]) == 0
    line = next(t for t in capsys.readouterr().out.splitlines() if t.startswith("best design"))
    assert ": max-y " in line and " mm (" in line and "fitness" not in line


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--refine", "2.0"], "not finer than the model's element size"),
        (["--search", "ga", "--refine", "1.0"], "--refine only applies to --search certified"),
        (["--refine", "0.19"], "GB for one solve"),
    ],
)
def test_design_refine_refusals(args: list[str], message: str, tmp_path: Path,
                                capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "never"
    code = main(["design", *args, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert message in err and "Traceback" not in err
    assert not out.exists()


def _study(model, objective, values):  # type: ignore[no-untyped-def]
    points = [{"design": d, "element_size_mm": h, "value": v} for d, by in values.items() for h, v in by.items()]
    return {"objective": objective.label, "points": points, "provenance": {"model": model.describe()}}


def test_mesh_note_from_a_study_of_the_same_model() -> None:
    from pneumorph.design.certified.refine import mesh_note
    from pneumorph.models.fe import Full3D

    model, objective = Full3D(15), make_objective("sin", 10.0)
    study = _study(model, objective, {"a": {1.5: 7.40, 1.0: 7.30, 0.75: 7.25}, "b": {1.5: 7.53, 0.75: 7.40},
                                      "c": {1.5: 9.0, 0.75: 8.80}})
    note = mesh_note(model, objective, {"w": 7.0, "x": 7.02, "y": 7.5}, "w", study)
    assert note is not None
    assert note["sizes_mm"] == [1.5, 0.75] and note["designs"] == 3
    assert note["value_change"] == pytest.approx([-0.2, -0.13])
    assert note["gap_change"] == pytest.approx(0.07)  # the gap b - c: -1.47 at 1.5 mm, -1.40 at 0.75 mm
    assert note["within"] == ["x"]
    # another objective, unit or fidelity: the study says nothing
    assert mesh_note(model, make_objective("cos", 10.0), {"w": 7.0}, "w", study) is None
    assert mesh_note(Full3D(15, UnitSpec(wall=2.0)), objective, {"w": 7.0}, "w", study) is None
    assert mesh_note(Reduced2D(15), objective, {"w": 7.0}, "w", study) is None


def test_the_shipped_study_speaks_for_the_default_run() -> None:
    """The shipped 3D study (15 units, sin A = 10 mm) applies to the default certified run's model: refining
    1.5 -> 0.75 mm lowers the close competitors' Eq 4.1 values by 0.15-0.17 mm and raises those of the random and
    aligned designs (at their smallest deformation), so gaps between dissimilar designs move by up to 0.67 mm: the
    default run's runner-up, 0.127 mm behind the winner, is named as one a finer mesh could swap."""
    from pneumorph.design.certified.refine import load_study, mesh_note
    from pneumorph.models import make_model

    study = load_study()
    assert study is not None
    model = make_model(15, {"fidelity": "3d"})
    note = mesh_note(model, make_objective("sin", 10.0), {"001111010001001": 7.4035, "001111010001000": 7.5306},
                     "001111010001001")
    assert note is not None and note["sizes_mm"] == [1.5, 0.75] and note["designs"] == 5
    lo, hi = note["value_change"]
    assert -0.2 < lo < -0.1 and 0.0 < hi < 0.6
    assert 0.127 < note["gap_change"] == pytest.approx(hi - lo)
    assert note["within"] == ["001111010001000"]
    # another pressure is another model: the study says nothing
    assert mesh_note(make_model(15, {"fidelity": "3d", "pressure_kpa": 30}), make_objective("sin", 10.0),
                     {"a": 1.0}, "a") is None

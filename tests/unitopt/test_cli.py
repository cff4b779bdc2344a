"""``pneumorph unit optimise``: bad input is one line and exit 2 before anything is solved or written; a tiny run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main

TINY = ["unit", "optimise", "--var", "cavity_height=4.5:7.5", "--var", "end_wall=2:3.5", "--element-size", "3",
        "--pressure", "10", "--pop", "4", "--gen", "1", "--resolution", "0.5", "--executor", "serial"]


@pytest.mark.parametrize(("args", "says"), [
    (["--var", "height=1:2"], "unknown unit variable 'height'"),
    (["--var", "wall=2.5:1"], "0 < low < high"),
    (["--var", "wall"], "NAME=LOW:HIGH"),
    (["--var", "wall=a:b"], "must be numbers"),
    (["--var", "wall=1:2", "--var", "wall=1:3"], "given twice"),
    (["--var", "end_wall=2:5.5"], "do not always make a unit"),
    (["--var", "pitch=5:12"], "do not always make a unit"),
    (["--strain-limit", "0"], "--strain-limit"),
    (["--strain-limit", "-1"], "--strain-limit"),
    (["--strain-limit", "nan"], "--strain-limit"),
    (["--units", "2"], "--units"),
    (["--pop", "3"], "--pop"),
    (["--var", "wall=1:1.04"], "the range of wall 1-1.04 mm holds one value (1 mm) at the resolution 0.1 mm"),
    (["--var", "wall=1.01:1.09"], "the range of wall 1.01-1.09 mm holds no value at the resolution 0.1 mm"),
    (["--var", "wall=1:900"], "narrow the bounds (this is the unit at wall=900 mm)"),
    (["--var", "wall=1:1e9"], "unit wall 1e+09 mm is above the limit MAX_LENGTH_MM"),
    (["--var", "wall=0.000001:2"], "at wall=1e-06 mm: unit wall 1e-06 mm is thinner than the thinnest wall a mould "
                                   "casts, MIN_WALL_MM = 1 mm"),
    (["--var", "cavity_height=0.5:6"], "MIN_FEATURE_MM = 1 mm"),
])
def test_bad_input_is_one_line_and_exit_2_before_any_solve(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                          monkeypatch: pytest.MonkeyPatch, args: list[str],
                                                          says: str) -> None:
    import pneumorph.models.fe as fe

    def tripwire(*a: object, **k: object) -> None:
        raise AssertionError("a solve was reached")

    monkeypatch.setattr(fe.FEModel, "solve", tripwire)
    out = tmp_path / "run"
    code = main(["unit", "optimise", *args, "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"),
                 "--out", str(out)])
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: ") and says in lines[0], err
    assert not out.exists() and not (tmp_path / "c.sqlite").exists()


@pytest.mark.slow
def test_a_tiny_run_prints_the_front_and_writes_its_folder(tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    assert main([*TINY, "--cache", str(tmp_path / "c.sqlite"), "--out", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["front"] and data["base"]["cavity_height"] == 6.0
    assert (out / "front.png").stat().st_size > 0 and (out / "units" / "knee.toml").exists()
    # the same run again into its folder: taken (answered from the cache); other settings: refused, one line
    assert main([*TINY, "--cache", str(tmp_path / "c.sqlite"), "--out", str(out), "--json"]) == 0
    capsys.readouterr()
    other = [*TINY[:-4], "--seed", "1", *TINY[-4:]]
    assert main([*other, "--cache", str(tmp_path / "c.sqlite"), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{out} holds a unit optimisation with other settings; " in err
    assert main([*other, "--cache", str(tmp_path / "c.sqlite"), "--out", str(out), "--overwrite", "--json"]) == 0



def test_the_printed_front_lists_the_base_unit_once() -> None:
    from types import SimpleNamespace as S

    from pneumorph.cli.unit import listed

    base = S(values={"cavity_height": 6.0, "end_wall": 3.0})
    front = [S(values={"cavity_height": 6.0, "end_wall": 3.0}), S(values={"cavity_height": 7.5, "end_wall": 2.0})]
    rows = listed(S(base=base, front=front), ["cavity_height", "end_wall"])
    assert [c.values for c, _ in rows] == [base.values, front[1].values]
    assert rows[0][1] == "  <- base unit (on the front)"
    off = listed(S(base=base, front=front[1:]), ["cavity_height", "end_wall"])
    assert len(off) == 2 and off[0][1] == "  <- base unit"


def _refused(args: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
             out: Path) -> str:
    """Run ``unit optimise`` with a tripwire on the solver: one line, exit 2, no cache written; the line."""
    import pneumorph.models.fe as fe

    def tripwire(*a: object, **k: object) -> None:
        raise AssertionError("a solve was reached")

    monkeypatch.setattr(fe.FEModel, "solve", tripwire)
    code = main(["unit", "optimise", *args, "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"),
                 "--out", str(out)])
    lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert code == 2 and len(lines) == 1 and lines[0].startswith("error: "), lines
    assert not (tmp_path / "c.sqlite").exists()
    return lines[0]


def test_a_solid_base_unit_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                      monkeypatch: pytest.MonkeyPatch) -> None:
    unit = tmp_path / "solid.toml"
    unit.write_text("[unit]\nsolid = true\n")
    line = _refused(["--unit", str(unit)], tmp_path, capsys, monkeypatch, tmp_path / "run")
    assert "the base unit is solid" in line and "Omega is 0" in line and not (tmp_path / "run").exists()


def test_a_probe_larger_than_the_memory_is_refused_with_its_estimate(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str],
                                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    from pneumorph.geometry import meshsize

    monkeypatch.setattr(meshsize, "available_memory", lambda: 4 * 10**9)
    line = _refused(["--units", "100"], tmp_path, capsys, monkeypatch, tmp_path / "run")
    assert "a 3D actuator of 100 units of this unit is a mesh of about " in line and "GB for one solve" in line
    assert "4.0 GB are available" in line and "fewer --units" in line and not (tmp_path / "run").exists()


def test_another_runs_folder_is_refused_without_overwrite(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "run"
    out.mkdir()
    (out / "config.toml").write_text("[design]\nunits = 15\n")  # a design run's folder
    before = sorted(p.name for p in out.iterdir())
    line = _refused(TINY[2:-2], tmp_path, capsys, monkeypatch, out)
    assert f"{out} holds another run's files (config.toml); give another folder with --out, or write into it " \
           "with --overwrite" in line
    assert sorted(p.name for p in out.iterdir()) == before


def test_an_optimisation_without_a_feasible_candidate_exits_2_and_says_why(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    """Every candidate failed: "front of 0" and exit 0 before; now one line naming the counts, and exit 2."""
    from dataclasses import replace

    import pneumorph.unitopt.run as run
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.unitopt.problem import UnitCandidate
    from pneumorph.unitopt.records import UnitOptimisation

    def all_fail(settings, evaluator, on_candidate=None, on_generation=None):  # type: ignore[no-untyped-def]
        failed = [UnitCandidate({"cavity_height": h}, replace(UnitSpec(), cavity_height=h), None,
                                "no convergence at load factor 0.4", 0.004, False, 1.0, 0) for h in (4.5, 6.0, 7.5)]
        return UnitOptimisation(settings, failed, [], failed[1])

    monkeypatch.setattr(run, "optimise", all_fail)
    out = tmp_path / "run"
    code = main([*TINY, "--cache", str(tmp_path / "c.sqlite"), "--out", str(out)])
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("error: ")]
    assert code == 2 and len(err) == 1, err
    assert "no feasible unit: of 3 candidates 3 failed to converge and 0 strained past --strain-limit" in err[0]
    assert "--var" in err[0] and (out / "candidates.csv").is_file()  # the failures are kept, to be read

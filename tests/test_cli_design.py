"""``pneumorph design``: a tiny run end to end, resume, and bad input."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from pneumorph.cli import main
from pneumorph.models.chain.fit import MIN_HELDOUT
from pneumorph.models.chain.plan import build_plan
from pneumorph.models.chain.sources import build_options
from pneumorph.models.chain.windows import covering_designs
from pneumorph.models.factory import make_model

TINY = ["--units", "2", "--search", "ga", "--pop", "4", "--gen", "2", "--pressure", "10", "--executor", "serial"]


def test_tiny_design_run_writes_the_folder_and_resumes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = ["design", *TINY, "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"), "--json"]
    assert main(args) == 0
    captured = capsys.readouterr()
    first = json.loads(captured.out)
    assert first["status"] == "finished" and first["solves"] >= 1
    err = captured.err.splitlines()
    assert "evaluating generation 0: " in err[1] and "generation  0/2: best" in err[2], err  # after the first line
    # the fitness in the objective's unit (Eq 4.1: mm)
    assert re.search(r"generation  0/2: best [0-9.e+-]+ mm  mean [0-9.e+-]+ mm  ", err[2]), err[2]
    # the run's cache hits are the sum of its generations' (an empty cache: none)
    assert first["cache_hits"] == 0 and all(" 0 cache hits" in line for line in err if "/2: best" in line)
    assert first["best"]["design"] in {"00", "01", "10", "11"}
    for name in ("config.toml", "generations.csv", "hall_of_fame.json", "report.md", "profile.png",
                 "winner/deformed.png", "winner/vtk/winner.pvd"):
        assert (tmp_path / "run" / name).is_file(), name
    assert main(args) == 0  # the same command again: everything from the cache
    second = json.loads(capsys.readouterr().out)
    assert second["solves"] == 0 and second["best"] == first["best"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--target", "sin", "--objective", "max-x"], "either --target"),
        (["--target", "y = x.__class__"], "attribute"),
        (["--target", "banana"], "banana"),
        (["--pop", "1"], "--pop must be a whole number >= 2"),
        (["--units", "0"], "--units must be a whole number >= 1"),
    ],
)
def test_design_rejects_bad_input(extra: list[str], message: str, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    given = {a for a in extra if a.startswith("--")}
    base = [a for i, a in enumerate(TINY) if not (a in given or (i > 0 and TINY[i - 1] in given))]  # the extra's own
    code = main(["design", *base, "--out", str(tmp_path / "r"), "--cache", str(tmp_path / "c.sqlite"), *extra])
    assert code == 2
    assert message in capsys.readouterr().err


def test_population_study_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = ["study", "--units", "2", "--pressure", "10", "--populations", "2,4", "--seeds", "2", "--gen", "2",
            "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "st"), "--json"]
    assert main(args) == 0
    captured = capsys.readouterr()
    rows = json.loads(captured.out)["rows"]
    # progress: a line before each run's generation 0, one per generation of each run, one per run
    err = captured.err.splitlines()
    assert sum("evaluating generation 0: " in line for line in err) == 4
    for pop in (2, 4):
        for seed in (0, 1):
            for gen in (0, 1, 2):
                assert sum(f"population {pop}, seed {seed}, generation {gen}/2: best " in line and " mm  mean " in line
                           for line in err) == 1, (pop, seed, gen)
    assert "run 4/4 done" in captured.err
    assert [r["population"] for r in rows] == [2, 4]
    for r in rows:
        assert r["lowest"] <= r["mean"] <= r["largest"] and len(r["best"]) == 2
    assert (tmp_path / "st" / "study.png").is_file()
    assert main(["study", "--populations", "2,x", "--out", str(tmp_path / "s2")]) == 2


def _certified(tmp_path: Path, *extra: str) -> list[str]:
    return ["design", "--model", "2d", "--units", "6", "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"),
            "--out", str(tmp_path / "run"), *extra]


def test_certified_design_on_the_shipped_2d_table(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*_certified(tmp_path, "--target", "cos", "--amplitude", "5", "--certify"), "--json"]) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    cert = out["certificate"]
    # the FE verification is never silent: every verified design is named before its solve and after it
    before = [line for line in captured.err.splitlines() if "  verifying " in line]
    after = [line for line in captured.err.splitlines() if "  verified " in line]
    for design in cert["verified"]:
        assert sum(design in line for line in before) == 1 and sum(design in line for line in after) == 1
    assert cert["certified"] and cert["designs_scored"] == 64 and cert["complete"]
    assert out["best"]["design"] in cert["verified"] and out["solves"] == len(cert["verified"])
    top = out["top"]
    assert top[0]["fe"] is not None and abs(top[0]["fe"] - top[0]["chain"]) <= cert["bound"]
    for name in ("certificate.json", "top.csv", "ranking.csv", "chain-vs-fe.png", "profile.png", "report.md"):
        assert (tmp_path / "run" / name).is_file(), name
    assert "## Certificate" in (tmp_path / "run" / "report.md").read_text()
    saved = json.loads((tmp_path / "run" / "certificate.json").read_text())
    assert saved["winner"]["design"] == out["best"]["design"]
    # the certificate in words, printed and in the report (the same run again: answered from the cache)
    assert main(_certified(tmp_path, "--target", "cos", "--amplitude", "5", "--certify")) == 0
    text = capsys.readouterr().out
    verdict = f"Certified: of the 64 designs scored by the chain model, none can beat {out['best']['design']}."
    verified = f"Verified by FE (2d): {len(cert['verified'])} design"
    assert f"  {verdict}\n" in text and f"  {verified}" in text and "  Bound: the chain model's value of " in text
    report = (tmp_path / "run" / "report.md").read_text()
    assert f"- {verdict}\n" in report and f"- {verified}" in report


def test_certified_design_refuses_bad_tables_before_writing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from pneumorph.models.chain.sources import shipped_path

    bad = tmp_path / "bad.json"
    bad.write_text('{"kind": "pneumorph chain table", "format": 1, "window": 2')
    assert main(_certified(tmp_path, "--chain-table", str(bad))) == 2
    err = capsys.readouterr().err
    assert f"chain table {bad}: not valid JSON" in err and "Traceback" not in err and len(err.strip().splitlines()) <= 2
    assert not (tmp_path / "run").exists()
    # the 3D table for the 2D model
    assert main(_certified(tmp_path, "--chain-table", str(shipped_path("3d")))) == 2
    assert "another model" in capsys.readouterr().err
    assert not (tmp_path / "run").exists()
    # too few units for the table's window
    args = _certified(tmp_path, "--chain-table", str(shipped_path("2d")))
    args[args.index("6")] = "4"
    assert main(args) == 2
    assert "needs at least 5 units" in capsys.readouterr().err


def test_gravity_falls_back_to_the_genetic_algorithm(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    config = tmp_path / "g.toml"
    config.write_text('[design]\nunits = 2\n[ga]\npopulation = 4\ngenerations = 1\n'
                      '[execution]\nexecutor = "serial"\n[model]\npressure_kpa = 10\ngravity = "hanging"\n')
    assert main(["design", str(config), "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"),
                 "--json"]) == 0
    captured = capsys.readouterr()
    assert "falling back to the genetic algorithm" in captured.err
    assert "certificate" not in json.loads(captured.out)
    assert (tmp_path / "run" / "generations.csv").is_file()


@pytest.mark.slow
def test_a_users_unit_gets_its_table_on_first_use_and_keeps_it(tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    unit = tmp_path / "coarse.toml"
    unit.write_text("[unit]\nelement_size = 3.0\n")
    cache = tmp_path / "cache" / "c.sqlite"
    args = ["design", "--model", "2d", "--unit", str(unit), "--pressure", "20", "--units", "7", "--executor", "serial",
            "--target", "cos", "--amplitude", "4", "--cache", str(cache), "--out", str(tmp_path / "run"), "--json"]
    assert main(args) == 0
    captured = capsys.readouterr()
    first = json.loads(captured.out)
    # the plan and its estimate before the first solve, then the build's progress
    plan = captured.err.index("building the chain table of the 2d model (unit with element_size 3, 2-20 kPa in 10 "
                              "levels)")
    training = make_model(15, {"fidelity": "2d", "unit_file": str(unit), "pressure_kpa": 20})
    counts = build_plan(training, **build_options(training))
    assert counts.windows == (2, 3) and counts.fewest == len(covering_designs(15, 2)) + 6  # 6 held-out if clear
    assert f"{counts.fewest}-{counts.solves[-1]} FE solves, estimated" in captured.err
    assert plan < captured.err.index(f"covering and {MIN_HELDOUT} held-out: 1/")  # one stream of solves
    assert "held-out" in captured.err and "building the tolerance tables" in captured.err
    kept = sorted((tmp_path / "cache" / "chain-tables").glob("chain-2d-*.json"))
    tables = [p for p in kept if "tolerance" not in p.name]
    assert len(tables) == 1 and [p.name for p in kept if "tolerance" in p.name] == [
        tables[0].name.replace(".json", "-tolerance-0.1.json")]  # the unit's tolerance tables, kept beside it
    assert first["robustness"]["winner"]["worst"] >= first["robustness"]["winner"]["mean"]
    from pneumorph.models.chain.model import ChainTable

    table = ChainTable.load(tables[0])
    assert table.source["n_units"] == 15 and max(table.validation["centre_worst_mm"]) <= 0.2
    # the solves of the build (15-unit designs) and the verification (6 units)
    assert first["solves"] > len(table.training) + len(first["certificate"]["verified"])
    assert main(args) == 0  # again: the table is found and every verification is cached
    again = json.loads(capsys.readouterr().out)
    assert again["solves"] == 0 and again["best"] == first["best"]


@pytest.mark.slow
def test_a_model_the_chain_cannot_represent_falls_back_to_the_ga(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    from pneumorph.errors import LocalityError
    from pneumorph.models.chain import sources as chaintables

    def no_locality(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise LocalityError("the chain model does not reproduce this model within 0.2 mm")

    monkeypatch.setattr(chaintables, "build_table", no_locality)
    unit = tmp_path / "coarse.toml"
    unit.write_text("[unit]\nelement_size = 3.0\n")
    args = ["design", "--unit", str(unit), "--pressure", "10", "--units", "7", "--pop", "4", "--gen", "1",
            "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"), "--json"]
    monkeypatch.chdir(tmp_path)
    assert main(args) == 0
    captured = capsys.readouterr()
    assert "falling back to the genetic algorithm" in captured.err
    out = json.loads(captured.out)
    assert "certificate" not in out and re.search(r"-7u-ga-2d-[0-9a-f]{8}$", out["folder"])
    assert not list((tmp_path / "runs").glob("*certified*"))  # the refused search left no folder


@pytest.mark.slow
def test_a_tampered_cache_entry_is_solved_again_and_reported(tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    import sqlite3

    args = ["design", *TINY, "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"), "--json"]
    assert main(args) == 0
    first = json.loads(capsys.readouterr().out)
    with sqlite3.connect(tmp_path / "c.sqlite") as db:  # someone edits a stored response
        (row, text), *_ = db.execute("SELECT rowid, response FROM evaluations").fetchall()
        db.execute("UPDATE evaluations SET response = ? WHERE rowid = ?",  # one entry (of one model)
                   (text.replace('"curl"', '"curl" ', 1).replace("1", "2", 1), row))
    assert main(args) == 0
    second = json.loads(capsys.readouterr().out)
    assert second["cache_entries_rejected"] == 1 and second["solves"] == 1
    assert second["best"] == first["best"]  # the tampered value was never used
    assert "1 damaged cache entries were solved again" in (tmp_path / "run" / "report.md").read_text()


# -- short actuators, pressures served by a table's levels, no silent builds ---------------------------
def _short(tmp_path: Path, units: int, *extra: str) -> list[str]:
    return ["design", "--model", "2d", "--units", str(units), "--executor", "serial", "--tolerance", "0",
            "--cache", str(tmp_path / "cache" / "c.sqlite"), "--out", str(tmp_path / f"run{units}"), "--json", *extra]


@pytest.mark.parametrize(("units", "search", "solves"), [(1, "exhaustive", 1), (4, "exhaustive", 9),
                                                          (5, "certified", 1)])
def test_an_actuator_shorter_than_its_table_needs_is_searched_exhaustively(
        units: int, search: str, solves: int, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the shipped 2D table (window +-2) needs 5 units; below, every design is solved (2^(n-1) + 1 with the mirror)
    assert main(_short(tmp_path, units)) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    assert out["search"] == search and out["solves"] == solves and len(out["best"]["design"]) == units
    report = (tmp_path / f"run{units}" / "report.md").read_text()
    if search == "exhaustive":
        assert out["search_note"].startswith(f"FE exhaustive search over all {2**units} designs instead of the "
                                             "certified search: the chain table of window +-2 needs at least 5 units")
        assert out["search_note"] in captured.err and out["search_note"] in report
        ranking = (tmp_path / f"run{units}" / "ranking.csv").read_text().splitlines()
        assert len(ranking) == 1 + 2**units and "certificate" not in out
        best = float(ranking[1].split(",")[2])
        assert best == out["best"]["fitness"] == min(float(r.split(",")[2]) for r in ranking[1:])
    else:
        assert out["certificate"]["designs_scored"] == 32 and out["certificate"]["complete"]


def test_a_pressure_between_the_tables_levels_is_served_by_the_levels_below_it(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = _short(tmp_path, 6, "--pressure", "25", "--target", "cos", "--amplitude", "5", "--certify", "--no-build")
    assert main(args) == 0
    captured = capsys.readouterr()
    out = json.loads(captured.out)
    note = ("certified search with the chain table of window +-2 fitted to 10 levels, scored at the table's levels "
            "4.5-22.5 kPa (5 levels) at or below 25 kPa")
    assert out["search"] == "certified" and out["search_note"] == note and note in captured.err
    cert = out["certificate"]
    assert cert["certified"] and cert["designs_scored"] == 64 and out["solves"] == len(cert["verified"])
    assert out["best"]["pressure_kpa"] in {4.5, 9.0, 13.5, 18.0, 22.5}
    top = out["top"][0]
    assert top["fe"] is not None and abs(top["fe"] - top["chain"]) <= cert["bound"]
    assert not (tmp_path / "cache" / "chain-tables").exists()  # nothing built, nothing kept
    config = (tmp_path / "run6" / "config.toml").read_text()
    assert "pressures_kpa = [4.5, 9.0, 13.5, 18.0, 22.5]" in config and "pressure_kpa = 25.0" in config
    assert note in (tmp_path / "run6" / "report.md").read_text()


@pytest.mark.slow
def test_no_build_stops_a_run_that_needs_a_table_with_one_line(tmp_path: Path,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    args = _short(tmp_path, 8, "--pressure", "3", "--no-build")
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    tables = tmp_path / "cache" / "chain-tables"
    assert "--no-build: no chain table serves the 2d model (the built-in unit, 0.3-3 kPa in 10 levels" in err
    assert "(the shipped table's levels start at 4.5 kPa)" in err
    assert f"`pneumorph chain build --model 2d --pressure 3 --out {tables}/chain-2d-" in err
    training = make_model(15, {"fidelity": "2d", "pressure_kpa": 3})
    counts = build_plan(training, **build_options(training))
    assert f"{counts.fewest}-{counts.solves[-1]} FE solves, estimated" in err
    assert not (tmp_path / "run8").exists() and not tables.exists()


def test_no_build_does_not_fall_back_to_the_ga(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # 26 types: a table at window +-1 needs (2*26)^2/2 = 1352 covering solves, more than MAX_TRAINING, so the
    # chain cannot serve and the certified run would fall back to the GA on the FE model
    units = "".join(f'[[units]]\nsymbol = "{chr(97 + i)}"\nunit = {{}}\n' for i in range(26))
    library = tmp_path / "many.toml"
    library.write_text(f'[library]\nname = "many"\n{units}')
    out = tmp_path / "run"
    args = ["design", "--library", str(library), "--model", "2d", "--no-build", "--cache", str(tmp_path / "c.sqlite"),
            "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert "1352 FE solves" in err and "--no-build" in err and "falling back" not in err
    assert "the fall-back to the genetic algorithm on the FE model is not started" in err
    assert not out.exists() and not (tmp_path / "c.sqlite").exists()


def test_no_build_stops_a_run_whose_tolerance_tables_are_missing(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    args = _short(tmp_path, 6, "--no-build")
    args[args.index("--tolerance") + 1] = "0.05"  # tolerance tables are shipped for +-0.1 mm only
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert "--no-build: the mould tolerance tables of this unit (+-0.05 mm) are neither shipped nor kept" in err
    assert "30 FE solves of 15-unit designs; estimated" in err and "--tolerance 0" in err
    assert not (tmp_path / "run6").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--objective", "max-x", "--amplitude", "20"], "--amplitude shapes a profile target, not the tip goal max-x"),
        (["--objective", "min-distance", "--periods", "2", "--amplitude", "5"], "--amplitude/--periods shape"),
        (["--target", "y = 0.1*x", "--amplitude", "5"], "which the target y = 0.1*x does not use"),
        (["--target", "y = A*x/L", "--periods", "2"], "--periods applies to the sin and cos presets"),
        (["--tolerance", "0", "--robust-samples", "5"], "which --tolerance 0 turns off"),
        (["--units", "5", "--periods", "1000"], "--periods 1000: a sin or cos target over 5 unit centres shows at "
                                                "most 2.5 periods"),
        (["--units", "5", "--stage", "45:sin", "--periods", "3"], "shows at most 2.5 periods"),
    ],
)
def test_shape_options_that_would_be_ignored_are_refused(args: list[str], message: str, tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "never"
    assert main(["design", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_tolerance_as_large_as_a_wall_names_the_option(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    unit = tmp_path / "thin.toml"
    unit.write_text("[unit]\nside_wall = 1.0\n")  # the thinnest wall a mould casts (MIN_WALL_MM)
    for argv in (["design", "--tolerance", "1.0", "--unit", str(unit), "--out", str(tmp_path / "never")],
                 ["sensitivity", "tolerances", "--tolerance", "1.0", "--unit", str(unit), "--units", "2",
                  "--executor", "serial"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert "not smaller than the unit's side_wall (1 mm)" in err and "--tolerance" in err
    assert not (tmp_path / "never").exists()

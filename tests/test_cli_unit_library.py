"""``pneumorph chain build --library`` and ``pneumorph design --library``: a mixed design end to end, bad input."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from pneumorph.cli import main
from pneumorph.models.chain.model import ChainTable

#: bending and near-rigid units, meshed coarsely for quick 2D solves
LIBRARY = """[library]
name = "coarse"
[[units]]
symbol = "a"
unit = { element_size = 3.0 }
[[units]]
symbol = "r"
mode = "near-rigid"
unit = { element_size = 3.0, solid = true, name = "near_rigid" }
"""


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """A library file, a chain table over it (2D, 7 units, 25 kPa) and the cache it was built through."""
    folder = tmp_path_factory.mktemp("lib")
    lib = folder / "lib.toml"
    lib.write_text(LIBRARY)
    table, cache = folder / "t.json", folder / "c.sqlite"
    args = ["chain", "build", "--model", "2d", "--library", str(lib), "--units", "7", "--pressure", "25",
            "--window", "1", "--heldout", "4", "--workers", "1", "--cache", str(cache), "--out", str(table)]
    assert main(args) == 0
    return lib, table, cache


def test_chain_build_over_a_library_reports_every_type(built, capsys: pytest.CaptureFixture[str]) -> None:
    _lib, path, _ = built
    table = ChainTable.load(path)
    assert table.alphabet == ("a", "r") and len(table.training) >= 8
    per = table.validation["per_type"]
    assert per["a"]["centres"] + per["r"]["centres"] == 4 * 7
    assert max(table.validation["centre_worst_mm"]) <= 0.2


def test_design_over_a_library_verifies_a_mixed_winner(built, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    lib, table, cache = built
    out = tmp_path / "run"
    args = ["design", "--library", str(lib), "--model", "2d", "--units", "7", "--pressure", "25", "--amplitude",
            "5", "--chain-table", str(table), "--tolerance", "0", "--executor", "serial", "--cache", str(cache),
            "--out", str(out), "--json"]
    assert main(args) == 0
    result = json.loads(capsys.readouterr().out)
    winner = result["best"]["design"]
    assert len(winner) == 7 and set(winner.lower()) <= {"a", "r"}
    rows = list(csv.DictReader((out / "top.csv").open()))
    assert rows[0]["design"] == winner and all(set(r["design"].lower()) <= {"a", "r"} for r in rows)
    cert = json.loads((out / "certificate.json").read_text())["certificate"]
    assert cert["designs_scored"] == 4**7
    # chain and FE agree on the winner within the bound
    assert abs(float(rows[0]["chain"]) - float(rows[0]["fe"])) <= cert["bound_worst"]


def test_ga_over_a_library_writes_letter_designs(built, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lib, _, cache = built
    out = tmp_path / "ga"
    args = ["design", "--library", str(lib), "--model", "2d", "--units", "4", "--pressure", "15", "--search", "ga",
            "--pop", "6", "--gen", "2", "--executor", "serial", "--cache", str(cache), "--out", str(out), "--json"]
    assert main(args) == 0
    winner = json.loads(capsys.readouterr().out)["best"]["design"]
    fame = json.loads((out / "hall_of_fame.json").read_text())
    designs = [entry["design"] for entry in fame["designs"]]
    assert winner == designs[0] and all(len(d) == 4 and set(d) <= set("aArR") for d in designs)
    rows = list(csv.DictReader((out / "generations.csv").open()))
    assert len(rows) == 3 and all(set(r["best_design"]) <= set("aArR") for r in rows)


def test_simulate_solves_a_mixed_design_as_design_and_the_api_build_it(built, tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    from pneumorph.models.factory import make_model

    lib, _, _ = built
    out = tmp_path / "sim"
    assert main(["simulate", "-o", "aRa", "--library", str(lib), "--pressure", "10", "--increments", "2",
                 "--out", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["orientation"] == "aRa" and len(result["levels"]) == 2
    written = json.loads((out / "provenance.json").read_text())["fingerprint"]
    model = make_model(3, {"fidelity": "2d", "pressure_kpa": 10, "increments": 2, "library": str(lib)})
    assert written == model.fingerprint() and model.mixed
    # a near-rigid unit in the middle: the actuator curls less than with three bending units
    assert main(["simulate", "-o", "aaa", "--library", str(lib), "--pressure", "10", "--increments", "2",
                 "--json"]) == 0
    bending = json.loads(capsys.readouterr().out)
    assert 0 < result["levels"][-1]["curl_deg"] < 0.9 * bending["levels"][-1]["curl_deg"]


@pytest.mark.parametrize(("args", "message"), [
    (["design", "--library", "{twice}", "--model", "2d"], "symbol 'a' is given twice"),
    (["chain", "build", "--model", "2d", "--library", "{twice}", "--out", "{out}"], "symbol 'a' is given twice"),
    (["design", "--library", "{missing}", "--model", "2d"], "missing.toml"),
    (["design", "--library", "builtin", "--model", "2d", "--units", "7", "--pressure", "25", "--chain-table",
      "{table}", "--tolerance", "0"], "unit type 'e', 's' has no table (it covers a, r)"),
    (["design", "--library", "{lib}", "--model", "2d", "--search", "exhaustive"],
     "--search exhaustive over a unit library"),
    (["design", "--library", "{lib}", "--model", "2d", "--tolerance", "0.1", "--out", "{run}"],
     "--tolerance: the mould tolerance report"),
    # e is symmetric (7 codes a unit): window +-3's base windows alone need 7^4 / 2 designs
    (["chain", "build", "--model", "2d", "--library", "builtin", "--window", "3", "--out", "{out}"],
     "needs at least 1200 FE solves"),
    (["design", "--library", "{lib}", "--unit", "{unit}"], "either --unit or --library"),
])
def test_bad_library_input_is_one_line_and_exit_2(built, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                  args: list[str], message: str) -> None:
    lib, table, cache = built
    twice = tmp_path / "twice.toml"
    twice.write_text('[[units]]\nsymbol = "a"\n[[units]]\nsymbol = "a"\n')
    unit = tmp_path / "unit.toml"
    unit.write_text("[unit]\nelement_size = 3.0\n")
    names = {"twice": twice, "lib": lib, "table": table, "out": tmp_path / "t.json",
             "missing": tmp_path / "missing.toml", "unit": unit, "run": tmp_path / "run"}
    code = main([a.format(**names) for a in args] + ["--cache", str(cache)] if args[0] == "design" else
                [a.format(**names) for a in args])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "t.json").exists() and not (tmp_path / "run").exists()

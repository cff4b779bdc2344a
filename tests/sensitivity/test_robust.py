"""Tolerance tables: exact at their nodes, against FE off them, and the design run's robustness report."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.design.runs.robustness import design_robustness
from pneumorph.errors import ChainTableError
from pneumorph.models.chain.model import ChainModel, ChainTable, design_array
from pneumorph.models.chain.sources import shipped_path
from pneumorph.models.chain.windows import window_codes
from pneumorph.models.factory import make_model
from pneumorph.sensitivity import Tolerance, perturbed
from pneumorph.sensitivity.robust import (
    ToleranceTables,
    inner_codes,
    shipped_tolerance_path,
    shipped_tolerance_tables,
)
from pneumorph.sensitivity.tolerances import matched_element_size


def test_inner_windows_of_wider_windows() -> None:
    bits = np.random.default_rng(0).integers(0, 2, size=(50, 9))
    for w in (1, 2, 3):
        assert np.array_equal(inner_codes(window_codes(bits, w), w), window_codes(bits, 1))


@pytest.mark.parametrize("fidelity", ["2d", "3d"])
def test_shipped_tables_are_exact_at_their_nodes_and_round_trip(fidelity: str, tmp_path: Path) -> None:
    tables = shipped_tolerance_tables(fidelity)
    assert tables.tolerance == Tolerance(0.1) and tables.source["element_size"] == 1.71
    t = tables.tolerance.tolerance
    for i in range(3):
        for sign, node in ((-1, tables.minus[i]), (1, tables.plus[i])):
            o = np.zeros(3)
            o[i] = sign * t
            moved = tables.perturbed(tables.nominal, o)
            assert np.allclose(moved.turn, node.turn, atol=1e-12) and np.allclose(moved.length, node.length, atol=1e-12)
            assert np.allclose(moved.centre_y, node.centre_y, atol=1e-12)
    nominal = ChainTable.load(shipped_path(fidelity))
    assert np.array_equal(tables.perturbed(nominal, np.zeros(3)).turn, nominal.turn)
    tables.save(tmp_path / "t.json")
    again = ToleranceTables.load(tmp_path / "t.json")
    assert np.array_equal(again.plus[2].turn, tables.plus[2].turn) and again.source == tables.source
    with pytest.raises(ChainTableError, match="outside"):
        tables.perturbed(nominal, np.array([0.2, 0.0, 0.0]))


def test_perturbed_chain_predicts_the_fe_model_of_a_perturbed_unit() -> None:
    # measured: the offsets move the 2D shape by 5-21 mm; the chain follows within 0.12-0.29 mm
    model = make_model(15, {"fidelity": "2d"})
    tables = shipped_tolerance_tables("2d")
    nominal = ChainTable.load(shipped_path("2d"))
    unit = replace(model.unit, element_size=matched_element_size(model.unit, tables.tolerance))
    design, offsets = "110010111011100", tables.tolerance.samples(1, seed=2)[0]
    fe = model.variant(unit=perturbed(unit, tables.tolerance.fields, offsets)).evaluate(design)
    shift = np.hypot(*(fe.centres - model.evaluate(design).centres).transpose(2, 0, 1)).max()
    centres, _, _ = ChainModel(tables.perturbed(nominal, offsets), 15).predict(design_array(design))
    error = np.hypot(*(centres[0] - fe.centres).transpose(2, 0, 1)).max()
    assert shift > 3.0 and error < 0.1 * shift and error < 0.35


def test_design_robustness_statistics_and_the_robust_level() -> None:
    from pneumorph.design.objectives.targets import make_objective

    nominal = ChainTable.load(shipped_path("2d"))
    tables = shipped_tolerance_tables("2d")
    objective = make_objective("sin", 10.0, 1.0, length=157.5)
    bits = design_array(["001111010001000", "000000000000000", "011110100010000"])
    fixed = design_robustness(nominal, tables, objective, bits, level=np.array([8, 8, 8]), samples=12, seed=3)
    assert fixed.values.shape == (12, 3) and (fixed.level == 8).all()
    worst, mean, p95 = (fixed.statistic(s) for s in ("worst", "mean", "p95"))
    assert (worst >= p95).all() and (p95 >= fixed.values.min(axis=0)).all() and (worst >= mean).all()
    chosen = design_robustness(nominal, tables, objective, bits, samples=12, seed=3, choose="worst")
    assert (chosen.statistic("worst") <= worst + 1e-12).all()  # the most robust level is at least as good
    again = design_robustness(nominal, tables, objective, bits, level=np.array([8, 8, 8]), samples=12, seed=3)
    assert np.array_equal(again.values, fixed.values)  # seeded


def test_design_run_reports_robustness_and_ranks_by_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    base = ["design", "--model", "2d", "--executor", "serial", "--cache", str(tmp_path / "c.sqlite"), "--json"]
    assert main([*base, "--out", str(tmp_path / "a")]) == 0
    plain = json.loads(capsys.readouterr().out)
    w = plain["robustness"]["winner"]
    assert w["design"] == plain["best"]["design"] and w["samples"] == 30 and w["worst"] >= w["p95"] >= w["best"]
    assert "Robustness to mould tolerances" in (tmp_path / "a" / "report.md").read_text()
    assert main([*base, "--out", str(tmp_path / "b"), "--robust", "worst", "--robust-samples", "10"]) == 0
    robust = json.loads(capsys.readouterr().out)
    r = robust["robustness"]
    assert r["robust_winner"]["design"] == robust["best"]["design"] == r["ranking"][0]["design"]
    assert r["ranking"][0]["worst"] <= w["worst"]  # no design is less robust than the most robust one
    assert [row["worst"] for row in r["ranking"]] == sorted(row["worst"] for row in r["ranking"])


def test_fe_robustness_of_another_search_and_bad_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = ["design", "--model", "2d", "--units", "3", "--search", "exhaustive", "--pressure", "20", "--executor",
            "serial", "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"), "--json",
            "--robust-samples", "4"]
    assert main(args) == 0
    rob = json.loads(capsys.readouterr().out)["robustness"]
    assert rob["method"].startswith("FE") and rob["samples"] == 4 and rob["failed"] == 0
    # the nominal unit on the matched mesh is the design model's mesh: the same value
    assert rob["winner"]["nominal_matched_mesh"] == pytest.approx(rob["winner"]["nominal_fe"], abs=1e-6)
    for bad, message in ((["--tolerance", "-0.1"], "--tolerance"), (["--robust", "worst"], "robust")):
        assert main([*args[:-2], *bad]) == 2
        assert message in capsys.readouterr().err
    assert shipped_tolerance_path("3d").is_file()


def test_the_interpolation_is_exact_for_any_quadratic_with_interactions() -> None:
    tables = shipped_tolerance_tables("2d")  # its tolerance and the corner order only
    t = tables.tolerance.tolerance
    rng = np.random.default_rng(7)
    g, c = rng.normal(size=3), rng.normal(size=3)
    b = rng.normal(size=(3, 3))
    b3 = rng.normal()

    def f(d: np.ndarray) -> float:
        return float(1.5 + g @ d + c @ d**2 + d[0] * d[1] * b[0, 1] + d[0] * d[2] * b[0, 2] + d[1] * d[2] * b[1, 2]
                     + b3 * d.prod())

    axis = [f(s * t * np.eye(3)[i]) for s in (-1, 1) for i in range(3)]
    values = [np.array(f(np.zeros(3))), *map(np.array, axis), *(np.array(f(o)) for o in tables.tolerance.corners())]
    for d in rng.uniform(-t, t, size=(20, 3)):
        assert float(tables._change(values, d)) == pytest.approx(f(d) - f(np.zeros(3)), abs=1e-12)
    # without the corners the interactions are missing
    assert abs(float(tables._change(values[:7], np.full(3, t))) - (f(np.full(3, t)) - f(np.zeros(3)))) > 1e-6


@pytest.mark.slow
def test_every_design_grown_unit_by_unit_equals_them_scored_one_by_one() -> None:
    from pneumorph.design.objectives.targets import make_objective

    nominal, tables = ChainTable.load(shipped_path("2d")), shipped_tolerance_tables("2d")
    every = ((np.arange(2**15)[:, None] >> np.arange(14, -1, -1)) & 1).astype(np.uint8)
    for objective in (make_objective("sin", 10.0, 1.0, length=157.5), make_objective("max-x", 10.0)):
        grown = design_robustness(nominal, tables, objective, every, samples=3, seed=1, choose="worst")
        one_by_one = design_robustness(nominal, tables, objective, every[:-1], samples=3, seed=1, choose="worst")
        assert np.abs(grown.values[:, :-1] - one_by_one.values).max() < 1e-9
        assert np.array_equal(grown.level[:-1], one_by_one.level)

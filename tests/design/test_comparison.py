"""Designing again with an identified model: the nominal model's optimum judged by the identified
model (design --model-file), on small 2D actuators that the shipped 2D chain table serves."""

from __future__ import annotations

import json
from pathlib import Path

from click.testing import CliRunner

from pneumorph.cli import cli
from pneumorph.design import DesignConfig, Problem
from pneumorph.design.certified.search import certified_search
from pneumorph.design.objectives.fitness import score
from pneumorph.design.runs.comparison import compare_with_reference
from pneumorph.execution.cache import CachedEvaluator, EvaluationCache
from pneumorph.execution.serial import SerialEvaluator
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import serve_table

UNITS = 8


def test_the_nominal_optimum_is_judged_by_the_other_model(tmp_path: Path) -> None:
    nominal = DesignConfig(units=UNITS, executor="serial", model={"fidelity": "2d"})
    stiffer = nominal.with_options({}, model={"body_bulk_scale": 1.3})
    model, reference = stiffer.make_model(), nominal.make_model()
    assert model.fingerprint() != reference.fingerprint()
    with EvaluationCache(tmp_path / "c.sqlite") as store:
        evaluator = CachedEvaluator(SerialEvaluator(), store)
        objective = nominal.make_objective()
        problem = Problem(stiffer, model, objective, evaluator=evaluator, reference=reference)
        served = serve_table(reference)
        assert served is not None  # the shipped 2D table
        own = certified_search(served.model, ChainModel(served.table, UNITS), objective, evaluator).winner
        winner = own  # any verified candidate of this model serves as "this run's winner" here
        out = compare_with_reference(problem, winner)
        assert out is not None and "note" not in out
        assert out["reference_design"] == own.design and out["reference_value"] == own.value
        # that design solved on the stiffer model, independently
        response = model.evaluate(own.design)
        assert out["reference_on_model"] == score(response, objective).value
        assert out["reference_on_model"] != out["reference_value"]  # the bulk modulus moves the shape
        assert out["gain"] == out["reference_on_model"] - winner.value and out["same"] is True
    assert compare_with_reference(Problem(stiffer, model, objective), winner) is None  # no reference


def test_design_with_a_model_file_reports_the_nominal_design(tmp_path: Path) -> None:
    # an identified model at nominal: the same chain table serves it, and the nominal design comes back
    (tmp_path / "identified.toml").write_text('[model]\nfidelity = "2d"\nbody_bulk_scale = 1.0\n', encoding="utf-8")
    runner = CliRunner()
    args = ["design", "--units", str(UNITS), "--executor", "serial", "--tolerance", "0", "--cache",
            str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"),
            "--model-file", str(tmp_path / "identified.toml")]
    done = runner.invoke(cli, [*args, "--json"])
    assert done.exit_code == 0, done.output
    out = json.loads(done.stdout)
    comparison = out["comparison"]
    assert comparison["same"] is True and comparison["reference_design"] == out["best"]["design"]
    assert comparison["reference_on_model"] == comparison["winner_value"] == out["best"]["fitness"]
    report = (tmp_path / "run" / "report.md").read_text(encoding="utf-8")
    assert f"the nominal model chose the same design {out['best']['design']}" in report
    # a certified run's hall of fame holds the chain's values, the winner's is by FE: each labelled
    assert "| rank | design | chain (mm) | pressure (kPa) |" in report and "The chain model's values" in report
    assert "warning" not in done.stderr  # not a file of pneumorph identify: nothing to say of its fit
    plain = runner.invoke(cli, args)  # again, from the cache: the comparison in words
    assert plain.exit_code == 0, plain.output
    assert "the nominal model chose the same design" in plain.stdout
    # a file of pneumorph identify whose scans left parameters undetermined: said before the run
    (tmp_path / "identified.toml").write_text('[model]\nfidelity = "2d"\nbody_bulk_scale = 1.0\n[provenance]\n'
                                              'identified = ["wall", "layer"]\n', encoding="utf-8")
    warned = runner.invoke(cli, args)
    assert warned.exit_code == 0, warned.output
    assert ("did not identify body_bulk_scale, body_shear_scale, side_wall (fixed at nominal or confounded)"
            in warned.stderr)


def test_an_exhaustive_run_of_an_identified_model_reports_the_nominal_design(tmp_path: Path) -> None:
    """A model no chain table serves, on an actuator too short for a new table: the certified run searches every
    design by FE, and still judges the nominal model's optimum (from the shipped table) by this model."""
    (tmp_path / "identified.toml").write_text('[model]\nfidelity = "2d"\nbody_shear_scale = 0.85\n',
                                              encoding="utf-8")
    args = ["design", "--units", "5", "--executor", "serial", "--tolerance", "0", "--target", "y = 0.1*x",
            "--cache", str(tmp_path / "c.sqlite"), "--out", str(tmp_path / "run"),
            "--model-file", str(tmp_path / "identified.toml"), "--json"]
    done = CliRunner().invoke(cli, args)
    assert done.exit_code == 0, done.output
    out = json.loads(done.stdout)
    c = out["comparison"]
    assert "note" not in c and c["winner_design"] == out["best"]["design"]
    assert c["gain"] >= 0 and c["gain"] == c["reference_on_model"] - c["winner_value"]
    # the nominal optimum solved on the identified model, independently
    config = DesignConfig(objective="y = 0.1*x", units=5, model={"fidelity": "2d", "body_shear_scale": 0.85})
    response = config.make_model().evaluate(c["reference_design"])
    assert c["reference_on_model"] == score(response, config.make_objective()).value

"""The unit optimisation end to end on a tiny, coarse problem: NSGA-II, the constraint, the outputs, resuming."""

from __future__ import annotations

import csv
import json

import pytest

from pneumorph.errors import GeometryError, SettingsError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.unitopt.measures import UnitMeasures
from pneumorph.unitopt.problem import UnitCandidate
from pneumorph.unitopt.run import OptimiseSettings, front_of, optimise, write_outputs
from pneumorph.unitopt.space import DesignSpace, Variable

#: two variables on a coarse mesh at 10 kPa: a candidate solves in well under a second
SPACE = DesignSpace((Variable("cavity_height", 4.5, 7.5), Variable("end_wall", 2.0, 3.5)),
                    base=UnitSpec(name="unitopt", element_size=3.0), resolution=0.5)


def _settings(**changes: object) -> OptimiseSettings:
    return OptimiseSettings(**{"space": SPACE, "pressure": 0.01, "pop_size": 4, "generations": 1, "seed": 3,
                               **changes})  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory):
    folder = tmp_path_factory.mktemp("unitopt")
    cache = folder / "cache.sqlite"
    result = optimise(_settings(), CachedEvaluator(SerialEvaluator(), EvaluationCache(cache)))
    write_outputs(result, folder / "out", command="test")
    return result, folder, cache


def test_two_generations_write_the_front_the_table_the_figure_and_unit_files(run) -> None:
    """The start and one generation of offspring (pymoo's n_gen = 2)."""
    result, folder, _ = run
    out = folder / "out"
    assert {p.name for p in out.iterdir()} >= {"candidates.csv", "pareto.csv", "pareto.json", "front.png", "units"}
    rows = list(csv.DictReader((out / "candidates.csv").open()))
    assert len(rows) == len(result.candidates) >= 4 + 1  # the start and at least one offspring
    assert {int(r["generation"]) for r in rows} >= {0, 1}
    data = json.loads((out / "pareto.json").read_text())
    assert data["provenance"]["settings"]["seed"] == 3 and data["provenance"]["command"] == "test"
    assert len(data["front"]) == len(result.front) >= 1
    # the front is non-dominated and sorted by h_b, with Omega rising along it
    omegas = [r["omega_deg"] for r in data["front"]]
    balloons = [r["balloon_mm"] for r in data["front"]]
    assert balloons == sorted(balloons) and omegas == sorted(omegas)
    # every chosen point's unit file is a unit of the space that `chain build --unit` reads
    units = {p.stem: UnitSpec.from_toml(p) for p in (out / "units").glob("*.toml")}
    assert {"max-omega", "min-balloon", "knee"} <= set(units)
    for label, unit in units.items():
        values = data["chosen"][label]
        assert unit.cavity_height == values["cavity_height"] and unit.end_wall == values["end_wall"]
        assert unit.element_size == 3.0 and unit.name == f"unitopt_{label.replace('-', '_')}"


def test_better_units_bend_more_at_no_more_ballooning_than_the_base(run) -> None:
    result, _, _ = run
    base = result.base.measures
    assert base is not None and result.base.values == {"cavity_height": 6.0, "end_wall": 3.0}
    for c in result.better():
        assert c.measures is not None
        assert c.measures.omega_deg > base.omega_deg and c.measures.balloon_mm <= base.balloon_mm


def test_a_rerun_with_the_same_seed_is_answered_from_the_cache(run) -> None:
    result, _, cache = run
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(cache))
    again = optimise(_settings(), evaluator)
    assert evaluator.solves == 0 and evaluator.hits == len(again.candidates)
    assert [c.values for c in again.front] == [c.values for c in result.front]


def test_the_strain_limit_makes_units_infeasible(run) -> None:
    result, _, _ = run
    strains = sorted(c.measures.strain for c in result.candidates if c.measures is not None)
    limit = strains[len(strains) // 2]  # half of the units strain more than this
    front = front_of(result.candidates, limit)
    assert front and all(c.measures is not None and c.measures.strain <= limit for c in front)
    over = next(c for c in result.candidates if c.measures is not None and c.measures.strain > limit)
    assert over.constraints(limit, 0.01)[0] > 0 and not over.feasible(limit)


def test_a_failed_ramp_is_infeasible_by_the_pressure_it_lacked() -> None:
    failed = UnitCandidate({"wall": 1.0}, UnitSpec(), None, "limit point", 0.03, False, 1.0, 0)
    assert failed.constraints(4.4, 0.045) == pytest.approx((0.0, 1 / 3))
    assert not failed.feasible(4.4)
    ok = UnitCandidate({"wall": 1.0}, UnitSpec(), UnitMeasures(20.0, 3.0, 3.0, 1.0, 2.0, 2.2, 0.1, 20.0), None, 0.045,
                   False, 1.0, 0)
    assert ok.constraints(4.4, 0.045) == pytest.approx((-0.5, 0.0)) and ok.objectives() == (-20.0, 3.0)


def test_bad_settings_are_refused_before_any_solve() -> None:
    with pytest.raises(SettingsError, match="strain limit"):
        _settings(strain_limit=0.0)
    with pytest.raises(SettingsError, match="strain limit"):
        _settings(strain_limit=float("nan"))
    with pytest.raises(SettingsError, match="unknown unit variable"):
        Variable("height", 1.0, 2.0)
    bad = DesignSpace((Variable("end_wall", 2.0, 5.5),), base=UnitSpec(element_size=3.0))
    with pytest.raises(GeometryError, match=r"end_wall=5\.5"):
        optimise(_settings(space=bad), object())  # an evaluator that cannot solve: refused before it is asked


def test_a_pipe_in_place_of_pareto_json_is_not_read_and_the_folder_is_refused(tmp_path) -> None:
    import os

    from pneumorph.errors import RunFolderError
    from pneumorph.unitopt.run import check_folder

    os.mkfifo(tmp_path / "pareto.json")  # reading it would wait for a writer for ever
    with pytest.raises(RunFolderError, match=r"another run's files \(pareto\.json\); give another folder"):
        check_folder(tmp_path, _settings())
    check_folder(tmp_path, _settings(), overwrite=True)  # taken: its outputs are replaced

"""Targets at several pressures of the ramp: the staged cost, its bound, the certified search, the config and CLI."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.design import DesignConfig, make_objective, run_exhaustive
from pneumorph.design.certified.search import certified_search, chain_errors, chain_scores, objective_bounds
from pneumorph.design.config import to_toml
from pneumorph.design.objectives.fitness import objective_values, stage_values
from pneumorph.design.objectives.targets import StagedTarget, staged_target, tip_goal
from pneumorph.errors import SearchConfigError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.models.chain.model import ChainModel, design_strings
from pneumorph.models.fe import Reduced2D

N = 6  # the units of the coarse_2d fixture (conftest.py)


@pytest.fixture(scope="module")
def setup(coarse_2d):  # type: ignore[no-untyped-def]
    """The real 2D model (coarse mesh, 25 kPa, 6 units) and its chain (tests/design/conftest.py)."""
    return coarse_2d


def _staged(length: float) -> StagedTarget:
    return staged_target([(0.01, make_objective("y = 0.04*x")),
                          (0.025, make_objective("sin", amplitude=5.0, length=length), 2.0),
                          (0.02, tip_goal("reach", (60.0, 15.0)), 0.5)])


def test_the_staged_cost_is_the_weighted_root_sum_square_of_each_stage_at_its_level(setup) -> None:
    model, chain, _ = setup
    staged = _staged(chain.length)
    assert staged.levels(model.pressures()) == (3, 9, 7)
    scores = chain_scores(chain, staged)
    assert scores.complete and len(scores.bits) == 2**N
    # every design: the stages' own chain values at their own levels, combined with the weights
    each = [chain_scores(chain, s.target) for s in staged.stages]
    number = {d: i for i, d in enumerate(design_strings(each[0].bits))}
    at = np.array([number[d] for d in design_strings(scores.bits)])
    parts = np.stack([e.per_level[at, k] for e, k in zip(each, (3, 9, 7), strict=True)], axis=1)
    expected = np.sqrt(((parts * [1.0, 2.0, 0.5]) ** 2).sum(axis=1))
    assert np.allclose(scores.cost, expected, rtol=1e-12, atol=1e-12)
    assert np.all(scores.level == 9)  # the cost stands at the highest stage's level; the others are the worst
    assert np.isinf(scores.per_level[:, :9]).all()
    # the bound: the same weighted norm of the stages' own bounds at their levels
    errors = chain_errors(chain)
    own = [objective_bounds(chain, s.target, np.zeros((1, 10, N, 2)), np.zeros((1, N, 2)), errors)[0, k]
           for s, k in zip(staged.stages, (3, 9, 7), strict=True)]
    assert scores.bound[0] == pytest.approx(np.sqrt(sum((w * b) ** 2 for w, b in zip((1.0, 2.0, 0.5), own,
                                                                                      strict=True))), rel=1e-12)


@pytest.mark.slow
def test_the_certified_search_over_stages_equals_the_fe_exhaustive_search(setup) -> None:
    model, chain, evaluator = setup
    staged = _staged(chain.length)
    truth = run_exhaustive(model, staged, evaluator)
    result = certified_search(model, chain, staged, evaluator, verify=1, certify=True)
    assert result.certificate["certified"] and result.certificate["gap"] == 0.0
    assert result.winner.value == pytest.approx(truth.best.value, abs=1e-9)
    assert result.winner.design == truth.best.design
    assert result.winner.pressure == pytest.approx(0.025)
    # the FE value is the weighted root-sum-square of the FE stages, and within the bound of the chain's
    fe = result.winner.response
    assert result.winner.value == pytest.approx(float(np.sqrt(((stage_values(fe, staged) * [1, 2, 0.5]) ** 2).sum())))
    order = result.scores.order()
    names = design_strings(result.scores.bits[order])
    for design, c in result.verified.items():
        i = order[names.index(design)]
        assert abs(result.scores.cost[i] - c.value) <= result.scores.bound[i] + 1e-9
    assert np.isinf(objective_values(fe, staged)[:9]).all()


def test_stages_that_cannot_be_added_up_or_are_off_the_ramp_are_refused() -> None:
    with pytest.raises(SearchConfigError, match="'max-y' is a maximum, not a distance"):
        staged_target([(0.02, tip_goal("max-y"))])
    with pytest.raises(SearchConfigError, match="polar profiles"):
        staged_target([(0.02, make_objective("r = 20 + 5*theta"))])
    with pytest.raises(SearchConfigError, match="the weight must be a positive number"):
        staged_target([(0.02, make_objective("sin"), 0.0)])
    with pytest.raises(SearchConfigError, match="two stages at one pressure"):
        staged_target([(0.02, make_objective("sin")), (0.02, make_objective("cos"))])
    staged = staged_target([(0.018, make_objective("sin")), (0.02, make_objective("cos"))])
    with pytest.raises(SearchConfigError, match=r"stage at 20 kPa: not a level of the model's ramp; the levels are "
                                                r"4\.5, 9, 13\.5, 18, 22\.5, 27, 31\.5, 36, 40\.5, 45 kPa"):
        staged.levels(np.linspace(0.0045, 0.045, 10))


def test_a_config_with_stages_round_trips_through_toml() -> None:
    config = DesignConfig(objective="stages", units=8, stage=(
        {"pressure_kpa": 18, "objective": "curve", "curve": [[0, 0], [40, 2], [80, 5]]},
        {"pressure_kpa": 45, "objective": "reach", "point": [60, 20], "weight": 0.5}))
    again = DesignConfig.from_dict(tomllib.loads(to_toml(config.to_dict())))
    assert again == config
    assert again.make_objective().label.startswith("stages: 18 kPa: curve: y = curve through 3 points; 45 kPa")
    with pytest.raises(SearchConfigError, match=r"\[\[design.stage\]\] 1 needs pressure_kpa"):
        DesignConfig(objective="stages", stage=({"objective": "sin"},))
    with pytest.raises(SearchConfigError, match="unknown key 'pressure' in"):
        DesignConfig(objective="stages", stage=({"pressure": 18, "objective": "sin"},))
    with pytest.raises(SearchConfigError, match='only applies to objective = "stages"'):
        DesignConfig(objective="sin", stage=({"pressure_kpa": 18, "objective": "sin"},))
    with pytest.raises(SearchConfigError, match="needs its stages"):
        DesignConfig(objective="stages")
    with pytest.raises(SearchConfigError, match=r"\[\[design.stage\]\]: stage at 18 kPa: 'max-x' is a maximum"):
        DesignConfig(objective="stages", stage=({"pressure_kpa": 18, "objective": "max-x"},))


@pytest.mark.slow
def test_design_with_stages_on_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    unit = tmp_path / "coarse.toml"
    unit.write_text("[unit]\nelement_size = 3.0\n")
    common = ["design", "--model", "2d", "--unit", str(unit), "--pressure", "20", "--units", "7", "--executor",
              "serial", "--tolerance", "0", "--cache", str(tmp_path / "c.sqlite")]
    # a stage off the ramp's levels: one line, exit 2, nothing written, before any solve
    assert main([*common, "--stage", "10:sin", "--stage", "15:y = 0.1*x", "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "stage at 15 kPa: not a level of the model's ramp" in err
    assert not (tmp_path / "bad").exists() and not (tmp_path / "c.sqlite").exists()
    assert main([*common, "--stage", "10:reach 40", "--out", str(tmp_path / "bad")]) == 2
    assert "reach needs the tip point X Y" in capsys.readouterr().err
    out = tmp_path / "run"
    assert main([*common, "--stage", "10:y = 0.05*x", "--stage", "20:sin", "--amplitude", "4", "--out",
                 str(out)]) == 0
    report = (out / "report.md").read_text()
    assert "- weighted root-sum-square of the stages:" in report
    assert "  - stage at 10 kPa (weight 1):" in report and "  - stage at 20 kPa (weight 1):" in report
    assert (out / "profile.png").stat().st_size > 10_000
    config = DesignConfig.read(out / "config.toml")
    assert config.objective == "stages" and [s["pressure_kpa"] for s in config.stage or ()] == [10.0, 20.0]
    assert config.stage is not None and config.stage[1]["amplitude"] == 4.0


@pytest.mark.parametrize("refine_at", [None, 0])
def test_branch_and_bound_over_stages_keeps_every_design_that_matters(refine_at: int | None,
                                                                     monkeypatch: pytest.MonkeyPatch,
                                                                     keeps_every_design) -> None:
    """30-unit-style growth on 15 units of the shipped 3D table: forced past enumeration, it keeps every design
    whose enumerated cost is below its threshold, with the same cost, and the same best design; also with the
    profile stages' bound on the centres still to place at every depth (``REFINE_AT = 0``)."""
    from pneumorph.design.certified import planegrowth as growth
    from pneumorph.models.chain.model import ChainTable
    from pneumorph.models.chain.sources import shipped_path

    if refine_at is not None:
        monkeypatch.setattr(growth, "REFINE_AT", refine_at)

    chain = ChainModel(ChainTable.load(shipped_path("3d")), 15)
    staged = staged_target([(0.018, make_objective("y = 0.05*x")),
                            (0.045, make_objective("sin", amplitude=10.0, length=chain.length)),
                            (0.027, tip_goal("reach", (150.0, 20.0)), 0.5)])
    every = chain_scores(chain, staged)
    grown = chain_scores(chain, staged, max_enumerate=10)  # the beam, then branch-and-bound
    assert len(grown.cost) < len(every.cost) / 10
    keeps_every_design(every, grown)


def test_the_stages_bound_on_the_centres_still_to_place_drops_no_design_below_the_threshold(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Admissible: with each profile stage's bound on its centres still to place at every depth (``REFINE_AT =
    0``), branch-and-bound at thresholds across the enumerated costs (all 4^7 designs of the 3D bending and
    near-rigid table) returns every design below the threshold."""
    from pneumorph.design.certified import planegrowth as growth
    from pneumorph.models.chain.model import ChainTable

    monkeypatch.setattr(growth, "REFINE_AT", 0)
    table = ChainTable.load(Path(__file__).resolve().parents[2] / "examples" / "libraries"
                            / "chain-3d-bending-rigid.json")
    chain = ChainModel(table, 7)
    staged = staged_target([(0.018, make_objective("y = 0.02*x", length=chain.length)),
                            (0.045, make_objective("sin", amplitude=10.0, length=chain.length), 2.0)])
    errors = chain_errors(chain)
    every = growth.grow_designs(chain, staged, errors)
    assert len(every.cost) == 4**7
    names = dict(zip(table.texts(every.bits), every.cost, strict=True))
    for q in (0.001, 0.01, 0.1, 0.5):
        threshold = float(np.quantile(every.cost, q))
        grown = growth.grow_designs(chain, staged, errors, threshold)
        kept = set(table.texts(grown.bits))
        must = {d for d, c in names.items() if c < threshold}
        assert must and must <= kept
        if q <= 0.01:
            assert len(kept) < 4**7 / 4  # and the bound prunes


def test_a_target_through_a_designs_own_centres_at_two_pressures_gives_it_back() -> None:
    """Curves drawn through the 2D FE centres of a design at 18 and 45 kPa, as two stages: the certified search over
    all 2^15 designs (shipped 2D table, 2D FE verification) returns that design, at an FE cost of 0."""
    from pneumorph.models.chain.model import ChainTable
    from pneumorph.models.chain.sources import shipped_path

    model = Reduced2D(15)
    chain = ChainModel(ChainTable.load(shipped_path("2d")), 15)
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    design = "011100101100011"
    (outcome,) = evaluator.evaluate_many(model, [design])
    r = outcome.response
    levels = staged_target([(0.018, make_objective("sin")), (0.045, make_objective("sin"))]).levels(r.pressures)

    def through(k: int) -> object:
        points = np.column_stack([r.centres[k, :, 0], r.centres[k, :, 1] - r.reference_centres[:, 1]])
        return make_objective("curve", curve=np.vstack([[0.0, 0.0], points]))

    staged = staged_target([(r.pressures[k], through(k)) for k in levels])
    result = certified_search(model, chain, staged, evaluator, certify=True)
    assert result.winner.design == design and result.certificate["certified"]
    assert result.winner.value == pytest.approx(0.0, abs=1e-9)
    assert np.allclose(stage_values(result.winner.response, staged), 0.0, atol=1e-9)

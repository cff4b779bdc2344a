"""Run folders: files, provenance, kill and resume, Ctrl-C, another run in the folder; the study."""

from __future__ import annotations

import csv
import json
import tomllib
from pathlib import Path

import pytest

from pneumorph.design import (
    DesignConfig,
    GAConfig,
    make_objective,
    plot_population_study,
    population_study,
    run_design,
)
from pneumorph.errors import RunFolderError, SearchConfigError
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator

from .toy_model import DyingToy, ToyModel


class Killed(BaseException):
    """Stands for the process being killed: nothing catches it."""


def config(tmp_path: Path, **kw) -> DesignConfig:
    ga = GAConfig(population=16, generations=8, indpb=1 / 8, hall_of_fame=5)
    return DesignConfig(**{"objective": "sin", "units": 8, "ga": ga, "cache": str(tmp_path / "cache.sqlite"),
                           "search": "ga", "executor": "serial", **kw})  # toy models, solved in this process


def test_the_api_defaults_are_the_command_lines() -> None:
    """DesignConfig's defaults run as ``pneumorph design``: a process pool, the 3D model for the certified
    search (2D for the others), through DesignConfig.make_model."""
    c = DesignConfig()
    assert c.search == "certified" and c.executor == "processes" and c.fidelity == "3d"
    assert c.make_model().fidelity == "3d" and c.model_settings() == {"fidelity": "3d"}
    assert DesignConfig(search="ga").make_model().fidelity == "2d"
    assert DesignConfig(model={"fidelity": "2d"}).make_model().fidelity == "2d"
    assert DesignConfig.from_dict({"design": {"units": 4}}).executor == "processes"  # a config file without one


def test_run_folder_contents(tmp_path: Path) -> None:
    cfg = config(tmp_path)
    result = run_design(cfg, ToyModel(), tmp_path / "run")
    folder = tmp_path / "run"
    assert result.status == "finished"
    names = {p.name for p in folder.iterdir()}
    written = {"config.toml", "generations.csv", "hall_of_fame.json", "report.md", "profile.png", "convergence.png"}
    assert written <= names
    saved = tomllib.loads((folder / "config.toml").read_text())
    assert DesignConfig.from_dict(saved) == cfg
    prov = saved["provenance"]
    assert prov["model_fingerprint"] == ToyModel().fingerprint() and prov["seed"] == 0
    assert prov["model_fidelity"] == "toy" and prov["pressures_kpa"][-1] == 45.0
    assert {"numpy", "deap"} <= set(prov["dependencies"]) and prov["pneumorph"]
    rows = list(csv.DictReader((folder / "generations.csv").open()))
    assert [int(r["generation"]) for r in rows] == list(range(9))
    assert [float(r["best"]) for r in rows] == [h.best for h in result.history]
    hof = json.loads((folder / "hall_of_fame.json").read_text())
    best = result.best
    assert hof["designs"][0]["design"] == best.design and hof["sense"] == "min"
    assert hof["designs"][0]["pressure_kpa"] == pytest.approx(best.pressure * 1e3)
    for name in ("hall_of_fame.json", "config.toml", "ranking.csv"):  # one spelling of kPa in keys: pressure_kpa
        if (folder / name).exists():
            assert "kPa" not in (folder / name).read_text(), name
    report = (folder / "report.md").read_text()
    assert f"`{best.design}`" in report and f"{best.pressure * 1e3:.4g} kPa" in report and "error (Eq 4.1)" in report
    assert "| rank | design | FE (mm) | pressure (kPa) |" in report  # a GA's hall of fame: the model's own values


def test_a_killed_run_resumes_without_solving_any_cached_design(tmp_path: Path) -> None:
    reference = run_design(config(tmp_path / "ref"), ToyModel(), tmp_path / "ref" / "run", figures=False)
    total = reference.solves
    dying = DyingToy(budget=37, signal=Killed)
    with pytest.raises(Killed):
        run_design(config(tmp_path), dying, tmp_path / "run", figures=False)
    cache = EvaluationCache(tmp_path / "cache.sqlite")
    stored = set(cache.designs(ToyModel().fingerprint()))
    assert stored == set(dying.calls) and len(stored) == 37
    again = ToyModel()
    resumed = run_design(config(tmp_path), again, tmp_path / "run", figures=False)
    assert not stored & set(again.calls)  # no cached design solved again
    assert len(again.calls) == total - 37 == resumed.solves and resumed.cache_hits >= 37
    assert [c.design for c in resumed.hall_of_fame] == [c.design for c in reference.hall_of_fame]
    assert [h.best for h in resumed.history] == [h.best for h in reference.history]
    assert tomllib.loads((tmp_path / "run" / "config.toml").read_text())["provenance"]["resumed"] is True


def test_ctrl_c_stops_cleanly_and_the_next_run_resumes(tmp_path: Path) -> None:
    dying = DyingToy(budget=40, signal=KeyboardInterrupt)
    result = run_design(config(tmp_path), dying, tmp_path / "run", figures=False)
    assert result.status == "interrupted" and result.best is None
    rows = list(csv.DictReader((tmp_path / "run" / "generations.csv").open()))
    assert len(rows) == len(result.history) >= 1  # the finished generations were flushed
    assert "Interrupted" in (tmp_path / "run" / "report.md").read_text()
    again = ToyModel()
    finished = run_design(config(tmp_path), again, tmp_path / "run", figures=False)
    assert finished.status == "finished" and finished.cache_hits >= 40
    assert len(again.calls) == finished.solves and not set(again.calls) & set(dying.calls)


def test_exhaustive_run_writes_the_ranking(tmp_path: Path) -> None:
    result = run_design(config(tmp_path, objective="max-y", search="exhaustive", units=5), ToyModel(n_units=5),
                        tmp_path / "run", figures=False)
    rows = list(csv.DictReader((tmp_path / "run" / "ranking.csv").open()))
    assert len(rows) == 32 and rows[0]["design"] == result.best.design
    assert result.solves == 17  # 16 designs starting with 0, plus one mirror to check the symmetry
    assert not (tmp_path / "run" / "generations.csv").exists()


def test_another_run_in_the_same_folder_is_refused(tmp_path: Path) -> None:
    run_design(config(tmp_path), ToyModel(), tmp_path / "run", figures=False)
    with pytest.raises(RunFolderError, match=r"other \[design\] settings") as info:
        run_design(config(tmp_path, amplitude=15.0), ToyModel(), tmp_path / "run")
    # the message names the differing setting and both ways out, on one line
    assert "amplitude = 10.0 there, 15.0 now;" in str(info.value)
    assert "--out" in str(info.value) and "--overwrite" in str(info.value) and "\n" not in str(info.value)
    with pytest.raises(RunFolderError, match="another model"):
        run_design(config(tmp_path), ToyModel(turn=25.0), tmp_path / "run")
    redo = run_design(config(tmp_path, amplitude=15.0), ToyModel(), tmp_path / "run", overwrite=True, figures=False)
    assert redo.status == "finished"
    with pytest.raises(SearchConfigError, match="the model has 6 units but the config asks for 8"):
        run_design(config(tmp_path), ToyModel(n_units=6), tmp_path / "other")


def test_config_file_errors(tmp_path: Path) -> None:
    path = tmp_path / "c.toml"
    path.write_text('[design]\nobjective = "cos"\namplitude = 20\nunits = 8\n[ga]\npopulation = 40\n')
    cfg = DesignConfig.read(path)
    assert (cfg.objective, cfg.amplitude, cfg.ga.population, cfg.ga.generations) == ("cos", 20.0, 40, 15)
    path.write_text("[ga]\npopsize = 40\n")
    with pytest.raises(SearchConfigError, match="unknown key 'popsize' in \\[ga\\]"):
        DesignConfig.read(path)
    path.write_text("[ga]\npopulation = 1\n")
    with pytest.raises(SearchConfigError, match="population must be a whole number >= 2"):
        DesignConfig.read(path)
    with pytest.raises(SearchConfigError, match="units must be a whole number >= 1"):
        DesignConfig(units=0)


def test_population_study(tmp_path: Path) -> None:
    model = ToyModel(n_units=6)
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    study = population_study(model, make_objective("sin"), populations=(4, 8), seeds=(0, 1, 2), generations=5,
                             evaluator=evaluator)
    assert [r.population for r in study.rows] == [4, 8]
    for row in study.rows:
        assert len(row.best) == 3 and row.lowest <= row.mean <= row.largest
        assert row.lowest == min(row.best) and all(0 <= g <= 5 for g in row.converged_at)
    assert evaluator.solves <= 64  # runs share the cache: no design of the 64 solved twice
    assert plot_population_study(study, tmp_path / "study.png").stat().st_size > 0

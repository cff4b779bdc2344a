"""``pneumorph study``: the GA population-size study of section 6.1 (Fig 6.1)."""

from __future__ import annotations

from typing import Any

import click

from pneumorph.checks import MAX_GENERATIONS, MAX_POPULATION, MAX_STARTS
from pneumorph.cli.options import params as P
from pneumorph.cli.options.execution import (
    check_options,
    cluster_line,
    cluster_report,
    execution_options,
    open_evaluator,
)
from pneumorph.cli.progress import reporter


@click.command("study")
@click.argument("config_file", required=False, type=P.InputFile())
@click.option("--populations", type=P.RealList(P.Count(2, MAX_POPULATION, limit="MAX_POPULATION"), max_items=100),
              default="20,40,60,80", show_default=True, metavar="LIST",
              help="Population sizes, comma-separated.")
@click.option("--seeds", type=P.Count(1, MAX_STARTS, limit="MAX_STARTS"), default=5, show_default=True,
              help="Runs (seeds 0..N-1) per population size.")
@click.option("--gen", "generations", type=P.Count(0, MAX_GENERATIONS, limit="MAX_GENERATIONS"), default=25,
              show_default=True, help="Generations per run.")
@click.option("--units", type=P.UNITS, help="Number of units (default: the config's, else 15).")
@click.option("--target", type=P.Text(), help="Profile target (default: the config's, else sin, amplitude 10 mm).")
@click.option("--pressure", type=P.PRESSURE_KPA, help="Maximum pressure, kPa (default 45).")
@execution_options()
@click.option("--cache", metavar="FILE", type=P.CacheFile(),
              help="Evaluation cache (default ~/.cache/pneumorph/evaluations.sqlite).")
@click.option("--out", type=P.OutputDir(), default="runs/population-study", show_default=True, metavar="DIR",
              help="Folder for study.json and study.png.")
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON.")
def study(config_file: str | None, populations: list[int], seeds: int, generations: int, units: int | None,
          target: str | None, pressure: float | None, executor: str, workers: int | None, scheduler: str | None,
          cache: str | None, out: str, as_json: bool) -> None:
    """Best fitness against GA population size over several seeds (lowest, largest, mean).

    Every design is solved once for the whole study: all runs share the evaluation cache.
    """
    from dataclasses import replace

    from pneumorph.design import DesignConfig, plot_population_study, population_study
    from pneumorph.io import provenance, strict_json, write_json
    from pneumorph.models.factory import make_model

    check_options(executor, workers, scheduler)
    pops = tuple(populations)
    if target is not None:
        from pneumorph.design.objectives.targets import make_objective
        from pneumorph.geometry.unit import UnitSpec

        with P.blame("--target"):
            make_objective(target, length=(units or DesignConfig.units) * UnitSpec.pitch)
    config = DesignConfig.read(config_file) if config_file else DesignConfig()
    changes: dict[str, Any] = {k: v for k, v in (("units", units), ("objective", target)) if v is not None}
    model_settings = dict(config.model)
    if pressure is not None:
        model_settings["pressure_kpa"] = pressure
    config = replace(config, model=model_settings, **changes)
    config = DesignConfig.from_dict(config.to_dict())
    model = make_model(config.units, config.model)
    objective = config.make_objective()
    evaluator = open_evaluator(executor, workers, scheduler, cache)
    click.echo(f"population study: {objective.label}, populations {pops}, {seeds} seeds, "
               f"{generations} generations, {config.units} units", err=True)

    runs = len(pops) * seeds
    done: list[int] = []

    def on_message(text: str) -> None:  # before a run's generation 0
        click.echo(f"  run {len(done) + 1}/{runs}: {text}", err=True)

    def on_generation(pop: int, seed: int, stats) -> None:
        click.echo(f"    population {pop}, seed {seed}, generation {stats.generation}/{generations}: "
                   f"{stats.describe(objective.unit)}", err=True)

    def on_run(pop: int, seed: int, result) -> None:
        done.append(pop)
        best = result.best
        click.echo(f"  population {pop:3d}, seed {seed}: best {best.value:.4g} {objective.unit} ({best.design}); "
                   f"run {len(done)}/{runs} done", err=True)

    try:
        result = population_study(model, objective, pops, tuple(range(seeds)), generations,
                                  base=replace(config.ga, seed=0), evaluator=evaluator, on_run=on_run,
                                  on_generation=on_generation, on_message=on_message)
    finally:
        evaluator.close()
    cluster = cluster_report(evaluator)
    if (line := cluster_line(evaluator)) is not None:
        click.echo(line, err=True)
    from pneumorph.io.files import all_or_nothing

    summary = {
        "objective": result.objective, "unit": result.unit, "generations": result.generations,
        "rows": [row.as_dict() for row in result.rows], **({"cluster": cluster} if cluster else {}),
        "provenance": provenance(model=model.describe(), fingerprint=model.fingerprint(), config=config.to_dict()),
    }
    # stopped while writing (Ctrl-C, a full disk): no partial output
    with all_or_nothing(out, say=reporter(), what="study.json and study.png") as folder:
        write_json(folder / "study.json", summary)
        plot_population_study(result, folder / "study.png")
    if as_json:
        click.echo(strict_json({k: v for k, v in summary.items() if k != "provenance"}))
    else:
        click.echo(f"{'population':>10} {'lowest':>10} {'largest':>10} {'mean':>10}   [{result.unit}]")
        for row in result.rows:
            click.echo(f"{row.population:>10} {row.lowest:>10.4g} {row.largest:>10.4g} {row.mean:>10.4g}")
        click.echo(f"written to {folder}/ (study.json, study.png)")

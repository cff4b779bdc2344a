"""``pneumorph chain``: build and inspect the chain tables of the certified search."""

from __future__ import annotations

from typing import Any

import click

from pneumorph.checks import MAX_STARTS, MAX_UNITS
from pneumorph.cli.options import params as P
from pneumorph.cli.options.execution import (
    check_options,
    cluster_line,
    cluster_report,
    execution_options,
    open_evaluator,
)
from pneumorph.cli.progress import reporter


@click.group("chain")
def chain() -> None:
    """Chain tables: per-window chord turns and lengths fitted to FE solves (documentation page chain-model,
    docs/chain-model.md in the source)."""


@chain.command("build")
@click.option("--model", "fidelity", type=click.Choice(["2d", "3d"]), default="3d", show_default=True,
              help="The FE model the table is fitted to.")
@click.option("--unit", "unit_file", type=P.InputFile(),
              help="Unit TOML file (default: the built-in unit).")
@click.option("--library", metavar="builtin|spatial|modes|FILE", type=P.Text(),
              help="A unit library ('builtin', 'spatial', 'modes' or a library TOML file): the table covers its unit "
                   "types "
                   "(documentation page unit-library, docs/unit-library.md in the source); instead of --unit.")
@click.option("--pressure", type=P.PRESSURE_KPA, help="Maximum pressure, kPa (default 45).")
@click.option("--quadrature", type=click.Choice(["full", "reduced", "irons"]),
              help="The quadrature rule of the model's quadratic cells (default full; the model's [model] quadrature, "
                   "documentation page notes/fe-core); the table is served with the model at this rule.")
@click.option("--units", "n_units", type=P.Count(3, MAX_UNITS, limit="MAX_UNITS"), default=15, show_default=True,
              help="Units of the training designs.")
@click.option("--window", type=P.Count(1, 3),
              help="Fixed window half-width (default: grow from the window the shipped table of the model's "
                   "fidelity needed, up to 3, until within tolerance; over several unit types from 1).")
@click.option("--tolerance", type=P.Real(0.0, 100.0, low_open=True, unit="mm"), default=0.2, show_default=True,
              help="Worst held-out unit-centre error allowed at every level, mm.")
@click.option("--heldout", type=P.Count(1, MAX_STARTS, limit="MAX_STARTS"), default=20, show_default=True,
              help="Held-out random designs solved.")
@execution_options(what="training and held-out designs")
@click.option("--cache", metavar="FILE", type=P.CacheFile(),
              help="Evaluation cache (default ~/.cache/pneumorph/evaluations.sqlite).")
@click.option("--out", required=True, metavar="FILE", type=P.OutputFile((".json",)), help="Table file to write (JSON).")
@click.option("--short", is_flag=True,
              help="Learn the windows at the base and the tip from actuators of 2w units (documentation page "
                   "chain-model, docs/chain-model.md in the source); the held-out designs keep --units.")
@click.option("--all-heldout", is_flag=True,
              help="Solve every held-out design, even when the first 6 show the table within half the tolerance "
                   "(as the shipped tables are validated).")
@click.option("--far-terms/--no-far-terms", "far", default=None,
              help="Without --window, try first the window one narrower than the first with far-field terms "
                   "(documentation page chain-model, docs/chain-model.md in the source). Default: on for the 3d "
                   "model of one unit type.")
@click.option("--split-terms", "split", is_flag=True,
              help="Far-field terms as every run of 2w units within +-(w + 1) (documentation page chain-model, "
                   "docs/chain-model.md in the source): far fewer training designs over several unit types. "
                   "Default: as the shipped table of a built-in library.")
@click.option("--json", "as_json", is_flag=True, help="Print the validation as JSON.")
def build(fidelity: str, unit_file: str | None, library: str | None, pressure: float | None, quadrature: str | None,
          n_units: int,
          window: int | None, tolerance: float, heldout: int, executor: str, workers: int | None,
          scheduler: str | None, cache: str | None, out: str, short: bool, all_heldout: bool, far: bool | None,
          split: bool, as_json: bool) -> None:
    """Fit and validate the chain table of a unit and model (resumable through the cache).

    The shipped tables of the built-in unit are regenerated with `pneumorph chain build --model 3d --window 3
    --all-heldout --out src/pneumorph/models/data/chain-3d.json` (and 2d with --window 2); the spatial library's
    chain in space with `pneumorph chain build --model 3d --library spatial --window 2 --far-terms --short
    --all-heldout --out src/pneumorph/models/data/chain-3d-spatial.json` (about an hour on 2 workers).
    """
    from pathlib import Path

    from pneumorph.errors import ChainTableError
    from pneumorph.io import strict_json
    from pneumorph.io.files import all_or_nothing_file
    from pneumorph.models.chain.fit import build_table
    from pneumorph.models.chain.model import fitted_quadrature
    from pneumorph.models.chain.plan import build_plan, cached_counter, evaluator_workers
    from pneumorph.models.chain.sources import build_options
    from pneumorph.models.factory import make_model

    check_options(executor, workers, scheduler)
    settings: dict = {"fidelity": fidelity, **({"quadrature": quadrature} if quadrature is not None else {})}
    if unit_file:
        P.unit_option(unit_file)
        settings["unit_file"] = unit_file
    if library is not None:
        P.library_option(library, unit_file)
        settings["library"] = library
    if pressure is not None:
        settings["pressure_kpa"] = pressure
    target = Path(out)
    if window is not None and (window < 1 or 2 * window + 1 > n_units):
        raise ChainTableError(f"--window {window} needs 1 <= window and 2 window + 1 <= --units ({n_units})")
    if split and far is False:
        raise ChainTableError("--split-terms lays out the far-field terms: not with --no-far-terms")
    model = make_model(n_units, settings)
    if getattr(model, "mixed", False):
        from pneumorph.models.chain.fit import check_training_size

        check_training_size(len(model.library), window or 1, len(model.library.symmetric))  # before any solve
    evaluator = open_evaluator(executor, workers, scheduler, cache)
    try:
        defaults = build_options(model)  # the first window and far-field terms a build on first use would take
        options: dict[str, Any] = {"heldout": heldout, "window": window, "tolerance": tolerance, "short": short,
                   "first_window": defaults["first_window"], "early": not all_heldout,
                   "far": "split" if split else defaults["far"] if far is None else far}
        plan = build_plan(model, workers=evaluator_workers(evaluator), cached=cached_counter(evaluator, model),
                          **options)
        with reporter() as lines:  # its heartbeat speaks while a window's solves or fits run
            lines.say(plan.text())  # what will be built and its estimate, before the first solve
            table = build_table(model, evaluator, on_progress=lines, **options)
    finally:
        evaluator.close()
    cluster = cluster_report(evaluator)
    if (line := cluster_line(evaluator)) is not None:
        click.echo(line, err=True)
    with all_or_nothing_file(target, say=lines, what="the chain table") as tmp:  # stopped: no table, no new folder
        try:
            table.save(tmp)
        finally:
            tmp.with_name(tmp.name + ".part").unlink(missing_ok=True)  # save's own temporary file, if it stopped there
    v = table.validation
    if as_json:
        click.echo(strict_json({"file": str(target), "window": table.window, "training": list(table.training),
                                "validation": v, **({"cluster": cluster} if cluster else {})}))
    else:
        click.echo(f"{target}: window +-{table.window}, {len(table.training)} covering designs at the "
                   f"{fitted_quadrature(table)} quadrature rule, "
                   f"{len(v['designs'])} held-out: worst centre error {max(v['centre_worst_mm']):.4f} mm, "
                   f"mean at {table.pressures[-1] * 1e3:g} kPa {v['centre_mean_mm'][-1]:.4f} mm")
        for symbol, errs in v.get("per_type", {}).items():
            if errs["centres"]:
                click.echo(f"  unit type {symbol}: worst held-out centre error {max(errs['centre_worst_mm']):.4f} "
                           f"mm, mean at the last level {errs['centre_mean_mm'][-1]:.4f} mm ({errs['centres']} "
                           "centres)")
        if "end_frame_worst_deg" in v:  # a chain in space with the end face's frame
            click.echo(f"  end face's frame: worst held-out angle {max(v['end_frame_worst_deg']):.4f} deg")

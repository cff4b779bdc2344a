"""``pneumorph calibrate``: the 2D model's filler law for a unit, against the 3D model."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import click

from pneumorph.checks import MAX_STARTS, MAX_UNITS
from pneumorph.cli.options import params as P
from pneumorph.cli.options.execution import check_options, cluster_line, execution_options, open_evaluator
from pneumorph.cli.progress import plan_solves, reporter


@click.command("calibrate")
@click.option("--unit", "unit_file", type=P.InputFile(),
              help="Unit TOML file (default: the built-in unit).")
@click.option("--units", "n_units", type=P.Count(1, MAX_UNITS, limit="MAX_UNITS"), default=15, show_default=True,
              help="Actuator length in units.")
@click.option("--pressures", type=P.RealList(P.PRESSURE_KPA, min_items=2, max_items=100),
              default="5,10,15,20,25,30,35,40,45", show_default=True, metavar="LIST",
              help="Calibration pressures, kPa, comma-separated.")
@click.option("--runs", type=P.Count(1, MAX_STARTS, limit="MAX_STARTS"), default=3, show_default=True,
              help="Independent runs (new random designs).")
@click.option("--seed", type=P.SEED, default=0, show_default=True)
@click.option("--validate", "n_validate", type=P.Count(0, MAX_STARTS, limit="MAX_STARTS"), default=10,
              show_default=True,
              help="Held-out random designs for the 2D-against-3D check.")
@execution_options(default="serial", what="3D references")
@click.option("--cache", metavar="FILE", type=P.CacheFile(),
              help="3D results cache (default ~/.cache/pneumorph/evaluations.sqlite).")
@click.option("--out", type=P.OutputDir(), default="runs/calibration", show_default=True, metavar="DIR")
@click.option("--references-only", is_flag=True,
              help="Only solve (and cache) the 3D references of the calibration and validation designs.")
@click.option("--weighting", type=click.Choice(["relative", "sensitivity", "uniform"]), default="relative",
              show_default=True,
              help="Weights of the points in the fits of E(P): relative error, relative error times the "
                   "measured sensitivity of Eq 5.1 (two more 2D solves per point), or none.")
@click.option("--json", "as_json", is_flag=True)
def calibrate(unit_file: str | None, n_units: int, pressures: list[float], runs: int, seed: int, n_validate: int,
              executor: str, workers: int | None, scheduler: str | None, cache: str | None, out: str,
              references_only: bool, weighting: str, as_json: bool) -> None:
    """Fit the filler law E(P) of the 2D model to the 3D model (chapter 5) and check it.

    Writes calibration.json, calibration.png (Fig 5.3) and unit.toml: the unit with the
    chosen law and its provenance, ready for --unit of the other commands.
    """
    from pneumorph.calibration import run_calibration, solve_references
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.io import strict_json

    check_options(executor, workers, scheduler)
    levels = tuple(sorted(set(pressures)))
    if len(levels) < 2:
        raise click.BadParameter(f"--pressures needs at least two different pressures, got {pressures}",
                                 param_hint="'--pressures'")
    with P.blame("--unit"):
        unit = UnitSpec.from_toml(unit_file) if unit_file else UnitSpec()

    from pneumorph.calibration.references import reference_jobs

    jobs = len(reference_jobs(unit, n_units, levels, runs, seed, n_validate))
    evaluator = open_evaluator(executor, workers, scheduler, cache)  # the 3D references: solved first, into the cache
    with reporter() as lines:
        plan_solves(lines, "3D references", jobs, SimpleNamespace(fidelity="3d", n_units=n_units), executor, workers,
                    None if references_only else out, title=f"3D references ({runs} calibration, {n_validate} "
                    f"validation)")

        def on_point(p: Any) -> None:
            lines.say(f"  run {p.run + 1}, {p.pressure * 1e3:5.1f} kPa, design {p.design}: E = {p.modulus:.5g} MPa "
                      f"(Eq 5.1 = {p.gamma:.4g} mm^2, {p.evaluations} 2D solves)")

        def on_reference(r: Any) -> None:
            msg = f"curl {r.curl:.1f} deg" if r.failure is None else f"FAILED: {r.failure}"
            lines.count(r.index, f"3D reference {r.index}/{r.total} ({r.kind}) {r.design}: {msg}, {r.seconds:.0f} s",
                        always=True)

        try:
            if references_only:
                solve_references(unit, n_units, levels, runs, seed, n_validate, evaluator.cache,
                                 on_reference=on_reference, evaluator=evaluator.inner)
                done = None
            else:
                done = run_calibration(unit, n_units, levels, out, runs, seed, n_validate, weighting, evaluator.cache,
                                       on_point, evaluator=evaluator.inner, on_reference=on_reference,
                                       say=lines)
        finally:
            evaluator.close()
            evaluator.cache.close()
    if (line := cluster_line(evaluator)) is not None:
        click.echo(line, err=True)
    if done is None:
        return
    result = done.calibration
    if as_json:
        click.echo(strict_json({k: v for k, v in done.summary.items() if k != "provenance"}))
        return
    for fit in (result.linear, result.quadratic):
        coeffs = ", ".join(f"{c:.5g}" for c in fit.coefficients)
        click.echo(f"degree {fit.degree}: coefficients [{coeffs}] (MPa, P in MPa), R^2 = {fit.r_squared:.4f} "
                   f"({fit.weighting} weighting; unweighted {fit.r_squared_unweighted:.4f})"
                   + (f"  PROBLEMS: {'; '.join(fit.problems)}" if fit.problems else ""))
    if result.chosen is None:
        click.echo("no acceptable law: nothing written to unit.toml", err=True)
    if done.validation is not None:
        v = done.validation
        for p, m, x in zip(v.pressures * 1e3, v.mean, v.max, strict=True):
            click.echo(f"  {p:5.1f} kPa: 2D-3D unit-centre distance mean {m:.3f} mm, max {x:.3f} mm")
    written = "calibration.json, calibration.png" + (", unit.toml" if done.unit is not None else "")
    click.echo(f"written to {done.folder}/ ({written})")

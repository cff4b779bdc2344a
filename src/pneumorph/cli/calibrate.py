"""``pneumorph calibrate``: the 2D model's filler law for a unit, against the 3D model."""

from __future__ import annotations

from typing import Any

import click

from pneumorph.checks import MAX_STARTS, MAX_UNITS
from pneumorph.cli import params as P


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
              cache: str | None, out: str, references_only: bool, weighting: str, as_json: bool) -> None:
    """Fit the filler law E(P) of the 2D model to the 3D model (chapter 5) and check it.

    Writes calibration.json, calibration.png (Fig 5.3) and unit.toml: the unit with the
    chosen law and its provenance, ready for --unit of the other commands.
    """
    from pathlib import Path

    from pneumorph import calibration as cal_mod
    from pneumorph.design.config import to_toml
    from pneumorph.execution import EvaluationCache, default_cache_path
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.io import atomic_write_text, provenance, strict_json, write_json
    from pneumorph.models.fe import RampSpec

    levels = tuple(sorted(set(pressures)))
    if len(levels) < 2:
        raise click.BadParameter(f"--pressures needs at least two different pressures, got {pressures}",
                                 param_hint="'--pressures'")
    unit = UnitSpec.from_toml(unit_file) if unit_file else UnitSpec()
    store = EvaluationCache(cache or default_cache_path())
    solve_3d = cal_mod.cached_3d_solver(store)

    if references_only:
        _solve_references(unit, n_units, levels, runs, seed, n_validate, solve_3d)
        store.close()
        return

    def on_point(p) -> None:
        click.echo(f"  run {p.run + 1}, {p.pressure * 1e3:5.1f} kPa, design {p.design}: E = {p.modulus:.5g} MPa "
                   f"(Eq 5.1 = {p.gamma:.4g} mm^2, {p.evaluations} 2D solves)", err=True)

    result = cal_mod.calibrate(unit, n_units, levels, runs, seed, solve_3d=solve_3d, on_point=on_point,
                               weighting=weighting)
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    cal_mod.plot_calibration(result, folder / "calibration.png")
    summary = {
        "points": [p.__dict__ for p in result.points],
        "linear": result.linear.__dict__, "quadratic": result.quadratic.__dict__,
        "chosen_degree": None if result.chosen is None else result.chosen.degree,
        "provenance": provenance(unit=unit.to_dict(), calibration=result.metadata),
    }
    if result.chosen is not None:
        calibrated = result.unit_with_law(unit)
        atomic_write_text(folder / "unit.toml", to_toml({"unit": calibrated.to_dict()}))
        if n_validate > 0:
            taken = cal_mod.calibration_designs(n_units, runs, seed)
            designs = cal_mod.holdout_designs(n_units, n_validate, seed, taken)
            p_max = max(levels) / 1e3
            check = cal_mod.validate(calibrated, n_units, designs, RampSpec(pressure=p_max), solve_3d)
            summary["validation"] = check.to_dict()
            summary["figures"] = _validation_figures(result, calibrated, n_units, designs[0], p_max, solve_3d,
                                                     folder)
    write_json(folder / "calibration.json", summary)
    store.close()
    if as_json:
        click.echo(strict_json({k: v for k, v in summary.items() if k != "provenance"}))
        return
    for fit in (result.linear, result.quadratic):
        coeffs = ", ".join(f"{c:.5g}" for c in fit.coefficients)
        click.echo(f"degree {fit.degree}: coefficients [{coeffs}] (MPa, P in MPa), R^2 = {fit.r_squared:.4f} "
                   f"({fit.weighting} weighting; unweighted {fit.r_squared_unweighted:.4f})"
                   + (f"  PROBLEMS: {'; '.join(fit.problems)}" if fit.problems else ""))
    if result.chosen is None:
        click.echo("no acceptable law: nothing written to unit.toml", err=True)
    if "validation" in summary:
        v: Any = summary["validation"]
        for p, m, x in zip(v["pressures_kpa"], v["mean_mm"], v["max_mm"], strict=False):
            click.echo(f"  {p:5.1f} kPa: 2D-3D unit-centre distance mean {m:.3f} mm, max {x:.3f} mm")
    written = "calibration.json, calibration.png" + (", unit.toml" if result.chosen is not None else "")
    click.echo(f"written to {folder}/ ({written})")


def _solve_references(unit, n_units, levels, runs, seed, n_validate, solve_3d) -> None:
    """Solve the 3D references into the cache, one by one, with their wall time."""
    import time

    from pneumorph import calibration as cal_mod
    from pneumorph.models.fe import Full3D, RampSpec

    jobs = [(cal_mod.reference_model(unit, n_units, levels), d)
            for d in cal_mod.calibration_designs(n_units, runs, seed)]
    holdout = Full3D(n_units, unit, RampSpec(pressure=max(levels) / 1e3))
    held = cal_mod.holdout_designs(n_units, n_validate, seed, [d for _, d in jobs])
    jobs += [(holdout, d) for d in held]
    for i, (model, design) in enumerate(jobs, 1):
        t0 = time.perf_counter()
        kind = "calibration" if i <= runs else "validation"
        try:
            r = solve_3d(model, design)
            msg = f"curl {r.curl[-1]:.1f} deg"
        except Exception as exc:  # a failed reference is reported, the others go on
            msg = f"FAILED: {exc}"
        click.echo(f"  3D reference {i}/{len(jobs)} ({kind}) {design}: {msg}, "
                   f"{time.perf_counter() - t0:.0f} s", err=True)


def _validation_figures(result, unit, n_units, design, p_max, solve_3d, folder):
    """Fig 5.4 (each run's law, the chosen law, 3D) and Fig 5.7 (constant filler against E(P))."""
    from dataclasses import replace

    from pneumorph import calibration as cal_mod
    from pneumorph.models.fe import Full3D, RampSpec
    from pneumorph.plot import calibration as figs

    ramp = RampSpec(pressure=p_max)
    reference = solve_3d(Full3D(n_units, unit, ramp), design)
    law = result.law()
    laws = {}
    for run in sorted({p.run for p in result.points}):
        pts = [p for p in result.points if p.run == run]
        fit = cal_mod.fit_law([p.pressure for p in pts], [p.modulus for p in pts], result.chosen.degree,
                              result.pressure_range, cal_mod.point_weights(pts, result.chosen.weighting))
        if fit.coefficients and not fit.problems:  # a run's law that is not positive cannot be solved
            laws[f"run {run + 1} law"] = replace(law, coefficients=fit.coefficients)
    constants = {"constant E(0)": figs.constant_law(law, 0.0, "constant E(0)"),
                 f"constant E({p_max * 1e3:g} kPa)": figs.constant_law(law, p_max, "constant E(p_max)")}
    solved = figs.law_responses(unit, n_units, design, ramp, {"E(P)": law, **laws, **constants})
    fitted = solved.pop("E(P)")  # solved once, drawn in both figures
    runs = {name: solved[name] for name in laws}
    profiles = figs.plot_law_profiles({**runs, "fitted law": fitted}, reference, folder / "profiles.png")
    paths = figs.plot_filler_paths({"E(P)": fitted, **{name: solved[name] for name in constants}}, reference,
                                   folder / "filler_paths.png")
    return [str(profiles), str(paths)]

"""``pneumorph identify``: the model's materials and mould thicknesses fitted to scans of cast actuators."""

from __future__ import annotations

import sys
from typing import Any

import click

from pneumorph.cli.options import params as P
from pneumorph.cli.options.execution import cluster_report, execution_options, open_evaluator


@click.command("identify")
@click.argument("scan", required=False, type=P.InputFile(text=False))
@click.option("--design", "-d", type=P.Text(1000), help="The design scanned (e.g. 001111010001001).")
@click.option("--pressure", type=P.PRESSURE_KPA, help="The pressure it was scanned at, kPa.")
@click.option("--manifest", type=P.InputFile(),
              help="A TOML file of [[scan]] tables (file, design, pressure_kpa, optionally scan_unit or scale) "
                   "instead of SCAN.")
@click.option("--model", "fidelity", type=click.Choice(["3d", "2d"]), default="3d", show_default=True,
              help="The model to identify (a 3D scan needs 3d; a photo trace may use either).")
@click.option("--unit", "unit_file", type=P.InputFile(), help="Unit TOML file of the nominal unit (default: built-in).")
@click.option("--scan-unit", type=click.Choice(["mm", "cm", "m", "in"]),
              help="The unit of SCAN's coordinates (default mm).")
@click.option("--scale", type=P.Real(0.0, 1e6, low_open=True),
              help="mm per unit of SCAN (a photo's mm per pixel), instead of --scan-unit.")
@click.option("--fit", "fit_names", metavar="NAMES", type=P.Text(200),
              help="The parameters to fit, comma-separated (default all: body_bulk_scale, body_shear_scale, "
                   "side_wall, wall, layer); the others stay at nominal.")
@click.option("--tolerance", type=P.Real(0.0, 1.0, low_open=True, unit="mm"), default=0.1, show_default=True,
              help="The thicknesses are fitted within +- this of nominal (every mould in the box is meshed alike).")
@click.option("--seed", type=P.SEED, default=0, show_default=True,
              help="Seed of the sample of a scan's points (scans of more than 4000 points).")
@execution_options(what="solves of the fit")
@click.option("--cache", metavar="FILE", type=P.CacheFile(),
              help="Evaluation cache (SQLite); default ~/.cache/pneumorph/evaluations.sqlite.")
@click.option("--out", type=P.OutputDir(), help="Folder for identified.toml and identify.json.")
@click.option("--overwrite", is_flag=True, help="Replace the identification an --out folder already holds.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
def identify(scan: str | None, design: str | None, pressure: float | None, manifest: str | None, fidelity: str,
             unit_file: str | None, scan_unit: str | None, scale: float | None, fit_names: str | None, tolerance: float,
             seed: int, executor: str, workers: int | None, scheduler: str | None, cache: str | None,
             out: str | None, overwrite: bool, as_json: bool) -> None:
    """Fit the body silicone's bulk and shear modulus scales and the three mould thicknesses (side walls,
    Mold Star wall, Smooth-Sil layer) to scans of cast actuators, by least squares on the distances
    `correlate` measures; report each with its standard error, the correlations, the residuals before and
    after, the combinations of parameters the scans do not determine (held at nominal, the others still
    identified) and which further scan would determine them. With --out, write the identified model
    (identified.toml: a [model] table for design/simulate --model-file).
    """

    from pneumorph.cli.options.execution import check_options
    from pneumorph.errors import SettingsError
    from pneumorph.execution.cache import chain_table_dir
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.identify import (
        NAMES,
        Observation,
        ParameterSet,
        load_scans,
        precheck_designs,
        write_identified,
    )
    from pneumorph.identify import identify as fit
    from pneumorph.io import provenance, strict_json, write_json

    scan_unit = P.scan_unit(scan_unit, scale)
    check_options(executor, workers, scheduler)
    if overwrite and not out:  # an option that would do nothing is refused, not ignored
        raise click.UsageError("--overwrite replaces the identification an --out folder holds: give --out DIR, or "
                               "leave out --overwrite")
    if out and not overwrite:
        _check_out(out)
    specs = _scan_specs(scan, design, pressure, manifest, scan_unit, scale)
    unit = UnitSpec()
    if unit_file is not None:
        with P.blame("--unit"):
            unit = UnitSpec.from_toml(unit_file)
    names = list(NAMES) if fit_names is None else [n.strip() for n in fit_names.split(",") if n.strip()]
    with P.blame("--fit"):
        from pneumorph.identify import parameter_indices

        parameter_indices(names)
        if not names:
            raise SettingsError("give at least one parameter")
    with P.blame("--tolerance"):
        params = ParameterSet(unit, tolerance)
    base: dict[str, Any] = {"fidelity": fidelity}
    # every scan read and checked, every model built (pressures in range), before any solve
    scans = load_scans(specs, unit.pitch)
    observations = [Observation(s, d) for s, d in zip(specs, scans, strict=True)]
    if scans[0].dim == 3 and fidelity == "2d":
        from pneumorph.errors import ScanError

        raise ScanError("a 3D scan needs the 3D model: leave out --model 2d")
    table_dir = chain_table_dir(cache)
    precheck_designs(observations, params, base, table_dir)  # size and units, where a table serves
    click.echo(f"identifying {', '.join(names)} from {len(specs)} scan(s) ({fidelity} model, executor {executor})",
               err=True)
    evaluator = open_evaluator(executor, workers, scheduler, cache)
    try:
        result = fit(observations, params, evaluator, base, names, seed=seed,
                     on_progress=lambda text: click.echo(f"  {text}", err=True), table_dir=table_dir)
    finally:
        evaluator.close()
    summary = {**result.to_dict(), "cluster": cluster_report(evaluator)}
    if out:
        from pneumorph.cli.progress import reporter
        from pneumorph.io.files import all_or_nothing

        command = " ".join(["pneumorph", *sys.argv[1:]])
        # stopped while writing (Ctrl-C, a full disk): no partial output
        with all_or_nothing(out, say=reporter(), what="the identified parameters and identify.json") as folder:
            write_identified(result, folder, command=command)
            write_json(folder / "identify.json", {**summary, "provenance": provenance(command=command)})
    if as_json:
        click.echo(strict_json(summary))
    else:
        _print_identification(result, observations, scans[0].dim, out)


def _check_out(out: str) -> None:
    """Refuse an output folder that holds an earlier identification, before anything is read or solved."""
    from pathlib import Path

    from pneumorph.errors import RunFolderError

    held = [name for name in ("identified.toml", "identify.json") if (Path(out) / name).exists()]
    if held:
        raise RunFolderError(f"--out {out} holds an earlier identification ({', '.join(held)}); give another "
                              "folder or replace it with --overwrite")


def _scan_specs(scan: str | None, design: str | None, pressure: float | None, manifest: str | None, scan_unit: str,
                scale: float | None) -> list[Any]:
    """The scans to fit: the manifest's, or the one SCAN --design --pressure (refusing a mix of both)."""
    from pneumorph.identify import ScanSpec, read_manifest

    if manifest is not None:
        given = [o for o, v in (("SCAN", scan), ("--design", design), ("--pressure", pressure),
                                ("--scale", scale)) if v is not None]
        if given:
            raise click.UsageError(f"give the scans either in --manifest or as SCAN --design --pressure, not both "
                                   f"({', '.join(given)} with --manifest)")
        return list(read_manifest(manifest))
    missing = [o for o, v in (("SCAN", scan), ("--design", design), ("--pressure", pressure)) if v is None]
    if missing:
        raise click.UsageError(f"missing {', '.join(missing)}: give SCAN --design D --pressure P, or --manifest")
    assert scan is not None and design is not None and pressure is not None
    from pneumorph.identify.scans import check_scan_pressure

    with P.blame("--pressure"):
        check_scan_pressure(pressure, "--pressure")
    with P.blame("--design"):
        return [ScanSpec(scan, design, pressure, scan_unit, scale)]


def _print_identification(result: Any, observations: list[Any], dim: int, out: str | None) -> None:
    """The parameters (each column with its unit), the combinations the scans do not determine, what to scan
    next, the correlations and the residuals, in words."""
    from pathlib import Path

    click.echo(f"{'parameter':<17} {'unit':>4} {'nominal':>8} {'value':>9} {'std err':>9} {'confounded':>10}  "
               "identified")
    for name, p in result.parameters().items():
        se = "-" if p["standard_error"] is None else f"{p['standard_error']:.2g}"
        ce = "-" if p["confounded_error"] is None else f"{p['confounded_error']:.2g}"
        note = f"  ({p['note']})" if p["note"] else ""
        click.echo(f"{name:<17} {p['unit']:>4} {p['nominal']:8.4g} {p['value']:9.5g} {se:>9} {ce:>10}  "
                   f"{'yes' if p['identified'] else 'no'}{note}")
    click.echo("(std err: the least-squares standard error; confounded: how far the parameter moves per plausible "
               "change of a combination the scans do not determine; both in the parameter's unit)")
    for c in result.combinations:
        click.echo(f"not determined by these scans: {c['combination']} (it changes them by {c['scan_change_mm']:.2g} "
                   f"mm RMS, against a residual sigma of {result.sigma:.2g} mm); held at nominal")
    if result.advice:
        click.echo(f"scan next: {result.advice[0]['why']}")
        if not result.advice[0]["determines"]:
            click.echo(f"  none of the {len(result.advice)} further scans weighed identifies them: take them from "
                       "coupon tests and fit the others (--fit)")
    if not result.converged:
        click.echo("the iterations stopped before the steps became small: the best point is kept, the parameters "
                   "still moving are not identified")
    if len(result.free) > 1:
        click.echo("correlations of the fitted parameters (the combinations not determined held):")
        for name, row in zip(result.free, result.correlation, strict=True):
            click.echo(f"  {name:<17} " + " ".join(f"{v:+6.3f}" for v in row))
    what = "surface" if dim == 3 else "outline"
    for o, before, after, fit_before, fit_after in zip(observations, result.rms_before, result.rms_after,
                                                        result.residual_before, result.residual_after, strict=True):
        click.echo(f"  {Path(o.spec.file).name}: fit residual (to the surface) {fit_before:.4g} mm at nominal, "
                   f"{fit_after:.4g} mm identified; {what} RMS (as correlate) {before:.4g} mm, {after:.4g} mm")
    click.echo(f"{result.iterations} iteration(s), {result.solves} solves (cache hits included), "
               f"residual sigma {result.sigma:.3g} mm")
    if out:
        click.echo(f"written to {Path(out)}/ (identified.toml, identify.json)")

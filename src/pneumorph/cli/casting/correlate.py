"""``pneumorph correlate``: a scan or photo of an inflated actuator against the model."""

from __future__ import annotations

import click

from pneumorph.cli.options import params as P


@click.command("correlate")
@click.argument("scan", type=P.InputFile(text=False))
@click.option("--design", "-d", required=True, type=P.Text(1000), help="The design scanned (e.g. 001111010001001).")
@click.option("--pressure", type=P.PRESSURE_KPA, default=45.0, show_default=True, help="Its pressure, kPa.")
@click.option("--model", "fidelity", type=click.Choice(["3d", "2d"]), default="3d", show_default=True,
              help="The model to compare with (a 3D scan needs 3d).")
@click.option("--unit", "unit_file", type=P.InputFile(), help="Unit TOML file (default: the built-in unit).")
@click.option("--library", metavar="builtin|spatial|modes|FILE", type=P.Text(),
              help="A unit library: the design's letters name its unit types; instead of --unit. A design with a "
                   "sideways unit ('spatial') is measured on its surface only (a 3D scan).")
@click.option("--model-file", type=P.InputFile(), help=P.MODEL_FILE_HELP)
@click.option("--scan-unit", type=click.Choice(["mm", "cm", "m", "in"]),
              help="The unit of the scan's coordinates (default mm).")
@click.option("--scale", type=P.Real(0.0, 1e6, low_open=True),
              help="mm per unit of the scan (a photo's mm per pixel), instead of --scan-unit.")
@click.option("--fit-scale", is_flag=True, help="Fit a scale too (a photo whose scale is not known exactly).")
@click.option("--photo", type=P.InputFile(text=False), help="The photo the 2D trace was taken on (drawn under it).")
@click.option("--out", type=P.OutputDir(), help="Folder for correlation.json and correlation.png.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
def correlate(scan: str, design: str, pressure: float, fidelity: str, unit_file: str | None, scan_unit: str | None,
              scale: float | None, fit_scale: bool, photo: str | None, out: str | None, as_json: bool,
              model_file: str | None = None, library: str | None = None) -> None:
    """Align SCAN (STL, PLY, OBJ, OFF, XYZ, or a CSV of x,y traced on a photo) to the model's
    inflated shape by least squares, and report RMS and maximum distances on the surface,
    along the outline and along the centreline.
    """
    from pathlib import Path

    from pneumorph.correlation import correlate_design, read_scan
    from pneumorph.correlation.compare import SIDEWAYS_TRACE
    from pneumorph.errors import ScanError
    from pneumorph.geometry import parse_orientation
    from pneumorph.geometry.alphabet import parse_design
    from pneumorph.io import strict_json
    from pneumorph.models.factory import make_model

    units = P.library_option(library, unit_file) if library is not None else None
    with P.blame("--design"):
        parsed = parse_design(design, units) if units is not None else None
        orientation = parse_orientation(design) if parsed is None else parsed.text
    types = parsed.units(units) if parsed is not None and units is not None else ()
    planar = not any(u.layer_side for u in types)
    data = read_scan(scan, P.scan_unit(scan_unit, scale), scale)  # a bad scan is refused before the model is solved
    if not planar and data.dim != 3:
        raise ScanError(SIDEWAYS_TRACE)
    if photo is not None and data.dim != 2:
        raise click.BadParameter("a photo goes with a 2D trace (a CSV of x,y), not a 3D scan", param_hint="'--photo'")
    if photo is not None:
        from pneumorph.correlation.figures import check_photo

        with P.blame("--photo"):
            check_photo(photo)
    settings: dict = {"fidelity": fidelity, "pressure_kpa": pressure}
    if unit_file:
        P.unit_option(unit_file)
        settings["unit_file"] = unit_file
    if library is not None:
        settings["library"] = library
    settings = P.model_file_option(settings, model_file, {"fidelity": "fidelity", "pressure_kpa": "pressure"})
    fidelity = str(settings["fidelity"])
    if data.dim == 3 and fidelity == "2d":
        raise ScanError("a 3D scan needs the 3D model: leave out --model 2d" if model_file is None else
                        f"a 3D scan needs the 3D model, but --model-file {model_file} is of the 2D model: "
                        "give --model 3d")
    model = make_model(len(orientation), settings)
    result, summary = correlate_design(data, orientation, model, pressure, types=types, planar=planar,
                                       fit_scale=fit_scale, out=out, photo=photo, photo_scale=scale, source=str(scan),
                                       say=lambda text: click.echo(text, err=True))
    if as_json:
        click.echo(strict_json(summary))
        return
    t = result.alignment.transform
    click.echo(f"aligned {len(data.points)} scan points: rotation {t.angle_deg:.3f} deg, translation "
               f"{', '.join(f'{v:.3f}' for v in t.translation)} mm, scale {t.scale:.5g}; "
               f"ICP RMS {result.alignment.rms:.4g} mm")
    for name, m in (("surface", result.surface), ("outline", result.outline), ("centreline", result.centreline)):
        if m.count:
            click.echo(f"  {name:<10} RMS {m.rms:.4g} mm, max {m.max:.4g} mm ({m.count} points)")
    if out:
        click.echo(f"written to {Path(out)}/ (correlation.json, correlation.png)")

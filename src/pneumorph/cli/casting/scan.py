"""``pneumorph scan synth``: a synthetic scan of a design's cast, for trials of correlate and identify."""

from __future__ import annotations

import sys
from typing import Any

import click

from pneumorph.cli.options import params as P


@click.group("scan")
def scan() -> None:
    """Scans of cast actuators: a synthetic one of a design, for trying the loop design -> cast -> scan -> identify
    before a real cast (documentation page identify, docs/identify.md in the source)."""


def _change(text: str) -> tuple[str, float]:
    """``KEY=VALUE`` as a name and a number."""
    key, sep, value = text.partition("=")
    try:
        number = float(value)
    except ValueError:
        number = float("nan")
    if not sep or not key.strip() or number != number:
        raise click.BadParameter(f"{text!r}: give KEY=VALUE, e.g. wall=1.4 or body_shear_scale=0.9",
                                 param_hint="'--set'")
    return key.strip(), number


@scan.command("synth")
@click.argument("design", type=P.Text(1000))
@click.option("--out", "-o", "out", required=True, type=P.OutputFile((".xyz", ".csv")),
              help="The scan file: .xyz (3D points) or .csv (x,y: a 2D trace); its truth beside it, FILE.json.")
@click.option("--pressure", type=P.PRESSURE_KPA, default=45.0, show_default=True, help="The pressure scanned, kPa.")
@click.option("--model", "fidelity", type=click.Choice(["3d", "2d"]), default="3d", show_default=True,
              help="The model that stands in for the cast (3d: surface points; 2d: the outline, a trace).")
@click.option("--set", "changes", metavar="KEY=VALUE", type=P.Text(200), multiple=True,
              help="How the cast differs from the model (repeat): body_bulk_scale, body_shear_scale (factors on the "
                   "body silicone's moduli) or a unit field in mm (wall, layer, side_wall, ...).")
@click.option("--unit", "unit_file", type=P.InputFile(), help="Unit TOML file (default: the built-in unit).")
@click.option("--model-file", type=P.InputFile(), help=P.MODEL_FILE_HELP)
@click.option("--points", type=P.Count(10, 500_000), default=1500, show_default=True, help="Points in the scan.")
@click.option("--noise", type=P.Real(0.0, 10.0, unit="mm"), default=0.05, show_default=True,
              help="Standard deviation of the scanner's noise on every coordinate, mm.")
@click.option("--seed", type=P.Count(0, 2**32 - 1), default=0, show_default=True,
              help="Seed of the sample, the scanner's frame and the noise.")
@click.option("--json", "as_json", is_flag=True, help="Print the scan's truth as JSON.")
def synth(design: str, out: str, pressure: float, fidelity: str, changes: tuple[str, ...], unit_file: str | None,
          model_file: str | None, points: int, noise: float, seed: int, as_json: bool) -> None:
    """Write a synthetic scan of DESIGN's cast at --pressure: the model with the cast's --set changes, solved,
    sampled, moved into a scanner's frame and given noise; the truth (changes, motion, settings) goes beside it."""
    from pathlib import Path

    from pneumorph.cli.progress import solve_levels
    from pneumorph.correlation import model_shape
    from pneumorph.correlation.synthetic import ScanNoise, cast_settings, synthetic_scan, write_scan
    from pneumorph.geometry import parse_orientation
    from pneumorph.io import provenance, strict_json
    from pneumorph.io.files import all_or_nothing_file, write_json
    from pneumorph.models.factory import make_model

    with P.blame("DESIGN"):
        orientation = parse_orientation(design)
    if Path(out).suffix.lower() != (".xyz" if fidelity == "3d" else ".csv"):
        raise click.BadParameter(f"{out}: the {fidelity.upper()} model's scan is "
                                 f"{'an .xyz file of x y z' if fidelity == '3d' else 'a .csv trace of x,y'}",
                                 param_hint="'--out'")
    cast = dict(_change(c) for c in changes)
    settings: dict[str, Any] = {"fidelity": fidelity, "pressure_kpa": pressure}
    if unit_file:
        P.unit_option(unit_file)
        settings["unit_file"] = unit_file
    settings = P.model_file_option(settings, model_file, {"fidelity": "fidelity", "pressure_kpa": "pressure"})
    with P.blame("--set"):
        settings = cast_settings(settings, cast)
    noisy = ScanNoise(points=points, noise=noise, seed=seed)
    model = make_model(len(orientation), settings)
    changed = ", ".join(f"{k} = {v:g}" for k, v in cast.items()) if cast else "as modelled"
    solution = solve_levels(model, orientation, f"design {orientation}'s cast", f"synthetic scan of design "
                            f"{orientation}'s cast at {pressure:g} kPa ({fidelity} model, {changed})", where=out)
    scanned, motion = synthetic_scan(model_shape(solution), noisy)
    truth = {"design": orientation, "pressure_kpa": pressure, "model": fidelity, "changes": cast,
             "points": len(scanned.points), "noise_mm": noise, "seed": seed,
             "motion": {"rotation": motion.rotation.tolist(), "translation_mm": motion.translation.tolist()},
             "settings": settings, "provenance": provenance(command=" ".join(sys.argv), model=model.describe(),
                                                            fingerprint=model.fingerprint())}
    sidecar = Path(out).with_name(Path(out).name + ".json")
    with all_or_nothing_file(sidecar) as tmp:  # the scan and its truth together, or neither
        write_json(tmp, truth)
        write_scan(scanned, out)
    if as_json:
        click.echo(strict_json(truth))
        return
    click.echo(f"wrote {len(scanned.points)} points ({noise:g} mm noise, seed {seed}) to {out}; the truth to {sidecar}")

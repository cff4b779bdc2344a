"""``pneumorph simulate``: solve the pressure ramp of one design."""

from __future__ import annotations

import sys
from typing import Any

import click

from pneumorph.checks import MAX_VOLUME_CHANGE, MIN_VOLUME_CHANGE, check_volume_steps
from pneumorph.cli.options import params as P
from pneumorph.cli.progress import reporter, solve_levels


@click.command("simulate")
@click.option("--orientation", "-o", required=True, metavar="DIGITS", type=P.Text(max_length=1000),
              help="The design, base first: one digit per unit, 1 = unit turned 180 degrees (e.g. 010011); "
                   "over a --library, one letter per unit, upper case = turned (e.g. aRRa).")
@click.option("--pressure", type=P.PRESSURE_KPA, default=45.0, show_default=True, help="Final pressure in kPa.")
@click.option("--increments", type=P.INCREMENTS, default=10, show_default=True, help="Reported pressure levels.")
@click.option("--volume-change", type=P.Real(MIN_VOLUME_CHANGE, MAX_VOLUME_CHANGE), default=None,
              help="Drive the cavities' volume instead of the pressure, to this relative change V/V0 - 1 in "
                   "--increments equal steps: the pressure is an output and may pass a maximum (a wall that "
                   "balloons); --pressure then only scales the solver's load factor.")
@click.option("--model", "fidelity", type=click.Choice(["2d", "3d"]), default="2d", show_default=True,
              help="2D reduced-order (plane strain with filler) or 3D model.")
@click.option("--unit", "unit_file", type=P.InputFile(),
              help="TOML file with a [unit] table (dimensions in mm, materials, element size).")
@click.option("--model-file", type=P.InputFile(), help=P.MODEL_FILE_HELP)
@click.option("--library", metavar="builtin|spatial|modes|FILE", type=P.Text(),
              help="A unit library ('builtin', 'spatial' (sideways units, --model 3d), 'modes' (bimodal and "
                   "low-bending units) or a library TOML file; "
                   "documentation page unit-library, "
                   "docs/unit-library.md in the source): the design's letters name its unit types; instead of --unit.")
@click.option("--gravity", type=click.Choice(["none", "hanging", "horizontal"]), default="none", show_default=True,
              help="Weight of the silicones, applied before the pressure: hanging from the clamped base "
                   "(appendix A.2.2) or lying horizontal with gravity across the height.")
@click.option("--obstacle", "obstacles", multiple=True, metavar="KIND:KEY=V;...", type=P.Text(max_length=1000),
              help="A rigid obstacle against the outer surface, mm (repeatable): "
                   "plane:point=X,Y;normal=NX,NY (the actuator on the normal's side), cylinder:centre=X,Y;radius=R "
                   "(a circle in 2D; 3D: ;axis=AX,AY,AZ), sphere:centre=...;radius=R; on=end touches the free end "
                   "face only, friction=MU adds Coulomb friction (MU at most 10). Each level's force on it and the "
                   "base reaction go to the JSON and the response.")
@click.option("--blocked", is_flag=True,
              help="Add a wall against the free end, normal to the free tip's motion at the first level (one more "
                   "solve of that level) at its start position: the blocked force over the ramp.")
@click.option("--out", type=P.OutputDir(), help="Folder for response (NPZ+JSON), VTK and PNG files.")
@click.option("--json", "as_json", is_flag=True, help="Print tip, curl and unit centres of every level as JSON.")
def simulate(
    orientation: str,
    pressure: float,
    increments: int,
    fidelity: str,
    unit_file: str | None,
    library: str | None,
    gravity: str,
    out: str | None,
    as_json: bool,
    model_file: str | None = None,
    volume_change: float | None = None,
    obstacles: tuple[str, ...] = (),
    blocked: bool = False,
) -> None:
    """Inflate one actuator design and report its shape at every pressure level."""
    from pneumorph.io import provenance
    from pneumorph.models import make_model

    design = _check_design(orientation, library, unit_file)
    # the factory, as `design` and the API use it: the model class's tuned ramp, the same fingerprint
    settings: dict = {"fidelity": fidelity, "pressure_kpa": pressure, "increments": increments, "gravity": gravity}
    if unit_file is not None:
        settings["unit_file"] = unit_file
    if library is not None:
        settings["library"] = library
    if volume_change is not None:
        settings["volume_change"] = volume_change
    if obstacles:
        settings["obstacle"] = _obstacles(obstacles, fidelity)
    settings = P.model_file_option(settings, model_file, {"fidelity": "fidelity", "pressure_kpa": "pressure",
                                                          "increments": "increments", "gravity": "gravity",
                                                          "obstacle": "obstacles", "volume_change": "volume_change"})
    steps = settings.get("increments")
    if volume_change is not None and isinstance(steps, int):  # a model file's value: the factory names its key
        check_volume_steps(volume_change, steps, ("--volume-change", "--increments"), click.UsageError)
    fidelity = str(settings["fidelity"])
    model = make_model(len(design), settings)
    model = _with_obstacles(model, design, bool(obstacles), blocked)
    weight = "" if gravity == "none" else f", {gravity} under gravity"
    volume = model.ramp.volume
    load = f"{pressure:g} kPa" if volume is None else f"the cavities' volume to {1 + volume:g} V0"
    solution = solve_levels(model, design, f"design {design}", f"simulating design {design} ({fidelity} model, "
                            f"{len(design)} units, {load}{weight})", where=out)
    meta = provenance(command=" ".join(sys.argv), model=model.describe(), fingerprint=model.fingerprint())
    if out:
        _write(out, solution, meta)
    if as_json:
        _print_json(design, fidelity, solution.response)
    else:
        _print_table(solution.response, out)


def _obstacles(texts: tuple[str, ...], fidelity: str) -> list[dict[str, Any]]:
    """The ``--obstacle`` tables, checked (a usage error naming the option)."""
    from pneumorph.models.fe.obstacles import check_obstacles, parse_obstacle

    with P.blame("--obstacle"):
        tables = [parse_obstacle(text) for text in texts]
        check_obstacles(tables, 3 if fidelity == "3d" else 2, where="obstacle")
    return tables


def _with_obstacles(model: Any, design: str, typed: bool, blocked: bool) -> Any:
    """``model`` with the ``--blocked`` wall added; an obstacle that starts inside the actuator refused before any
    solve (naming ``--obstacle`` when typed)."""
    from contextlib import nullcontext

    from pneumorph.models.fe.obstacles import blocked_obstacle, check_reach

    with P.blame("--obstacle") if typed else nullcontext():
        check_reach(model, design)
    if not blocked:
        return model
    wall = blocked_obstacle(model, design)
    click.echo(f"blocking wall: plane through {_numbers(wall['point'])} mm, normal {_numbers(wall['normal'])}, "
               "against the free end", err=True)
    return model.variant(obstacles=[*model.obstacles, wall])


def _numbers(values: Any) -> str:
    return "(" + ", ".join(f"{v:.4g}" for v in values) + ")"


def _check_design(orientation: str, library: str | None, unit_file: str | None) -> str:
    """The design's orientation string, read over --library's letters or as digits; --unit's file checked."""
    from pneumorph.geometry import parse_orientation

    if library is not None:
        from pneumorph.geometry.alphabet import parse_design

        units = P.library_option(library, unit_file)
        with P.blame("--orientation"):
            design = parse_design(orientation, units).text
    else:
        with P.blame("--orientation"):
            design = parse_orientation(orientation)
    if unit_file is not None:
        from pneumorph.geometry.unit import UnitSpec

        with P.blame("--unit"):
            UnitSpec.from_toml(unit_file)
    return design


def _write(out: str, solution: Any, meta: dict) -> None:
    """The response, the VTK series, the shape figure and the provenance, all or nothing."""
    from pneumorph.io import write_vtk_series
    from pneumorph.io.files import all_or_nothing, write_json

    resp = solution.response
    with all_or_nothing(out, say=reporter(), what="the response, the VTK series, the shape figure and the "
                        "provenance") as folder:  # stopped while writing (Ctrl-C, a full disk): no partial output
        resp.save(folder / "response")
        write_vtk_series(solution, folder / "vtk", meta=meta)
        from pneumorph.plot.shape import plot_shape

        plot_shape(solution, folder / "shape.png", levels=sorted({resp.n_levels // 2 - 1, resp.n_levels - 1}))
        write_json(folder / "provenance.json", meta)


def _print_json(design: str, fidelity: str, resp: Any) -> None:
    """Tip, curl and unit centres of every level as JSON."""
    from pneumorph.io.files import strict_json

    twist = resp.twist
    levels = [
        {
            "pressure_kpa": float(p * 1e3),
            "tip_mm": resp.tip[k].tolist(),
            "curl_deg": float(resp.curl[k]),
            **({} if twist is None else {"twist_deg": float(twist[k])}),  # the full width: the end face's twist
            "unit_centres_mm": resp.centres[k].tolist(),
        }
        for k, p in enumerate(resp.pressures)
    ]
    click.echo(strict_json({"orientation": design, "model": fidelity, "converged": resp.converged,
                            "levels": levels, "metadata": resp.metadata}))


def _print_table(resp: Any, out: str | None) -> None:
    """Tip and curl of every level as a table, the solver's effort, and where the files went."""
    from pathlib import Path

    space = resp.axes == 3  # the full width: the tip's z, and the end face's twist where the response has its frame
    twist = resp.twist
    click.echo(f"{'p [kPa]':>8} {'tip x [mm]':>11} {'tip y [mm]':>11} "
               + (f"{'tip z [mm]':>11} " if space else "") + f"{'curl [deg]':>11}"
               + (f" {'twist [deg]':>12}" if twist is not None else ""))
    for k, p in enumerate(resp.pressures):
        z = f"{resp.tip[k, 2]:11.3f} " if space else ""
        tw = f" {twist[k]:12.3f}" if twist is not None else ""
        click.echo(f"{p * 1e3:8.3f} {resp.tip[k, 0]:11.3f} {resp.tip[k, 1]:11.3f} {z}{resp.curl[k]:11.2f}{tw}")
    m = resp.metadata
    if "contact" in m:
        _print_contact(m["contact"])
    click.echo(f"{m['newton_iterations']} Newton iterations, {m['cutbacks']} cut-backs, {m['dofs']} dofs, "
               f"{m['wall_time_s']:.2f} s")
    if out:
        click.echo(f"written to {Path(out)}/ (response.npz/.json, vtk/actuator.pvd, shape.png, provenance.json)")
    else:
        click.echo("nothing written: --out DIR keeps the response, the VTK series and the shape figure")


def _print_contact(contact: dict) -> None:
    """Each level's force on every obstacle, its contact and the base reaction."""
    import numpy as np

    n = len(contact["obstacles"])
    key = next((k for k in ("contact_length_mm", "contact_area_mm2")
                if contact["levels"] and k in contact["levels"][0]["obstacles"][0]), "contact_length_mm")
    unit = "mm" if key.endswith("_mm") else "mm^2"
    click.echo(f"{'p [kPa]':>8} " + " ".join(f"{f'F{i + 1} [N]':>10} {f'c{i + 1} [{unit}]':>11}" for i in range(n))
               + f" {'base reaction [N]':>18}")
    for level in contact["levels"]:
        cells = " ".join(f"{o['force_magnitude_n']:10.4f} {o[key]:11.3f}" for o in level["obstacles"])
        click.echo(f"{level['pressure_kpa']:8.3f} {cells} {np.linalg.norm(level['base_reaction_n']):18.4f}")

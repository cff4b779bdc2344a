"""``pneumorph export``: a design's parts as STL, and the casting mould of its body."""

from __future__ import annotations

import contextlib
from typing import Any

import click

from pneumorph.cli.options import params as P

_MOULD_ONLY = ("clearance", "draft")
_DECK_ONLY = ("pressure",)


@click.command("export")
@click.argument("design", type=P.Text(1000))
@click.option("--stl", "stl_dir", type=P.OutputDir(),
              help="Folder for the parts' STL files (mm): body, layer pieces, base block.")
@click.option("--inp", "inp_file", type=P.OutputFile((".inp",)),
              help="The 3D model as a CalculiX/Abaqus input deck (mm, Pa; documentation page manufacturing, "
                   "docs/manufacturing.md in the source).")
@click.option("--pressure", type=P.PRESSURE_KPA, default=45.0, show_default=True,
              help="Deck: the final pressure of the ramp, kPa (levels as the 3D model's).")
@click.option("--mould", "with_mould", is_flag=True,
              help="Also the body's casting mould: its parts' STL and an exploded drawing in DIR/mould/.")
@click.option("--unit", "unit_file", type=P.InputFile(), help="Unit TOML file (default: the built-in unit).")
@click.option("--library", metavar="builtin|spatial|modes|FILE", type=P.Text(),
              help="A unit library ('builtin', 'spatial' (sideways units), 'modes' or a library TOML file): DESIGN's "
                   "letters name its unit types; instead of --unit. Its parts, --mould and --inp as for one unit type.")
@click.option("--clearance", type=P.Real(0.0, 5.0, unit="mm"), default=0.2, show_default=True,
              help="Mould: gap between mating printed parts (pins, core tenons), mm.")
@click.option("--draft", type=P.Real(0.0, 45.0, high_open=True, unit="degrees"), default=0.0, show_default=True,
              help="Mould: taper of the cavity cores, degrees (0: exact cavities).")
@click.option("--model-file", type=P.InputFile(), help=P.MODEL_FILE_HELP + " Here: its unit, and the deck's materials.")
@click.option("--json", "as_json", is_flag=True, help="Print the files and volumes as JSON.")
@click.pass_context
def export(ctx: click.Context, design: str, stl_dir: str | None, inp_file: str | None, pressure: float,
           with_mould: bool, unit_file: str | None, clearance: float, draft: float, as_json: bool,
           model_file: str | None = None, library: str | None = None) -> None:
    """Write DESIGN's parts (the Mold Star body with its cavities, the Smooth-Sil layer
    pieces, the base block) as watertight STL files, with --mould the printable casting
    mould of the body, and with --inp the 3D model as a CalculiX/Abaqus deck
    (documentation page manufacturing, docs/manufacturing.md in the source).
    """
    from pathlib import Path

    from pneumorph.export import BaseBlock, check_materials
    from pneumorph.export.parts import check_buildable
    from pneumorph.geometry.alphabet import parse_design
    from pneumorph.geometry.library import UnitLibrary
    from pneumorph.io import strict_json

    # everything is checked before anything is built or written; the design is parsed once, here
    _check_request(ctx, stl_dir, inp_file, with_mould)
    units = P.library_option(library, unit_file) if library is not None else None
    with P.blame("DESIGN"):
        parsed = parse_design(design, units if units is not None else UnitLibrary.single())
    orientation = parsed.text
    settings = {"fidelity": "3d", "pressure_kpa": pressure, **({"unit_file": unit_file} if unit_file else {}),
                **({"library": library} if library else {})}
    settings = P.model_file_option(settings, model_file, {"pressure_kpa": "pressure"})
    if units is not None:
        with P.blame("--library"):
            check_buildable(units, parsed)
            check_materials(units, BaseBlock(), parsed)
    unit = units if units is not None else _unit(settings, unit_file, model_file)
    folder = Path(stl_dir) if stl_dir is not None else Path()
    mould_spec = _mould_spec(unit, parsed, clearance, draft, folder) if with_mould else None
    model = None
    if inp_file is not None:
        from pneumorph.models.factory import make_model

        model = make_model(len(orientation), settings)
    summary: dict = {"design": orientation, "units": len(orientation)}
    block = BaseBlock()
    parts, paths, mould = _write(parsed, unit, block, model, stl_dir, inp_file, mould_spec, summary)
    if stl_dir is None:
        if as_json:
            click.echo(strict_json(summary))
        else:
            click.echo(f"wrote the CalculiX deck of design {orientation} at {pressure:g} kPa to {inp_file}")
        return
    describe = _parts_summary(summary, unit, parsed, block, parts, paths, mould, mould_spec, folder)
    if as_json:
        click.echo(strict_json(summary))
        return
    n, length = len(orientation), summary["length_mm"]
    kind = "library" if library else "unit"
    click.echo(f"design {orientation}: {n} unit{'s' if n > 1 else ''}, {length:g} mm long ({kind} {unit.name!r})")
    if inp_file is not None:
        click.echo(f"wrote the CalculiX deck at {pressure:g} kPa to {inp_file}")
    click.echo(f"wrote {len(paths)} STL files (mm) to {folder}/:")
    width = max(len(p.name) for p in paths)
    for path, (name, mesh) in zip(paths, parts.items(), strict=False):
        click.echo(f"  {path.name:<{width}}  {float(mesh.volume):10.2f} mm^3  {describe[name]}")
    if mould is not None:
        _print_mould(mould, mould_spec, folder)


def _check_request(ctx: click.Context, stl_dir: str | None, inp_file: str | None, with_mould: bool) -> None:
    """Refuse what would write nothing, collide, or ignore an option (before anything is built)."""
    from pathlib import Path

    if stl_dir is None and inp_file is None:
        raise click.UsageError("nothing to export: give --stl DIR (the parts' STL files) and/or --inp FILE "
                               "(a CalculiX deck)")
    if with_mould and stl_dir is None:
        raise click.UsageError("--mould writes into the --stl folder: give --stl DIR")
    if stl_dir is not None and inp_file is not None:
        deck_path, stl_path = Path(inp_file).resolve(), Path(stl_dir).resolve()
        if deck_path == stl_path or deck_path in stl_path.parents:
            raise click.UsageError(f"--inp {inp_file} and the --stl folder {stl_dir} collide: the deck would be "
                                   "written where the STL folder goes; give them different paths")
    if inp_file is None and ctx.get_parameter_source("pressure") is not click.core.ParameterSource.DEFAULT:
        raise click.UsageError("--pressure applies to the deck only: add --inp FILE")
    if not with_mould:
        given = [f"--{k}" for k in _MOULD_ONLY
                 if ctx.get_parameter_source(k) is not click.core.ParameterSource.DEFAULT]
        if given:
            raise click.UsageError(f"{' and '.join(given)} {'apply' if len(given) > 1 else 'applies'} to the "
                                   "mould only: add --mould")


def _unit(settings: dict, unit_file: str | None, model_file: str | None) -> Any:
    """The unit of the parts: --unit's, the model file's, or the built-in one; its materials checked."""
    from pneumorph.export import check_materials
    from pneumorph.export.parts import check_buildable
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.models.factory import unit_or_library

    with P.blame("--unit" if model_file is None or unit_file is not None else "--model-file"):
        if unit_file:
            unit = UnitSpec.from_toml(unit_file)
        else:  # the model file's unit, read as the model factory reads it (a library's file: the built-in unit)
            unit = unit_or_library(settings)[0] or UnitSpec()
        check_materials(unit)  # the parts' materials, before anything is built
        check_buildable(unit)
    return unit


def _mould_spec(unit: Any, orientation: Any, clearance: float, draft: float, folder: Any) -> Any:
    """The mould's settings, each checked naming its option."""
    from pneumorph.export import MouldSpec
    from pneumorph.io import check_writable_dir

    with P.blame("DESIGN"):  # what the design asks of any mould: a face to pour through, a flat side sheet
        MouldSpec().check_design(unit, orientation)
    with P.blame("--clearance"):
        MouldSpec(clearance=clearance).check(unit, orientation)
    with P.blame("--draft"):
        MouldSpec(draft=draft).check(unit, orientation)
    with P.blame("--unit"):
        spec = MouldSpec(clearance=clearance, draft=draft)
        spec.check(unit, orientation)
    with P.blame("--stl"):
        check_writable_dir(folder / "mould", "--stl")
    return spec


def _write(orientation: Any, unit: Any, block: Any, model: Any, stl_dir: str | None, inp_file: str | None,
           mould_spec: Any, summary: dict) -> tuple[dict, list, Any]:
    """The deck, the parts and the mould written all or nothing (a failure or Ctrl-C while writing leaves no
    output); the parts, their paths and the mould."""
    from pathlib import Path

    from pneumorph.cli.progress import reporter
    from pneumorph.export import actuator_parts, casting_mould, plot_mould, write_stl
    from pneumorph.io.files import all_or_nothing, all_or_nothing_file

    parts: dict = {}
    paths: list = []
    mould = None
    with contextlib.ExitStack() as outputs:
        folder = Path(stl_dir) if stl_dir is not None else Path()
        say = reporter()  # the parts' booleans and the mould's checks take seconds: said before they start
        if stl_dir is not None:
            what = "the parts' STL files" + (", the casting mould and its drawing" if mould_spec is not None else "")
            outputs.enter_context(all_or_nothing(folder, say=say, what=what))
        if model is not None:
            from pneumorph.export import write_calculix_deck

            assert inp_file is not None
            # in place once the STL files are written too
            deck = outputs.enter_context(all_or_nothing_file(inp_file, say=say, what="the CalculiX deck"))
            write_calculix_deck(model, orientation, deck)
            summary["deck"] = {"file": str(Path(inp_file)), "pressure_kpa": round(float(model.ramp.pressure) * 1e3, 9),
                               "levels": int(model.ramp.steps.increments), "fingerprint": model.fingerprint()}
        if stl_dir is not None:
            parts = actuator_parts(unit, orientation, block)
            paths = write_stl(parts, folder)
            if mould_spec is not None:
                mould = casting_mould(unit, orientation, mould_spec)
                summary["mould_files"] = [str(p) for p in write_stl(mould.parts, folder / "mould")]
                plot_mould(mould, folder / "mould" / "mould.png")
    return parts, paths, mould


def _parts_summary(summary: dict, unit: Any, orientation: Any, block: Any, parts: dict, paths: list, mould: Any,
                   mould_spec: Any, folder: Any) -> dict:
    """The parts (files, volumes, layer pieces) and the mould into ``summary``; each part in words."""
    from pneumorph.export import layer_pieces
    from pneumorph.geometry.alphabet import library_design
    from pneumorph.geometry.assembly import unit_starts

    library, parsed = library_design(unit, orientation)
    types = parsed.units(library)
    ref, pieces = library[library.default], layer_pieces(unit, orientation)
    k = sum(not u.solid for u in types)
    solid = f"solid unit{'s' if len(set(types)) > 1 else ''}"
    cavities = f"{k} cavit{'y' if k == 1 else 'ies'}" if k else f"no cavities ({solid})"
    describe = {"body": f"{ref.body_material} body, {cavities}",
                "base_block": f"base block {block.length:g} x {ref.height + 2 * block.margin:g} x "
                              f"{ref.width + 2 * block.margin:g} mm, {block.material}"}
    layer_names = [k for k in parts if k.startswith("layer_")]
    for name, p in zip(layer_names, pieces, strict=False):
        units = f"unit {p.first + 1}" if p.first == p.last else f"units {p.first + 1}-{p.last + 1}"
        describe[name] = f"{p.material} strip, {units}, {p.side}, cut {p.length:g} mm"
    summary.update({
        "length_mm": float(unit_starts(types)[-1]) + ref.end_cap,
        "unit": unit.name,
        "files": [str(p) for p in paths],
        "volumes_mm3": {name: float(mesh.volume) for name, mesh in parts.items()},
        "layer_pieces": [{"name": name, "first_unit": p.first + 1, "last_unit": p.last + 1, "side": p.side,
                          "length_mm": p.length} for name, p in zip(layer_names, pieces, strict=False)],
    })
    if mould is not None:
        summary["mould"] = {
            "clearance_mm": mould_spec.clearance,
            "draft_deg": mould_spec.draft,
            "files": summary.pop("mould_files"),
            "drawing": str(folder / "mould" / "mould.png"),
            "volumes_mm3": {name: float(mesh.volume) for name, mesh in mould.parts.items()},
            "cast_mm3": {name: float(mesh.volume) for name, mesh in mould.cast.items()},
            "check": mould.check.to_dict(),
        }
    return describe


def _print_mould(mould: Any, mould_spec: Any, folder: Any) -> None:
    """The mould's parts and its checks, in words."""
    c = mould.check
    click.echo(f"mould: {len(mould.parts)} parts (clearance {mould_spec.clearance:g} mm, draft "
               f"{mould_spec.draft:g} deg) in {folder / 'mould'}/, drawing mould.png")
    click.echo(f"  cast: open body {float(mould.cast['open_body'].volume):.2f} mm^3 + side sheet "
               f"{float(mould.cast['side_sheet'].volume):.2f} mm^3, glued = the body "
               f"(difference {c.reassembly_error:.2g} mm^3; the draft adds {c.cavity_volume_change:.4g} mm^3)")
    click.echo(f"  checked: all parts watertight, largest overlap {c.max_overlap:.2g} mm^3 "
               f"({c.overlap_pairs} pairs), empty space = cast + pour/vent holes + clearance gaps "
               f"(difference {c.cavity_error:.2g} mm^3), gaps {c.gap_distance:.3g} mm from the cast")

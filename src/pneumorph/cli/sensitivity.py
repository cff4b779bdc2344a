"""``pneumorph sensitivity``: the studies of appendices D and E for any design and model."""

from __future__ import annotations

import sys
from collections.abc import Callable
from functools import partial
from typing import Any

import click

from pneumorph.cli.options import params as P
from pneumorph.cli.options.execution import (
    check_options,
    cluster_line,
    cluster_report,
    execution_options,
    open_evaluator,
)
from pneumorph.cli.progress import plan_solves, reporter


def _common(command: Callable[..., Any], models: tuple[str, ...] = ("2d", "3d")) -> Callable[..., Any]:
    """The options every study shares: the design, the model (of ``models``), the executor, the outputs."""
    options = [
        click.option("--design", metavar="DIGITS", type=P.Text(max_length=1000),
                     help="The design, base first (default: all units aligned, as appendix E)."),
        click.option("--model", "fidelity", type=click.Choice(models), default="3d", show_default=True,
                     help="The FE model." + ("" if len(models) > 1 else " This study varies options of the 3D "
                                             "model only.")),
        click.option("--units", "n_units", type=P.UNITS, default=15, show_default=True,
                     help="Units of the default design (ignored with --design)."),
        click.option("--pressure", type=P.PRESSURE_KPA, default=45.0, show_default=True, help="Final pressure, kPa."),
        click.option("--unit", "unit_file", type=P.InputFile(), help="Unit TOML file (default: the built-in unit)."),
        click.option("--model-file", type=P.InputFile(), help=P.MODEL_FILE_HELP),
        click.option("--cache", metavar="FILE", type=P.CacheFile(),
                     help="Evaluation cache (default ~/.cache/pneumorph/evaluations.sqlite): a rerun resumes."),
        click.option("--out", type=P.OutputDir(), help="Folder for study.json and study.png."),
        click.option("--json", "as_json", is_flag=True, help="Print the results as JSON."),
    ]
    for option in reversed(options):
        command = option(command)
    return execution_options(what="cases")(command)


@click.group("sensitivity")
def sensitivity() -> None:
    """How far a design's inflated shape moves with the model's simplifications, mould
    tolerances and material data (appendices D and E; documentation page sensitivity, docs/sensitivity.md in the
    source)."""


def _run(name: str, common: dict[str, Any], **options: Any) -> None:
    from pathlib import Path

    from pneumorph.geometry import parse_orientation
    from pneumorph.io import provenance, strict_json
    from pneumorph.io.files import all_or_nothing, write_json
    from pneumorph.models import make_model
    from pneumorph.sensitivity import BUILDERS, run_study

    check_options(common["executor"], common["workers"], common["scheduler"])
    design, n = common["design"], common["n_units"]
    if design is not None:
        with P.blame("--design"):
            n = len(parse_orientation(design))
    settings: dict[str, Any] = {"fidelity": common["fidelity"], "pressure_kpa": common["pressure"]}
    if common["unit_file"]:
        P.unit_option(common["unit_file"])
        settings["unit_file"] = common["unit_file"]
    settings = _with_model_file(settings, common["model_file"])
    common["fidelity"], common["pressure"] = settings["fidelity"], settings["pressure_kpa"]
    model = make_model(n, settings)
    if options.get("base") is not None:
        _check_base_block(model, options["base"], common)
    study = BUILDERS[name](model, design, **options)  # every variant is built (and checked) before any solve
    total = len(study.cases) + 1
    evaluator = open_evaluator(common["executor"], common["workers"], common["scheduler"], common["cache"])

    def progress(done: int, total: int, r: Any) -> None:
        state = "cached" if r.outcome.cached else ("solved" if r.outcome.ok else f"failed: {r.outcome.failure}")
        curl = f", curl {r.outcome.response.curl[-1]:.2f} deg" if r.outcome.ok else ""
        lines.count(done, f"{r.case.label}: {state}{curl}", always=not r.outcome.ok)

    with reporter() as lines:
        plan_solves(lines, f"{name} study", total, model, common["executor"], common["workers"], common["out"],
                    title=f"{name} study of design {study.design} ({common['fidelity']} model, {model.n_units} "
                    f"units, {common['pressure']:g} kPa)")
        try:
            result = run_study(study, evaluator, on_case=progress)
        finally:
            evaluator.close()
    if (line := cluster_line(evaluator)) is not None:
        click.echo(line, err=True)
    data = result.to_dict()
    if (cluster := cluster_report(evaluator)) is not None:
        data["cluster"] = cluster
    data["provenance"] = provenance(command=" ".join(sys.argv), model=model.describe(), fingerprint=model.fingerprint())
    if common["out"]:
        from pneumorph.plot.sensitivity import plot_study

        # stopped while writing (Ctrl-C, a full disk): no partial output
        with all_or_nothing(common["out"], say=reporter(), what="study.json and study.png") as folder:
            write_json(folder / "study.json", data)
            plot_study(result, folder / "study.png")
    if common["as_json"]:
        click.echo(strict_json(data))
        return
    _print(result)
    if name == "tolerances" and model.dim == 2:
        click.echo("note: the 2D model is a section along the length; the side walls are not in it, so the "
                   "side_wall rows equal the reference (use --model 3d for them)")
    if common["out"]:
        click.echo(f"written to {Path(common['out'])}/ (study.json, study.png)")


def _with_model_file(settings: dict[str, Any], model_file: str | None) -> dict[str, Any]:
    """``settings`` with ``--model-file``'s under the options typed; a fidelity the study's ``--model`` does not
    offer refused, naming both."""
    merged = P.model_file_option(settings, model_file, {"fidelity": "fidelity", "pressure_kpa": "pressure"})
    offered = click.get_current_context().command.params
    choices = next((p.type.choices for p in offered if p.name == "fidelity" and isinstance(p.type, click.Choice)), ())
    if model_file is not None and merged["fidelity"] not in choices:
        raise click.UsageError(f"--model-file {model_file} is of the {merged['fidelity']} model, which this study "
                               f"does not vary; give --model {'/'.join(choices)}")
    return merged


def _check_base_block(model: Any, base: Any, common: dict[str, Any]) -> None:
    """Refuse a base block whose variants' mesh would not fit in the memory available, before any mesh is built.

    The model's own mesh was counted by ``make_model``; the base block's cases (two, solved at once by a pool)
    are longer by the block.
    """
    import os

    from pneumorph.geometry.meshsize import available_memory, check_mesh

    parallel = 1 if common["executor"] == "serial" else min(2, common["workers"] or os.cpu_count() or 1)
    with P.blame("--base-length"):
        check_mesh(model.unit, model.n_units, model.dim, getattr(model, "half", True), memory=available_memory(),
                   parallel=parallel, base=base,
                   advice="give a shorter --base-length or a unit with a larger element_size")


def _print(result: Any) -> None:
    ref = result.reference
    level = result.study.level
    r = ref.outcome.response
    if ref.outcome.ok:
        click.echo(f"reference ({ref.case.label}): curl {r.curl[level]:.2f} deg, tip ({r.tip[level, 0]:.2f}, "
                   f"{r.tip[level, 1]:.2f}) mm at {r.pressures[level] * 1e3:g} kPa")
    else:
        click.echo(f"reference ({ref.case.label}) failed: {ref.outcome.failure}")
    click.echo(f"{'case':<28} {'distance [mm]':>13} {'X [%]':>7} {'Y [%]':>7} {'tip [mm]':>9} {'curl [deg]':>10}")
    for c in result.cases:
        if c.difference is None:
            click.echo(f"{c.case.label:<28} failed: {c.outcome.failure}")
            if c.matching_kpa is not None:
                click.echo(f"{'':<28} closest to the reference shape at {c.matching_kpa:.1f} kPa before it failed "
                           f"(max distance {c.matching_mm:.3f} mm)")
            continue
        d = c.difference
        click.echo(f"{c.case.label:<28} {d.distance_mm:13.3f} {d.x_error_pct:7.2f} {d.y_error_pct:7.2f} "
                   f"{d.tip_mm:9.3f} {d.curl_deg:10.2f}")
        if c.matching_kpa is not None:
            click.echo(f"{'':<28} closest to the reference shape at {c.matching_kpa:.1f} kPa "
                       f"(max distance {c.matching_mm:.3f} mm)")
    s = result.summary()
    if "curl_min_deg" in s:
        fields = list(s["minimum_curl_inputs"])
        click.echo(f"curl {s['curl_min_deg']:.2f} .. {s['curl_max_deg']:.2f} deg (mean {s['curl_mean_deg']:.2f}, "
                   f"sd {s['curl_std_deg']:.2f}); tip spread {s['tip_spread_mm']:.2f} mm; distance mean "
                   f"{s['distance_mean_mm']:.3f}, 95th percentile {s['distance_p95_mm']:.3f}, worst "
                   f"{s['worst_distance_mm']:.3f} mm")
        click.echo(f"{'':<16}" + "".join(f"{f:>12}" for f in fields))
        for key, label in (("minimum_curl_inputs", "minimum curl"), ("maximum_curl_inputs", "maximum curl")):
            click.echo(f"{label:<16}" + "".join(f"{s[key][f]:12.3f}" for f in fields))


def _common_3d(command: Callable[..., Any]) -> Callable[..., Any]:
    """:func:`_common` for a study whose variants exist in the 3D model only."""
    return _common(command, models=("3d",))


@sensitivity.command("simplifications")
@_common_3d
@click.option("--passage", type=P.Real(0.0, 100.0, low_open=True, unit="mm"), default=1.5, show_default=True,
              help="Diameter of the air passages between cavities (section 6.4.1), mm.")
@click.option("--base-length", type=P.POSITIVE_MM, default=10.0, show_default=True,
              help="Length of the silicone base block held by the clamp, mm.")
@click.option("--change", type=P.Real(-100.0, 100.0, unit="degC"), default=10.0, show_default=True,
              help="Temperature change, degC.")
def simplifications_cmd(passage: float, base_length: float, change: float, **common: Any) -> None:
    """Appendix D: passages between cavities, the base block, a temperature change, all three."""
    from pneumorph.geometry.features import BaseBlock, check_passage
    from pneumorph.geometry.unit import UnitSpec

    with P.blame("--unit"):
        unit = UnitSpec.from_toml(common["unit_file"]) if common["unit_file"] else UnitSpec()
    with P.blame("--passage"):
        check_passage(unit, passage)
    _run("simplifications", common, passage=passage, base=BaseBlock(length=base_length), temperature_change=change)


@sensitivity.command("tolerances")
@_common
@click.option("--tolerance", type=P.Real(0.0, 1.0, low_open=True, unit="mm"), default=0.1, show_default=True,
              help="Mould tolerance on the side walls, the Mold Star wall and the Smooth-Sil layer, +- mm "
                   "(0.1: FDM-printed moulds; 0.02: machined).")
@click.option("--samples", type=P.Count(0, 10_000), default=30, show_default=True,
              help="Random combinations besides the one-at-a-time extremes.")
@click.option("--seed", type=P.SEED, default=0, show_default=True, help="Seed of the random combinations.")
@click.option("--corners", is_flag=True, help="Also every combination of the thicknesses at their ends (8 cases).")
def tolerances_cmd(tolerance: float, samples: int, seed: int, corners: bool, **common: Any) -> None:
    """Appendix E.2: mould tolerances (Table E.1, Figs E.5-E.6)."""
    from pneumorph.sensitivity import Tolerance

    _run("tolerances", common, tolerance=Tolerance(tolerance), samples=samples, seed=seed, corners=corners)


@sensitivity.command("bulk-modulus")
@_common
@click.option("--factor", "factors", type=P.Real(0.0, 100.0, low_open=True), multiple=True,
              help="Factor on the body silicone's bulk modulus (repeat; default 1.05 and 1.10).")
def bulk_modulus_cmd(factors: tuple[float, ...], **common: Any) -> None:
    """Appendix E.1.2: the body silicone's bulk modulus raised."""
    _run("bulk-modulus", common, factors=factors or (1.05, 1.10))


@sensitivity.command("calibration")
@_common
@click.option("--reach", type=P.Real(1.0, 10.0), default=2.0, show_default=True,
              help="The tension-only model is ramped to this multiple of the pressure.")
def calibration_cmd(reach: float, **common: Any) -> None:
    """Appendix E.1.1: the body silicone calibrated on tension only, and the pressure that
    brings it to the reference shape."""
    _run("calibration", common, reach=reach)


@sensitivity.command("temperature")
@_common_3d
@click.option("--change", "changes", type=P.Real(-100.0, 100.0, unit="degC"), multiple=True,
              help="Uniform temperature change, degC (repeat; default 10).")
def temperature_cmd(changes: tuple[float, ...], **common: Any) -> None:
    """Appendix D.3: a uniform temperature change from the casting temperature."""
    _run("temperature", common, changes=changes or (10.0,))


@sensitivity.command("mesh")
@click.option("--design", "designs", metavar="DIGITS", type=P.Text(max_length=1000), multiple=True,
              help="A design, base first (repeat; default: all units aligned). All of one length.")
@click.option("--units", "n_units", type=P.UNITS, default=15, show_default=True,
              help="Units of the default design (ignored with --design).")
@click.option("--size", "sizes", type=P.Real(0.0, 100.0, low_open=True, unit="mm"), multiple=True,
              help="Element size, mm (repeat; default 1.5, 1.0 and 0.75).")
@click.option("--model", "fidelity", type=click.Choice(["2d", "3d"]), default="3d", show_default=True,
              help="The FE model.")
@click.option("--pressure", type=P.PRESSURE_KPA, default=45.0, show_default=True, help="Final pressure, kPa.")
@click.option("--unit", "unit_file", type=P.InputFile(), help="Unit TOML file (default: the built-in unit).")
@click.option("--model-file", type=P.InputFile(), help=P.MODEL_FILE_HELP)
@click.option("--target", type=P.Text(), default="sin", show_default=True,
              help="The objective whose value is compared: a profile ('sin', 'y = ...') or a tip goal ('max-x').")
@click.option("--amplitude", type=P.Real(-1e4, 1e4, unit="mm"), default=10.0, show_default=True,
              help="Amplitude of a preset profile, mm.")
@click.option("--order", type=P.Real(0.0, 12.0, low_open=True), default=None,
              help="Order of convergence to assume for a design solved on two meshes only (e.g. observed on a "
                   "short actuator).")
@click.option("--cache", metavar="FILE", type=P.CacheFile(),
              help="Evaluation cache (default ~/.cache/pneumorph/evaluations.sqlite): a rerun resumes.")
@click.option("--out", type=P.OutputDir(), help="Folder for mesh.json and mesh.png.")
@click.option("--json", "as_json", is_flag=True, help="Print the results as JSON.")
@execution_options(default="serial", what="solves")
def mesh_cmd(designs: tuple[str, ...], n_units: int, sizes: tuple[float, ...], fidelity: str, pressure: float,
             unit_file: str | None, target: str, amplitude: float, order: float | None, cache: str | None,
             out: str | None, as_json: bool, executor: str, workers: int | None, scheduler: str | None,
             model_file: str | None = None) -> None:
    """Mesh convergence: designs solved at several element sizes; observed order, Richardson limit and error
    estimate of the tip, the curl and the objective (documentation page mesh-convergence, docs/mesh-convergence.md
    in the source)."""
    import os
    from pathlib import Path

    from pneumorph.design.objectives.targets import make_objective
    from pneumorph.geometry import parse_orientation
    from pneumorph.io import provenance, strict_json
    from pneumorph.io.files import all_or_nothing, write_json
    from pneumorph.models import make_model
    from pneumorph.sensitivity.mesh import MeshStudy, check_refinement, mesh_points

    check_options(executor, workers, scheduler)
    lengths = set()
    for design in designs:
        with P.blame("--design"):
            lengths.add(len(parse_orientation(design)))
    if len(lengths) > 1:
        raise click.BadParameter(f"the designs have different lengths ({sorted(lengths)}); give designs of one "
                                 "length", param_hint="--design")
    n = lengths.pop() if lengths else n_units
    designs = tuple(dict.fromkeys(designs)) or ("0" * n,)
    sizes = _mesh_sizes(sizes)
    settings: dict[str, Any] = {"fidelity": fidelity, "pressure_kpa": pressure}
    if unit_file:
        P.unit_option(unit_file)
        settings["unit_file"] = unit_file
    settings = _with_model_file(settings, model_file)
    fidelity = settings["fidelity"]
    model = make_model(n, settings)
    with P.blame("--target"):
        objective = make_objective(target, amplitude, length=n * model.unit.pitch)
    parallel = 1 if executor == "serial" else (workers or os.cpu_count() or 1)
    with P.blame("--size"):
        check_refinement(model, sizes, parallel=min(parallel, len(designs) * len(sizes)))
    evaluator = open_evaluator(executor, workers, scheduler, cache)
    done = [0]

    def progress(point: Any) -> None:
        done[0] += 1
        state = (f"curl {point.curl:.4f} deg, value {point.value:.4g} {objective.unit}" if point.ok
                 else f"failed: {point.failure}")
        lines.count(done[0], f"{point.design} at {point.element_size:g} mm ({point.cells:,} cells): {state}",
                    always=True)  # each point a line: their element sizes differ in cost

    with reporter() as lines:
        plan_solves(lines, "mesh study", len(designs) * len(sizes), model, executor, workers, out,
                    title=f"mesh study ({fidelity} model, {n} units, {pressure:g} kPa; {len(designs)} design(s) x "
                    f"{len(sizes)} element size(s))")
        try:
            points = mesh_points(model, designs, sizes, partial(_objective_at_best, objective), evaluator,
                                 on_point=progress)
        finally:
            evaluator.close()
    study = MeshStudy(tuple(points), objective.label, order)
    data = study.to_dict()
    data["objective_unit"] = objective.unit
    if (cluster := cluster_report(evaluator)) is not None:
        data["cluster"] = cluster
    data["provenance"] = provenance(command=" ".join(sys.argv), model=model.describe(), fingerprint=model.fingerprint())
    if out:
        from pneumorph.plot.mesh import plot_mesh_study

        # stopped while writing (Ctrl-C, a full disk): no partial output
        with all_or_nothing(out, say=reporter(), what="mesh.json and mesh.png") as folder:
            write_json(folder / "mesh.json", data)
            plot_mesh_study(study, folder / "mesh.png", unit=objective.unit, fingerprint=model.fingerprint())
    if as_json:
        click.echo(strict_json(data))
        return
    _print_mesh(study, objective.unit)
    if out:
        click.echo(f"written to {Path(out)}/ (mesh.json, mesh.png)")


def _mesh_sizes(sizes: tuple[float, ...]) -> tuple[float, ...]:
    """The element sizes of ``--size`` (default 1.5, 1.0 and 0.75), coarsest first: two or more, each once.

    One size has no convergence to estimate (and no use for ``--order``); a size given twice would be solved once.
    """
    if not sizes:
        return (1.5, 1.0, 0.75)
    twice = sorted({s for s in sizes if sizes.count(s) > 1})
    if twice:
        raise click.BadParameter(f"{', '.join(f'{s:g}' for s in twice)} mm given more than once; give each element "
                                 "size once", param_hint="--size")
    if len(sizes) < 2:
        raise click.BadParameter(f"one element size ({sizes[0]:g} mm) shows no convergence; give two or more (e.g. "
                                 f"--size {sizes[0]:g} --size {sizes[0] / 1.5:.3g}), or leave --size out for 1.5, "
                                 "1.0 and 0.75 mm", param_hint="--size")
    return tuple(sorted(sizes, reverse=True))


def _objective_at_best(objective: Any, response: Any) -> tuple[float, int | None]:
    """The objective at its best level (and the level) of a response."""
    from pneumorph.design.objectives.fitness import score

    s = score(response, objective)
    return float(s.value), s.level


def _print_mesh(study: Any, unit: str) -> None:
    click.echo(f"{'design':<18} {'size':>5} {'h [mm]':>7} {'cells':>7} {'dofs':>8} {'tip x':>9} {'tip y':>9} "
               f"{'curl [deg]':>10} {'value [' + unit + ']':>11} {'at kPa':>7} {'s':>6}")
    for p in study.points:
        if not p.ok:
            click.echo(f"{p.design:<18} {p.element_size:5.3g} {p.cell_size:7.3f} {p.cells:7,} {'':>8} failed: "
                       f"{p.failure}")
            continue
        assert p.tip is not None
        click.echo(f"{p.design:<18} {p.element_size:5.3g} {p.cell_size:7.3f} {p.cells:7,} {p.dofs:8,} "
                   f"{p.tip[0]:9.3f} {p.tip[1]:9.3f} {p.curl:10.4f} {p.value:11.4f} {p.pressure_kpa:7.4g} "
                   f"{p.wall_time_s:6.0f}")
    click.echo("")
    click.echo(f"{'design':<18} {'quantity':<8} {'order':>6} {'limit':>10} {'+-':>8}  method")
    for design in study.designs:
        for quantity in ("tip_x", "tip_y", "curl", "value"):
            c = study.convergence(design, quantity)
            if c is None:
                continue
            order = "-" if c.order is None else f"{c.order:.2f}"
            limit = "-" if c.extrapolated is None else f"{c.extrapolated:.4f}"
            click.echo(f"{design:<18} {quantity:<8} {order:>6} {limit:>10} {c.error:8.4f}  {c.method}")

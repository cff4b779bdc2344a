"""``pneumorph bimodal``: the bimodal Slow Pneu-net actuator of section 3.3 (3D FE).

Pressures in kPa, lengths in mm. FElupe and matplotlib are imported inside the command.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from pneumorph.checks import MAX_INCREMENTS, MAX_VOLUME_CHANGE, MIN_VOLUME_CHANGE, check_volume_steps
from pneumorph.cli.options import params as P
from pneumorph.cli.progress import reporter

#: the voids' relative volume change V/V0 - 1 at the end of the default volume-controlled ramp: the full-size
#: actuator (CR 0.2, library bulk modulus) passes the pressure ramp's end (about 35 kPa) and its pressure maximum
DEFAULT_VOLUME_CHANGE = 8.0
#: CPU seconds of one level of a bimodal ramp per ``nodes ** (4 / 3)`` of its half mesh (hex20, one thread; the
#: direct solver's growth, as :data:`~pneumorph.geometry.meshsize.BYTES_3D`'s): the full-size actuator's 12-step
#: volume ramps, 15,807 nodes (a 1.5 mm end wall) and 16,291 (the 6 mm one), took 69-113 s of CPU, 92 s on
#: average (docs/bimodal.md)
LEVEL_SECONDS = 1.9e-5


@click.command("bimodal")
@click.option("--crimp-ratio", "-c", type=click.Choice(["0.2", "0.25", "0.3"]), required=True,
              help="Crimp ratio of the bilinear composite (Table B.1).")
@click.option("--pmax", type=P.PRESSURE_KPA, default=60.0, show_default=True, help="Top pressure of the ramp in kPa.")
@click.option("--step", type=P.PRESSURE_KPA, default=5.0, show_default=True, help="Pressure step in kPa.")
@click.option("--voids", type=P.UNITS, default=15, show_default=True, help="Number of voids (10.5 mm each).")
@click.option("--element-size", type=P.POSITIVE_MM, default=2.5, show_default=True, help="Target element edge in mm.")
@click.option("--end-cap", type=P.Real(0.0, 1e4, unit="mm"), default=None,
              help="Extra solid beyond the last void in mm (the free end wall is 1.5 mm + this; 0: the 1.5 mm wall "
                   "alone, which balloons before the actuator reverses) [default: the geometry's, 4.5 mm: a 6 mm "
                   "free end, with which all three crimp ratios reverse].")
@click.option("--composite", type=click.Choice(["fibre", "homogenised"]), default="fibre", show_default=True,
              help="The composite: the Ecoflex matrix with the crimped paper along the actuator, or the "
                   "Table B.1 homogeneous Ogden material (isotropic, the dissertation's model).")
@click.option("--paper", type=click.Choice(["measured", "ideal"]), default="measured", show_default=True,
              help="With --composite fibre: the paper of the cast coupons (Table 3.2: it straightens at the measured "
                   "transition strain and resists unfolding before it) or the ideal crimp (slack until the analytic "
                   "straightening stretch, then the library paper's stiffness).")
@click.option("--bilinear-nu", type=P.Real(-1.0, 0.5, low_open=True, high_open=True), default=None,
              help="Small-strain Poisson's ratio of the composite (with --composite fibre: of its matrix), sets "
                   "its bulk modulus [default: the library's assumed bulk modulus].")
@click.option("--max-cutbacks", type=P.Count(0, 60), default=None,
              help="Halvings of a step that does not converge before the ramp ends there "
                   "[default: the model's own, shown in the --json metadata].")
@click.option("--max-iterations", type=P.Count(1, 1000), default=None,
              help="Newton iterations per trial [default: the model's own, shown in --json metadata].")
@click.option("--control", type=click.Choice(["volume", "pressure"]), default="volume", show_default=True,
              help="What the ramp drives: the voids' volume (the pressure an output, followed past its maximum "
                   "where a wall balloons) or the pressure (the ramp ends where a wall balloons).")
@click.option("--volume-change", type=P.Real(MIN_VOLUME_CHANGE, MAX_VOLUME_CHANGE), default=DEFAULT_VOLUME_CHANGE,
              show_default=True, help="With --control volume: the voids' relative volume change V/V0 - 1 at the "
                                      "ramp's end, in --pmax/--step equal steps (--pmax then scales the solver).")
@click.option("--gravity", type=click.Choice(["none", "hanging"]), default="none", show_default=True,
              help="Weight of the layers, applied before the ramp and held through it: hanging from the clamped "
                   "base as on the test bench (section 3.3.2); kept in the JSON's model description.")
@click.option("--out", type=P.OutputDir(), default=None,
              help="Folder for the response (JSON) and figures (PNG).")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@click.option("--quiet", "-q", is_flag=True, help="No progress lines.")
def bimodal(crimp_ratio: str, pmax: float, step: float, voids: int, element_size: float, end_cap: float | None,
            bilinear_nu: float | None, max_cutbacks: int | None, max_iterations: int | None, out: Path | None,
            as_json: bool, quiet: bool, control: str = "volume", volume_change: float = DEFAULT_VOLUME_CHANGE,
            composite: str = "fibre", paper: str = "measured", gravity: str = "none") -> None:
    """3D FE of the bimodal actuator: tip displacement in volume or pressure steps, switch pressure.

    Volume control (default) follows the pressure past its maximum where a wall balloons and
    reports the pressure of every step; pressure control ends at --pmax or at the last
    pressure that converges.
    """
    from pneumorph.bimodal.geometry import BimodalSpec
    from pneumorph.bimodal.model import MATRIX, BimodalModel, bilinear_material, bulk_from_poisson
    from pneumorph.io.files import strict_json
    from pneumorph.materials import get

    n = round(pmax / step)
    if step > pmax or abs(pmax / step - n) > 1e-6 or n > MAX_INCREMENTS:
        raise click.BadParameter(f"--step {step:g} kPa must divide --pmax {pmax:g} kPa into at most {MAX_INCREMENTS} "
                                 f"equal steps, so that the ramp ends at --pmax (e.g. --step "
                                 f"{pmax / min(max(n, 1), MAX_INCREMENTS):.4g})", param_hint="'--step'")
    if control == "volume":  # the one rule of a volume step (simulate's too), named in this command's options
        check_volume_steps(volume_change, n, ("--volume-change", "--pmax/--step"), click.UsageError,
                           advice=lambda least: f"give --step {pmax / least:.4g} kPa or smaller ({least} steps)")
    cr = float(crimp_ratio)
    bulk = None
    if bilinear_nu is not None:
        matrix = MATRIX if composite == "fibre" else bilinear_material(cr)
        bulk = bulk_from_poisson(get(matrix).shear_modulus, bilinear_nu)
    given = {"voids": voids, "element_size": element_size} | ({} if end_cap is None else {"end_cap": end_cap})
    for field, value in given.items():
        with P.blame("--" + field.replace("_", "-")):
            # one field at a time, so that an error names its option
            BimodalSpec(**{field: value})  # type: ignore[arg-type]
    spec = BimodalSpec(**given)  # type: ignore[arg-type]
    each = _level_seconds(spec)
    model = BimodalModel(spec, crimp_ratio=cr, pmax=pmax / 1e3, step=step / 1e3, bilinear_bulk=bulk,
                         max_cutbacks=max_cutbacks, max_iterations=max_iterations,  # None: the model's own
                         volume=volume_change if control == "volume" else None, composite=composite,
                         paper=paper, gravity=None if gravity == "none" else gravity)

    lines = reporter(quiet)  # on standard error: with --json too, standard output holds the JSON alone
    with lines:
        lines.plan("bimodal ramp", max(1, round(pmax / step)), noun="levels", each=each,
                   title=f"bimodal ramp to {pmax:g} kPa in steps of {step:g} kPa" if control == "pressure" else
                   f"bimodal ramp of the voids' volume to {1 + volume_change:g} V0 in {n} steps")
        result = model.solve(on_level=lambda k, p, v: lines.count(k + 1, f"{1e3 * p:6.1f} kPa  tip u_y {v:+8.3f} mm",
                                                                  always=True))
    data = result.to_dict()
    if out is not None:
        data["files"] = [str(p) for p in write_outputs(result, Path(out), say=lines)]
    if as_json:
        click.echo(strict_json(data, indent=2))
    else:
        click.echo(format_result(data))
        click.echo(f"written to {Path(out)}/ ({', '.join(Path(f).name for f in data['files'])})" if out is not None
                   else "nothing written: --out DIR keeps the response (JSON) and the figures")
    if not result.completed:  # a partial ramp is reported and written, and ends with its cause (exit 2)
        from pneumorph.errors import SimulationFailed

        reached = float(result.pressures[-1]) / result.pmax if len(result.pressures) else 0.0
        kept = "the levels before it are printed" + (" and written" if out is not None else "")
        raise SimulationFailed(reached=reached, cause=f"{result.cause.strip()}; {kept}", pressure=result.pmax)


def _level_seconds(spec: Any) -> float:
    """CPU seconds of one level of the bimodal actuator ``spec`` (:data:`LEVEL_SECONDS`), its nodes counted from
    its grid lines without meshing (:func:`~pneumorph.bimodal.geometry.node_count`); a solve estimated to need
    more memory than is available (:func:`~pneumorph.geometry.meshsize.solve_memory`) is refused, naming --voids
    and --element-size."""
    from pneumorph.bimodal.geometry import node_count
    from pneumorph.geometry.meshsize import available_memory, solve_memory

    nodes = node_count(spec)
    need, free = solve_memory(nodes, 3), available_memory()
    if need > free:
        raise click.UsageError(f"--voids {spec.voids} --element-size {spec.element_size:g}: a mesh of about "
                               f"{nodes:,} nodes, {need / 1e9:.1f} GB for the solve; {free / 1e9:.1f} GB are "
                               "available: fewer voids or larger elements")
    return LEVEL_SECONDS * nodes ** (4 / 3)


def format_result(d: dict[str, Any]) -> str:
    """Text summary of a :meth:`BimodalResult.to_dict`."""
    m = d["metadata"]
    s = d["switch"]
    head = (f"bimodal actuator, CR {d['crimp_ratio']:g}: {m['dofs']} dofs, {m['wall_time_s']:.0f} s, "
            f"composite {m['model'].get('composite', 'homogenised')}"
            f"{', paper ' + m['model']['paper'] if m['model'].get('paper') else ''}, "
            f"its bulk modulus {m['model']['bulk_moduli_kpa']['bilinear']:.4g} kPa"
            f"{', hanging under gravity' if m['model'].get('gravity_mm_s2') else ''}")
    lines = [head, "pressure (kPa)   tip u_x (mm)   tip u_y (mm)"]
    for p, ux, uy in zip(d["pressures_kpa"], d["tip_ux_mm"], d["tip_uy_mm"], strict=False):
        lines.append(f"{p:10.1f}   {ux:12.3f}   {uy:12.3f}")
    if not d["completed"]:
        lines.append(f"ramp ended early: {d['cause'].strip()}")
    if "pressure_max_kpa" in m and d["pressures_kpa"]:
        top = int(max(range(len(d["pressures_kpa"])), key=lambda k: d["pressures_kpa"][k]))
        after = "" if top == len(d["pressures_kpa"]) - 1 else f", then {d['pressures_kpa'][-1]:.1f} kPa at the end"
        lines.append(f"volume control: pressure maximum {m['pressure_max_kpa']:.2f} kPa at step {top + 1} "
                     f"(V = {m['volumes_mm3'][top] / m['volume0_mm3']:.3g} V0){after}")
    turn = "none" if s["turning_kpa"] is None else f"{s['turning_kpa']:g} kPa (u_y {s['peak_mm']:.3f} mm)"
    lines.append(f"tip turns back at: {turn}")
    limit = d["pressures_kpa"][-1] if d["pressures_kpa"] else 0.0
    sw = f"{s['switch_kpa']:.2f} kPa" if s["switch_kpa"] is not None else f"none below {limit:g} kPa"
    lines.append(f"switch pressure (bending direction reverses): {sw}")
    return "\n".join(lines)


def write_outputs(result: Any, out: Path, say: Any = None) -> list[Path]:
    """Write ``bimodal-CR.json`` and the tip-path and outline figures into ``out`` (saying so first through
    ``say``, a reporter)."""
    from pneumorph.bimodal import figures
    from pneumorph.io.files import all_or_nothing, write_json

    tag = f"cr{result.crimp_ratio:g}".replace(".", "_")
    js = out / f"bimodal-{tag}.json"
    tip = out / f"bimodal-{tag}-tip.png"
    shape = out / f"bimodal-{tag}-shape.png"
    # stopped while writing (Ctrl-C, a full disk): no partial output
    with all_or_nothing(out, say=say, what="the response (JSON) and the figures"):
        write_json(js, result.to_dict(), indent=2)
        figures.plot_tip_paths([(f"CR {result.crimp_ratio:g}", result)],
                               title=f"Bimodal actuator, CR {result.crimp_ratio:g}", path=tip)
        figures.plot_outlines(result, title=f"Mid-plane outline, CR {result.crimp_ratio:g}", path=shape)
    return [js, tip, shape]

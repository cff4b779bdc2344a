"""``pneumorph composite ...``: the crimped paper-silicone composite (chapter 3).

Lengths in mm; the matrix bulk modulus in kPa (as the material library prints it).
FElupe and matplotlib are imported only by the commands that need them.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from pneumorph.cli.options import params as P
from pneumorph.errors import CrimpError


@click.group()
def composite() -> None:
    """Bilinear paper-silicone composite: analytical transition strain, coupon FE, strain gauges."""


def _crimp(crimp_ratio: float | None, wavelength: float | None, amplitude: float, length: float) -> Any:
    from pneumorph.composite.crimp import Crimp

    if (crimp_ratio is None) == (wavelength is None):
        raise CrimpError("give exactly one of --crimp-ratio and --wavelength")
    if crimp_ratio is not None:
        return Crimp.from_ratio(crimp_ratio, amplitude, length)
    return Crimp(amplitude, wavelength, length)  # type: ignore[arg-type]


_CRIMP_OPTIONS = [
    click.option("--crimp-ratio", "-c", type=P.Real(0.0, 10.0, low_open=True), default=None, help="CR = A / lambda."),
    click.option("--wavelength", type=P.POSITIVE_MM, default=None, help="lambda in mm (instead of --crimp-ratio)."),
    click.option("--amplitude", "-a", type=P.POSITIVE_MM, default=1.5, show_default=True,
                 help="A in mm (paper between -A and +A)."),
    click.option("--length", "-l", type=P.POSITIVE_MM, default=176.25, show_default=True,
                 help="Crimped length L0 in mm."),
]


def _crimp_options(f: Any) -> Any:
    for option in reversed(_CRIMP_OPTIONS):
        f = option(f)
    return f


@composite.command("transition")
@_crimp_options
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of text.")
def transition(crimp_ratio: float | None, wavelength: float | None, amplitude: float, length: float,
               as_json: bool) -> None:
    """Analytical transition strain of a triangular crimp (Eqs 3.1-3.4)."""
    from pneumorph.io.files import strict_json

    c = _crimp(crimp_ratio, wavelength, amplitude, length)
    data = c.to_dict()
    if as_json:
        click.echo(strict_json(data, indent=2))
        return
    click.echo(
        "\n".join(
            [
                f"crimp ratio CR        {c.crimp_ratio:.4g}",
                f"amplitude A           {c.amplitude:.4g} mm",
                f"wavelength lambda     {c.wavelength:.4g} mm",
                f"crimped length L0     {c.length:.6g} mm",
                f"flute length s        {c.flute_length:.4f} mm   (Eq 3.1)",
                f"flutes N              {c.flutes:.4f}      (Eq 3.2)",
                f"effective length L_e  {c.effective_length:.3f} mm  (Eq 3.3)",
                f"transition strain     {100 * c.transition_strain:.2f} %     (Eq 3.4)",
                f"  whole-length crimp  {100 * c.limit_transition_strain:.2f} %     (2 s / lambda - 1)",
            ]
        )
    )


@composite.command("coupon")
@_crimp_options
@click.option("--thickness", type=P.POSITIVE_MM, default=5.0, show_default=True, help="Coupon thickness in mm.")
@click.option("--per-flute", type=P.Count(1, 64), default=4, show_default=True,
              help="Cells along each flute (half wavelength).")
@click.option("--rows", type=P.Count(1, 64), default=4, show_default=True,
              help="Cell rows between the paper and each surface.")
@click.option("--levels", type=P.INCREMENTS, default=100, show_default=True, help="Recorded load levels.")
@click.option("--strain-max", type=P.Real(0.0, 10.0, low_open=True), default=None,
              help="Final engineering strain [default: 2 s / lambda - 1 + 0.10].")
@click.option("--bulk-modulus", type=P.Real(0.0, 1e9, low_open=True, unit="kPa"), default=None,
              help="Matrix bulk modulus in kPa [default: library].")
@click.option("--gauges", type=P.Count(0, 10_000), default=None,
              help="Virtual strain gauges [default: Eq 3.5, 385; 0: none].")
@click.option("--seed", type=P.SEED, default=0, show_default=True, help="Seed of the gauge placement.")
@click.option("--snapshot", type=P.Real(0.0, 10.0), default=None,
              help="Engineering strain of the deformed-shape and surface-strain figures [default: last level].")
@click.option("--out", type=P.OutputDir(), default=None,
              help="Folder for the curve (CSV), summary (JSON) and figures (PNG).")
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON.")
@click.option("--quiet", "-q", is_flag=True, help="No progress lines.")
def coupon(crimp_ratio: float | None, wavelength: float | None, amplitude: float, length: float, thickness: float,
           per_flute: int, rows: int, levels: int, strain_max: float | None, bulk_modulus: float | None,
           gauges: int | None, seed: int, snapshot: float | None, out: Path | None, as_json: bool,
           quiet: bool) -> None:
    """Plane-strain FE tensile test of a crimped composite coupon (section 3.2.3)."""
    from pneumorph.cli.progress import reporter
    from pneumorph.composite.coupon import CouponSpec, simulate_coupon
    from pneumorph.io.files import strict_json

    c = _crimp(crimp_ratio, wavelength, amplitude, length)
    final = strain_max if strain_max is not None else c.limit_transition_strain + 0.10
    if snapshot is not None and snapshot > final:
        raise click.BadParameter(f"--snapshot {snapshot:g} lies beyond the final strain {final:.4g} of the test",
                                 param_hint="'--snapshot'")
    spec = CouponSpec(crimp=c, thickness=thickness, per_flute=per_flute, rows=rows,
                      bulk_modulus=None if bulk_modulus is None else bulk_modulus / 1000.0)
    snaps = () if snapshot is None else (snapshot,)
    lines = reporter(quiet)
    with lines:  # the plan, each level as it converges, and the heartbeat through the gauges and the figures
        lines.plan("coupon", levels, each=spec.level_seconds(), noun="levels", where=None if out is None else str(out),
                   title=f"coupon of CR {c.crimp_ratio:.4g} ({len(spec.mesh().points):,} nodes) pulled to "
                         f"{100 * final:.1f} % strain")
        result = simulate_coupon(spec, strain_max=strain_max, levels=levels, snapshots=snaps,
                                 on_level=lambda k, e, f: lines.count(k + 1, f"{100 * e:.1f} % strain, {f:.4g} N/mm"))
        summary = summarise(result, gauges, seed)
        if out is not None:
            write_outputs(result, summary, Path(out), snapshot, say=lines)
    if as_json:
        click.echo(strict_json(summary, indent=2))
        return
    click.echo(format_summary(summary))


def summarise(result: Any, gauges: int | None, seed: int) -> dict[str, Any]:
    """Plain-data summary of a coupon run (transitions, cost, optional gauge study)."""
    data = result.to_dict()
    summary = {k: v for k, v in data.items() if k not in ("engineering_strain", "surface_strain", "force")}
    summary["levels"] = len(result.force) - 1
    summary["final_engineering_strain"] = float(result.engineering_strain[-1])
    summary["analytical_transition"] = result.spec.crimp.transition_strain
    summary["analytical_limit_transition"] = result.spec.crimp.limit_transition_strain
    if gauges is None or gauges > 0:
        from pneumorph.composite.gauges import gauge_study

        study = gauge_study(result, count=gauges, rng=seed)
        summary["gauges"] = {**study.to_dict(), "seed": seed, "lengths_mm": "5-50 in steps of 5"}
    return summary


def format_summary(s: dict[str, Any]) -> str:
    """Text form of :func:`summarise`."""
    c = s["spec"]["crimp"]
    lines = [
        (
            f"coupon: CR {c['crimp_ratio']:.4g} (A {c['amplitude']:g} mm, lambda {c['wavelength']:.4g} mm), "
            f"L0 {c['length']:g} mm, thickness {s['spec']['thickness']:g} mm, {s['dofs']} dofs, "
            f"{s['levels']} levels to {100 * s['final_engineering_strain']:.1f} % in {s['seconds']:.1f} s "
            f"({s['newton_iterations']} Newton iterations, {s['cutbacks']} cut-backs)"
        ),
        f"transition, engineering strain      {100 * s['transition_engineering']:.2f} %",
        f"transition, averaged surface strain {100 * s['transition_surface']:.2f} %",
        f"analytical, Eq 3.4                  {100 * s['analytical_transition']:.2f} %",
        f"analytical, 2 s / lambda - 1        {100 * s['analytical_limit_transition']:.2f} %",
        (
            f"primary / secondary slope (engineering) {s['primary_modulus_engineering']:.4g} / "
            f"{s['secondary_modulus_engineering']:.4g} N per mm of width"
        ),
    ]
    g = s.get("gauges")
    if g:
        half = g["confidence_halfwidth_95"]
        lines.append(
            f"virtual strain gauges ({g['count']}, seed {g['seed']}): averaged-curve transition "
            f"{100 * g['transition_strain']:.2f} %, per gauge {100 * g['mean_transition']:.2f} % "
            f"+- {100 * g['std_transition']:.2f} % (s.d.; 95 % CI of the mean +- "
            f"{100 * half if math.isfinite(half) else float('nan'):.2f} %; {g['fitted']} fitted)"
        )
    return "\n".join(lines)


def write_outputs(result: Any, summary: dict[str, Any], out: Path, snapshot: float | None,
                  say: Any = None) -> list[Path]:
    """Write ``coupon-CR.csv``, ``coupon-CR.json`` and the three figures into ``out`` (saying so first through
    ``say``, a reporter)."""
    import numpy as np

    from pneumorph.composite import figures
    from pneumorph.io.files import all_or_nothing, write_json

    tag = f"cr{result.spec.crimp.crimp_ratio:.4g}".replace(".", "_")
    csv = out / f"coupon-{tag}.csv"
    js = out / f"coupon-{tag}.json"
    paths = [csv, js]
    # stopped while writing (Ctrl-C, a full disk): no partial output
    with all_or_nothing(out, say=say, what="the coupon's CSV, JSON and figures"):
        np.savetxt(csv, np.column_stack([result.engineering_strain, result.surface_strain, result.force]),
                   delimiter=",", header="engineering_strain,surface_strain,force_N_per_mm", comments="", fmt="%.8g")
        write_json(js, summary, indent=2)
        for name, fn in (("load", lambda p: figures.plot_load_strain([result], p)),
                         ("deformed", lambda p: figures.plot_deformed(result, snapshot, path=p)),
                         ("surface-strain", lambda p: figures.plot_surface_strain(result, snapshot, path=p))):
            path = out / f"coupon-{tag}-{name}.png"
            fn(path)
            paths.append(path)
    return paths

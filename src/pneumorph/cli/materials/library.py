"""``pneumorph materials list`` and ``pneumorph materials show NAME``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import click

from pneumorph.cli.options import params as P
from pneumorph.errors import UnknownMaterialError

if TYPE_CHECKING:  # the library is imported when a command runs: --help imports no material code
    from pneumorph.materials.laws.filler import FillerLaw
    from pneumorph.materials.library.builtin import Material, Quantity

_LABELS = {
    "density": "density",
    "bulk_modulus": "bulk modulus",
    "thermal_expansion": "thermal expansion",
    "youngs_modulus": "Young's modulus",
    "poisson_ratio": "Poisson's ratio",
    "thickness": "thickness",
}


def _register(files: tuple[str, ...]) -> None:
    from pneumorph.materials.library import builtin as library

    for path in files:
        with P.blame("--library"):
            library.register_toml(path)


_library_option = click.option(
    "--library",
    "library_files",
    multiple=True,
    type=P.InputFile(),
    help="Also load materials from this TOML file (same schema as the built-in library; repeatable).",
)


@click.command("list")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of a table.")
@_library_option
def list_materials(as_json: bool, library_files: tuple[str, ...]) -> None:
    """List the materials and filler laws of the library.

    Shows the name to use with `show`, the kind, the initial shear modulus mu0 and the
    bulk modulus. Names are case and format tolerant ("Mold Star 15" = mold_star_15).
    """
    from pneumorph.io.files import strict_json
    from pneumorph.materials.library import builtin as library

    _register(library_files)
    materials = [library.get(n) for n in library.names()]
    fillers = [library.get_filler(n) for n in library.filler_names()]
    if as_json:
        out = {
            "materials": [
                {
                    "name": m.name,
                    "display_name": m.display_name,
                    "kind": m.kind,
                    "shear_modulus_MPa": m.shear_modulus,
                    "bulk_modulus_MPa": m.bulk_modulus.value if m.bulk_modulus else None,
                    "assumed": list(m.assumed),
                    "source": m.source,
                    "origin": m.origin,
                }
                for m in materials
            ],
            "fillers": [
                {"name": f.name, "display_name": f.display_name, "source": f.source} for f in fillers
            ],
        }
        click.echo(strict_json(out, indent=2))
        return
    width = max(20, *(len(m.name) for m in materials), *(len(f.name) for f in fillers))
    click.echo(f"{'name':<{width}} {'kind':<15} {'mu0 [kPa]':>10} {'K [kPa]':>9}  display name")
    for m in materials:
        k = f"{m.bulk_modulus.value * 1e3:9.5g}" if m.bulk_modulus else f"{'-':>9}"
        star = "*" if m.assumed else " "
        click.echo(f"{m.name:<{width}} {m.kind:<15} {m.shear_modulus * 1e3:10.4g} {k}{star} {m.display_name}")
    for f in fillers:
        lo, hi = (x * 1e3 for x in f.pressure_range)
        click.echo(f"{f.name:<{width}} {'filler E(P)':<15} {'':>10} {'':>9}  {f.display_name} ({lo:g}-{hi:g} kPa)")
    if any(m.assumed for m in materials):
        click.echo("* includes assumed values (not given by the source); see `pneumorph materials show NAME`")


def _quantity_line(q: Quantity) -> list[str]:
    flag = "  [ASSUMED]" if q.assumed else ""
    if q.unit == "-":
        value = f"{q.printed:g}"
    else:
        value = f"{q.printed:g} {q.printed_unit} = {q.value:.6g} {q.unit}"
    lines = [
        f"  {_LABELS[q.name]:<18} {value}{flag}",
        f"  {'':<18} source: {q.source}",
    ]
    if q.reason:
        lines.append(f"  {'':<18} reason: {q.reason}")
    return lines


def _fit_lines(m: Material) -> list[str]:
    """How the model was fitted: data, attribution, range, method, stability, caveats."""
    f = m.fitting
    assert f is not None and m.model is not None
    lo, hi = f.stretch_range
    report = f.stability(m.model)
    check_lo, check_hi = f.stability_range
    lines = [
        "fitted to test data:",
        f"  data: {f.data}",
        f"  {f.attribution}",
        f"  fitted: {f.mode} tension, stretch {lo:g}-{hi:g} ({f.points} points); "
        "outside that range the model extrapolates",
        f"  method: {f.method}",
        f"  Drucker stability (uniaxial, equibiaxial, planar; stretch {check_lo:g}-{check_hi:g}): "
        + ("stable in every mode" if report.is_stable else "NOT stable everywhere"),
    ]
    if not report.is_stable:
        lines += ["    " + line for line in report.summary().splitlines()]
    lines.append("  caveats:")
    lines += [f"  - {c}" for c in f.caveats]
    return lines


def _material_text(m: Material) -> str:
    lines = [f"{m.display_name} ({m.name})", f"  kind: {m.kind}; source: {m.source}"]
    if m.description:
        lines.append(f"  {m.description}")
    if m.aliases:
        lines.append(f"  also called: {', '.join(m.aliases)}")
    lines.append(f"  from: {m.origin}")
    rec = m.model_record
    if rec is not None and rec.type == "ogden":
        params = dict(rec.parameters)
        lines.append(
            f"model: Ogden, {len(params['mu'])} terms, MSC Marc convention "  # type: ignore[arg-type]
            "W = sum mu_n/alpha_n (l1^a_n + l2^a_n + l3^a_n - 3)"
        )
        lines.append(f"  parameters as printed ({rec.source}), mu in {rec.unit}:")
        lines.append(f"  {'n':>3} {'mu_n (Marc)':>14} {'alpha_n':>10} {'mu_n FElupe [MPa]':>19}")
        mu, alpha = params["mu"], params["alpha"]
        assert isinstance(mu, tuple) and isinstance(alpha, tuple)  # an Ogden record's parameters are lists
        for i, (a, b, c) in enumerate(zip(mu, alpha, m.ogden_felupe_mu, strict=True), start=1):
            lines.append(f"  {i:>3} {a:>14g} {b:>10g} {c:>19.6g}")
        lines.append("  FElupe convention psi = sum 2 mu_i/alpha_i^2 (...): mu_i = mu_n alpha_n / 2")
        mu0_felupe = sum(m.ogden_felupe_mu)
        lines.append(
            f"initial shear modulus mu0 = {m.shear_modulus:.6g} MPa "
            f"(Marc: sum mu_n alpha_n / 2 = {m.shear_modulus:.6g}; FElupe: sum mu_i = {mu0_felupe:.6g})"
        )
    elif rec is not None:
        printed = ", ".join(f"{k} = {v}" for k, v in rec.parameters)
        lines.append(f"model: {rec.type} ({rec.source}): {printed} [{rec.unit}]")
        lines.append(f"initial shear modulus mu0 = {m.shear_modulus:.6g} MPa")
    else:
        lines.append(f"linear elastic; shear modulus E / (2 (1 + nu)) = {m.shear_modulus:.6g} MPa")
    nu0 = m.initial_poisson_ratio
    if nu0 is not None and m.model is not None:
        lines.append(f"small-strain Poisson's ratio from K and mu0: {nu0:.4g}")
    lines.append("properties (as printed = internal units):")
    for q in m.quantities:
        lines.extend(_quantity_line(q))
    if m.r_squared:
        values = ", ".join(f"{k} {v:.4f}" for k, v in m.r_squared)
        lines.append(f"R^2 of the source's fits: {values} ({m.r_squared_source})")
    if m.fitting is not None:
        lines.extend(_fit_lines(m))
    lines.append(f"assumed values: {', '.join(m.assumed) if m.assumed else 'none'}")
    return "\n".join(lines)


def _filler_text(f: FillerLaw) -> str:
    lo, hi = (x * 1e3 for x in f.pressure_range)
    terms = f"{f.coefficients[0]:g}"
    for k, c in enumerate(f.coefficients[1:], start=1):
        power = "P" if k == 1 else f"P^{k}"
        terms += f" {'-' if c < 0 else '+'} {abs(c):g} {power}"
    p_min, e_min = f.minimum()
    lines = [
        f"{f.display_name} ({f.name})",
        f"  source: {f.source}",
        f"  E(P) = {terms}  [MPa, P in MPa]",
        f"  calibrated range: {lo:g}-{hi:g} kPa (outside it the law is refused)",
        f"  {f.range_source}" if f.range_source else "",
        f"  smallest modulus in range: {e_min:.6g} MPa at {p_min * 1e3:g} kPa",
        f"  Poisson's ratio: {f.poisson_ratio:g}{'  [ASSUMED]' if f.poisson_ratio_assumed else ''}",
        f"    source: {f.poisson_ratio_source}",
    ]
    if f.poisson_ratio_reason:
        lines.append(f"    reason: {f.poisson_ratio_reason}")
    return "\n".join(line for line in lines if line)


@click.command("show")
@click.argument("name")
@click.option("--json", "as_json", is_flag=True, help="Print JSON (printed and internal values).")
@_library_option
def show_material(name: str, as_json: bool, library_files: tuple[str, ...]) -> None:
    """Show every property of material NAME with units, convention, source and assumptions.

    NAME may be any spelling ("Mold Star 15", mold-star-15) or the name of a filler law
    (ellis2020_eq5_2). Internal units: MPa, tonne/mm^3, 1/K, mm.
    """
    from pneumorph.io.files import strict_json
    from pneumorph.materials.library import builtin as library
    from pneumorph.materials.library.builtin import Material

    _register(library_files)
    obj: Material | FillerLaw
    try:
        obj = library.get(name)
    except UnknownMaterialError:
        if library.normalise(name) not in library.filler_names():
            raise UnknownMaterialError(name, library.names() + library.filler_names()) from None
        obj = library.get_filler(name)
    if as_json:
        data: dict[str, Any] = obj.to_dict()
        click.echo(strict_json(data, indent=2))
    elif isinstance(obj, Material):
        click.echo(_material_text(obj))
    else:
        click.echo(_filler_text(obj))

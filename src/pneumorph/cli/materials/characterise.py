"""``pneumorph materials characterise poisson|thermal|bilinear DATA.csv``."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from pneumorph.cli.options import params as P
from pneumorph.errors import DataFormatError

if TYPE_CHECKING:
    import numpy as np

_STRAIN_SCALE = {"fraction": 1.0, "percent": 0.01}


def read_columns(
    path: str | Path, required: tuple[str, ...], optional: tuple[str, ...] = ()
) -> dict[str, np.ndarray]:
    """Read named numeric columns of a CSV file with a header row.

    The delimiter (comma, semicolon or tab) is taken from the header line; column names
    are matched case-insensitively, ignoring surrounding spaces; other columns are ignored;
    blank lines are skipped.

    Raises
    ------
    DataFormatError
        Empty file, missing column, a row with too few fields or a non-numeric / non-finite
        value; the message names the file and the row (1-based, header = row 1).
    """
    import numpy as np

    from pneumorph.io.reading import check_rows, csv_rows, read_text_file

    p = str(path)
    text = read_text_file(path, "data file", DataFormatError, encoding="utf-8-sig")
    check_rows(text, f"data file {p}", DataFormatError)  # counted before they are split
    lines = text.splitlines()
    if not lines or not lines[0].strip():
        raise DataFormatError("empty file; expected a header row with " + ", ".join(required), p, 1)
    header = lines[0]
    delimiter = max((",", ";", "\t"), key=header.count)
    rows = csv_rows(lines, f"data file {p}", DataFormatError, delimiter)
    names = [h.strip().lower() for h in rows[0]]
    index: dict[str, int] = {}
    for col in (*required, *optional):
        if col in names:
            index[col] = names.index(col)
        elif col in required:
            raise DataFormatError(
                f"missing column {col!r}; expected columns {', '.join(required)}"
                + (f" (optional: {', '.join(optional)})" if optional else "")
                + f", found {', '.join(names)}",
                p,
                1,
            )
    values: dict[str, list[float]] = {col: [] for col in index}
    for row_no, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        for col, i in index.items():
            if i >= len(row):
                raise DataFormatError(f"{len(row)} field(s), but column {col!r} is field {i + 1}", p, row_no)
            cell = row[i].strip()
            try:
                x = float(cell)
            except ValueError:
                raise DataFormatError(f"column {col!r}: expected a number, got {cell!r}", p, row_no) from None
            if not math.isfinite(x):
                raise DataFormatError(f"column {col!r}: expected a finite number, got {cell!r}", p, row_no)
            values[col].append(x)
    if not any(values.values()):
        raise DataFormatError("no data rows after the header", p, 2)
    return {col: np.array(v) for col, v in values.items()}


def _emit(data: dict[str, Any], text: list[str], as_json: bool) -> None:
    from pneumorph.io.files import strict_json

    click.echo(strict_json(data, indent=2) if as_json else "\n".join(text))


_strain_unit = click.option(
    "--strain-unit",
    type=click.Choice(list(_STRAIN_SCALE)),
    default="fraction",
    show_default=True,
    help="Unit of the strain columns in the file (0.1 or 10 for 10 %).",
)
_json = click.option("--json", "as_json", is_flag=True, help="Print JSON.")


@click.group("characterise")
def characterise() -> None:
    """Characterise materials from test data (CSV files with a header row)."""


@characterise.command("poisson")
@click.argument("data", type=P.InputFile())
@click.option(
    "--strain-range",
    nargs=2,
    type=P.Real(-1e6, 1e6),
    default=(0.0, 150.0),
    show_default=True,
    help="Axial strain range to average over, in percent (Table A.5 used 0-150 %).",
)
@click.option(
    "--modulus",
    type=click.Choice(["secant", "tangent"]),
    default="secant",
    show_default=True,
    help="E in Eq A.4: secant sigma/eps (consistent with Eq A.5) or tangent d sigma/d eps.",
)
@_strain_unit
@_json
def poisson(data: str, strain_range: tuple[float, float], modulus: str, strain_unit: str, as_json: bool) -> None:
    """Poisson's ratio (Eq A.5) and bulk modulus (Eq A.4) from a uniaxial DIC test.

    \b
    DATA columns (header row, any order, comma/semicolon/tab separated):
      axial_strain        engineering strain in the loaded direction
      transverse_strain   engineering strain across it (negative in tension)
      axial_stress        engineering stress in MPa (optional; needed for K)

    nu = -eps_y/eps_x and K = E/(3(1 - 2 nu)) are evaluated at every point with non-zero
    axial strain inside --strain-range and averaged.
    """
    from pneumorph.materials.characterisation import analyses as ch

    cols = read_columns(data, ("axial_strain", "transverse_strain"), ("axial_stress",))
    scale = _STRAIN_SCALE[strain_unit]
    lo, hi = (x / 100.0 for x in strain_range)
    r = ch.characterise_bulk_modulus(
        cols["axial_strain"] * scale,
        cols["transverse_strain"] * scale,
        cols.get("axial_stress"),
        strain_range=(lo, hi),
        modulus=modulus,  # type: ignore[arg-type]
    )
    out: dict[str, Any] = {
        "file": data,
        "strain_range_percent": list(strain_range),
        "points": r.n,
        "mean_poisson_ratio": r.mean_poisson_ratio,
        "modulus": modulus,
        "mean_youngs_modulus_MPa": r.mean_youngs_modulus,
        "mean_bulk_modulus_MPa": r.mean_bulk_modulus,
        "strain_average_bulk_modulus_MPa": r.strain_average_bulk_modulus,
    }
    text = [
        f"{data}: {r.n} points with axial strain {strain_range[0]:g}-{strain_range[1]:g} %",
        f"  mean Poisson's ratio (Eq A.5): {r.mean_poisson_ratio:.4f}",
    ]
    if r.mean_bulk_modulus is not None:
        assert r.mean_youngs_modulus is not None and r.strain_average_bulk_modulus is not None
        text += [
            f"  mean {modulus} Young's modulus: {r.mean_youngs_modulus * 1e3:.4g} kPa",
            f"  mean bulk modulus (Eq A.4): {r.mean_bulk_modulus * 1e3:.4g} kPa "
            f"(strain-weighted: {r.strain_average_bulk_modulus * 1e3:.4g} kPa)",
        ]
    else:
        text.append("  no axial_stress column: bulk modulus not computed")
    _emit(out, text, as_json)


@characterise.command("thermal")
@click.argument("data", type=P.InputFile())
@_strain_unit
@_json
def thermal(data: str, strain_unit: str, as_json: bool) -> None:
    """Linear thermal expansion coefficient (Eq A.6) by linear regression.

    \b
    DATA columns (header row):
      temperature   degC
      strain        engineering thermal strain (any reference state)
    """
    from pneumorph.materials.characterisation import analyses as ch

    cols = read_columns(data, ("temperature", "strain"))
    r = ch.thermal_expansion(cols["temperature"], cols["strain"] * _STRAIN_SCALE[strain_unit])
    out = {
        "file": data,
        "alpha_per_K": r.alpha,
        "alpha_micro_per_degC": r.alpha * 1e6,
        "standard_error_per_K": r.standard_error,
        "intercept": r.intercept,
        "r_squared": r.r_squared,
        "points": r.n,
        "temperature_range_degC": list(r.temperature_range),
    }
    text = [
        f"{data}: {r.n} points, {r.temperature_range[0]:g}-{r.temperature_range[1]:g} degC",
        f"  alpha = {r.alpha * 1e6:.4g} +/- {r.standard_error * 1e6:.2g} micro-mm/mm/degC "
        f"(= {r.alpha:.4g} 1/K, +/- one standard error)",
        f"  R^2 = {r.r_squared:.5f}",
    ]
    _emit(out, text, as_json)


@characterise.command("bilinear")
@click.argument("data", type=P.InputFile())
@click.option(
    "--primary-limit",
    type=P.Real(0.0, 1e6, low_open=True),
    default=10.0,
    show_default=True,
    help="Primary fit uses the points with strain up to this value, in percent.",
)
@click.option("--secondary-points", type=P.Count(2, 1_000_000), default=10, show_default=True,
              help="Secondary fit uses this many final points.")
@_strain_unit
@_json
def bilinear(data: str, primary_limit: float, secondary_points: int, strain_unit: str, as_json: bool) -> None:
    """Two-line characterisation of a composite tensile curve (section 3.2.6, Table 3.2).

    \b
    DATA columns (header row, rows in test order):
      strain   engineering strain
      stress   engineering stress in MPa
    Primary modulus: line through the first --primary-limit % of strain; secondary
    modulus: line through the last --secondary-points points; transition: where they meet.
    """
    from pneumorph.materials.characterisation import analyses as ch

    cols = read_columns(data, ("strain", "stress"))
    if secondary_points > cols["strain"].size:
        raise click.BadParameter(f"{secondary_points} points asked for the secondary fit, but {data} has "
                                 f"{cols['strain'].size}", param_hint="'--secondary-points'")
    r = ch.bilinear(
        cols["strain"] * _STRAIN_SCALE[strain_unit],
        cols["stress"],
        primary_strain_limit=primary_limit / 100.0,
        secondary_points=secondary_points,
    )
    out = {
        "file": data,
        "primary_modulus_MPa": r.primary_modulus,
        "primary_r_squared": r.primary.r_squared,
        "primary_points": r.primary.n,
        "secondary_modulus_MPa": r.secondary_modulus,
        "secondary_r_squared": r.secondary.r_squared,
        "secondary_points": r.secondary.n,
        "transition_strain": r.transition_strain,
        "transition_stress_MPa": r.transition_stress,
    }
    text = [
        f"{data}:",
        f"  primary modulus   {r.primary_modulus * 1e3:.4g} kPa (R^2 {r.primary.r_squared:.4f}, "
        f"{r.primary.n} points <= {primary_limit:g} %)",
        f"  secondary modulus {r.secondary_modulus:.4g} MPa (R^2 {r.secondary.r_squared:.4f}, "
        f"last {r.secondary.n} points)",
        f"  transition        {r.transition_strain * 100:.4g} % strain at {r.transition_stress * 1e3:.4g} kPa",
    ]
    _emit(out, text, as_json)

"""``pneumorph materials fit``: fit hyperelastic models to test data."""

from __future__ import annotations

import click

from pneumorph import __version__
from pneumorph.checks import COLUMN_ROLES, MAX_STARTS, MODEL_NAMES, MODES, TRUNCATE, WEIGHTINGS
from pneumorph.cli.options import params as P


@click.command("fit")
@click.argument("data", nargs=-1, required=True, type=P.Text(1000))
@click.option("--model", "-m", "models", multiple=True, metavar="NAME", type=P.Text(100),
              help=f"Model to fit, repeatable (several give a comparison table): "
                   f"{', '.join(MODEL_NAMES)}. Default ogden-3.")
@click.option("--mode", type=click.Choice(MODES),
              help="Loading mode of the data files (default: from each file name, else uniaxial).")
@click.option("--columns", metavar="ROLES", type=P.Text(200),
              help=f"Column roles, comma-separated, from {', '.join(COLUMN_ROLES)}; "
                   "e.g. 'stress,stretch' (default: from the header, else stretch,stress).")
@click.option("--strain-unit", type=click.Choice(["fraction", "percent"]), help="Unit of a strain column.")
@click.option("--stress-kind", type=click.Choice(["nominal", "true"]),
              help="Nominal (engineering) or true stress; true becomes sigma/lambda.")
@click.option("--stress-unit", metavar="UNIT", type=P.Text(20), help="MPa (default), kPa, Pa, N/mm^2, kgf/cm^2 or psi.")
@click.option("--delimiter", metavar="CHAR", type=P.DELIMITER, help="Column delimiter (default: detected).")
@click.option("--truncate", type=click.Choice(TRUNCATE),
              help="Keep the rows up to the largest stretch (loading) or stress (peak-stress); "
                   "default peak-stress for pull-to-failure database files, else none.")
@click.option("--min-stretch", type=P.Real(0.0, 100.0, low_open=True),
              help="Fit only points with at least this stretch.")
@click.option("--max-stretch", type=P.Real(0.0, 100.0, low_open=True),
              help="Fit only points with at most this stretch.")
@click.option("--weighting", type=click.Choice(WEIGHTINGS), default="absolute", show_default=True,
              help="Residuals: plain stress, relative to the stress, or per-mode normalised.")
@click.option("--stable", is_flag=True,
              help="Constrain parameter signs so that the model is Drucker-stable everywhere "
                   "(Ogden mu_n alpha_n >= 0; invariant models coefficients >= 0).")
@click.option("--seed", type=P.SEED, default=0, show_default=True, help="Seed of the Ogden starts.")
@click.option("--starts", type=P.Count(1, MAX_STARTS, limit="MAX_STARTS"), default=8, show_default=True,
              help="Number of Ogden starts.")
@click.option("--plot", "plot_path", type=P.OutputFile((".png", ".pdf", ".svg")),
              help="Write a figure of data and fits (PNG, SVG or PDF by extension).")
@click.option("--json", "as_json", is_flag=True, help="Machine-readable output.")
@click.option("--markdown", is_flag=True, help="Print only the R^2 table as Markdown.")
def fit(data: tuple[str, ...], models: tuple[str, ...], mode: str | None, columns: str | None,
        strain_unit: str | None, stress_kind: str | None, stress_unit: str | None,
        delimiter: str | None, truncate: str | None, min_stretch: float | None,
        max_stretch: float | None, weighting: str, stable: bool, seed: int, starts: int,
        plot_path: str | None, as_json: bool, markdown: bool) -> None:
    """Fit hyperelastic models to test DATA (files and/or bundled data sets).

    DATA are stress-stretch files (CSV, semicolon, tab or whitespace; the Soft Robotics
    Materials Database format is recognised) or names of bundled data sets
    (e.g. treloar1944). Several files are combined, each mode taken from its file name
    (Treloar_ut.dat, .../PS/...) unless --mode is given.
    """
    from pneumorph.io.files import strict_json
    from pneumorph.materials.characterisation.datasets import list_datasets, read_test_data
    from pneumorph.materials.characterisation.testdata import column_roles, stress_unit_factor
    from pneumorph.materials.fitting.comparison import compare
    from pneumorph.materials.fitting.fit import resolve_model

    models = models or ("ogden-3",)
    with P.blame("--model"):
        for name in models:
            resolve_model(name)
    if columns is not None:
        with P.blame("--columns"):
            column_roles(columns)
    if stress_unit is not None:
        with P.blame("--stress-unit"):
            stress_unit_factor(stress_unit)
    given = {"columns": columns, "strain_unit": strain_unit, "stress_kind": stress_kind,
             "stress_unit": stress_unit, "delimiter": delimiter, "truncate": truncate}
    options = {k: v for k, v in given.items() if v is not None}
    test = read_test_data(data, mode, **options)
    if min_stretch is not None or max_stretch is not None:
        test = test.restrict(min_stretch, max_stretch)
    table = compare(models, test, weighting=weighting, seed=seed, starts=starts, stable=stable)
    if plot_path:
        from pneumorph.plot.fits import plot_fits  # matplotlib only when asked

        plot_fits(test, table.results, plot_path)
    if as_json:
        out = {"pneumorph": __version__, "command": "materials fit",
               "data": {"name": test.name, "sources": list(test.sources),
                        "datasets": [d.name for d in list_datasets() if d.name in data],
                        "notes": sorted({n for c in test.curves for n in c.notes})},
               "modes": list(table.modes), "table": table.rows(),
               "fits": [r.to_dict() for r in table.results], "plot": plot_path}
        click.echo(strict_json(out, indent=2))
        return
    if markdown:
        click.echo(table.to_markdown())
        return
    notes = sorted({n for c in test.curves for n in c.notes})
    click.echo(f"data: {test.name} ({', '.join(test.modes)})")
    for n in notes:
        click.echo(f"  note: {n}")
    for r in table.results:
        click.echo("")
        click.echo(r.summary())
    if len(table.results) > 1:
        click.echo("")
        click.echo(table.to_text())
    if plot_path:
        click.echo(f"\nfigure written to {plot_path}")

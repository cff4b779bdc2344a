"""Command-line interface: a thin layer over the public API.

Each sub-command group lives in its own module and only parses arguments, calls the API
and prints results (human-readable, or JSON with ``--json``). Units at this edge are the
ones users speak (kPa for pressure); the API works in mm, N, MPa.
"""

from __future__ import annotations

import sys

import click

from pneumorph import __version__
from pneumorph.cli.materials import materials
from pneumorph.errors import PneumorphError


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", "-V", prog_name="pneumorph")
def cli() -> None:
    """pneumorph - generative design of soft pneumatic actuators."""


cli.add_command(materials)

from pneumorph.cli.composite import composite  # noqa: E402

cli.add_command(composite)

from pneumorph.cli.calibrate import calibrate  # noqa: E402
from pneumorph.cli.chain import chain  # noqa: E402
from pneumorph.cli.design import design  # noqa: E402
from pneumorph.cli.simulate import simulate  # noqa: E402
from pneumorph.cli.study import study  # noqa: E402

cli.add_command(calibrate)
cli.add_command(chain)
cli.add_command(design)
cli.add_command(simulate)
cli.add_command(study)

from pneumorph.cli.bimodal import bimodal  # noqa: E402

cli.add_command(bimodal)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code (errors print one clear line)."""
    try:
        cli.main(args=argv, prog_name="pneumorph", standalone_mode=False)
    except click.exceptions.Abort:
        click.echo("aborted", err=True)
        return 130
    except click.ClickException as exc:
        exc.show()
        return exc.exit_code
    except PneumorphError as exc:
        click.echo(f"error: {exc}", err=True)
        return 2
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""``pneumorph materials ...``: the material library, fitting and characterisation."""

from __future__ import annotations

import click


@click.group()
def materials() -> None:
    """Silicone and composite materials: list, show, fit, characterise."""

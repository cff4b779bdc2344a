"""``pneumorph materials ...``: the material library, fitting and characterisation."""

from __future__ import annotations

import click


@click.group()
def materials() -> None:
    """Silicone and composite materials: list, show, fit, characterise."""


from pneumorph.cli.materials.characterise import characterise  # noqa: E402
from pneumorph.cli.materials.library import list_materials, show_material  # noqa: E402

materials.add_command(list_materials)
materials.add_command(show_material)
materials.add_command(characterise)

from pneumorph.cli.materials.fit import fit  # noqa: E402

materials.add_command(fit)

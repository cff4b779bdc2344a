"""``pneumorph materials ...``: the material library, fitting and characterisation."""

from __future__ import annotations

import click

from pneumorph.cli import LazyGroup

#: The group's commands: each one's module and attribute, and the first sentence of its help (``materials
#: --help`` lists them without importing one; a command imports the material code it needs when it runs or
#: shows its own help).
MATERIALS_COMMANDS: dict[str, tuple[str, str]] = {
    "characterise": ("pneumorph.cli.materials.characterise", "Characterise materials from test data (CSV files "
                     "with a header row)."),
    "fit": ("pneumorph.cli.materials.fit", "Fit hyperelastic models to test DATA (files and/or bundled data sets)."),
    "list": ("pneumorph.cli.materials.library:list_materials", "List the materials and filler laws of the library."),
    "show": ("pneumorph.cli.materials.library:show_material", "Show every property of material NAME with units, "
             "convention, source and assumptions."),
}


@click.group(cls=LazyGroup, table=MATERIALS_COMMANDS)
def materials() -> None:
    """Silicone and composite materials: list, show, fit, characterise."""

"""``pneumorph materials ...``: the group (:mod:`~pneumorph.cli.materials.group`), the library,
fits and characterisation."""

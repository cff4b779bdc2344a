"""The material library: material records, their TOML files and the built-in silicones.

- :mod:`~pneumorph.materials.library.material`: immutable material records;
- :mod:`~pneumorph.materials.library.schema`: reading and checking a material file;
- :mod:`~pneumorph.materials.library.builtin`: the dissertation's silicones, composites, paper
  and filler law (``materials/data/materials.toml``);
- :mod:`~pneumorph.materials.library.units`: the files' units and their conversion;
- :mod:`~pneumorph.materials.library.scaling`: a silicone with its moduli scaled.

The names to import are re-exported by :mod:`pneumorph.materials`.
"""

__all__: list[str] = []  # the names to import are re-exported by the parent package

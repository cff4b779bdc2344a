"""Constitutive laws: the closed-form hyperelastic models, their FElupe materials, the filler law.

- :mod:`~pneumorph.materials.laws.hyperelastic`: incompressible models in closed form
  (neo-Hookean, Mooney-Rivlin, Yeoh, Ogden, ...), their stresses in every test mode;
- :mod:`~pneumorph.materials.laws.felupe_models`: the same models as FElupe materials, with a
  bulk modulus, for the FE models;
- :mod:`~pneumorph.materials.laws.filler`: the pressure-dependent filler of the 2D model.

The names to import are re-exported by :mod:`pneumorph.materials`.
"""

__all__: list[str] = []  # the names to import are re-exported by the parent package

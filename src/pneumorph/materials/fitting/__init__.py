"""Fitting hyperelastic models to test data.

- :mod:`~pneumorph.materials.fitting.fit`: least-squares fits of the closed-form models to one
  or several test modes at once;
- :mod:`~pneumorph.materials.fitting.ogden`: the multi-start fit of an Ogden model;
- :mod:`~pneumorph.materials.fitting.comparison`: several models fitted to the same data, side
  by side;
- :mod:`~pneumorph.materials.fitting.database`: the recipe that fits the library's silicones to
  their tensile tests (Soft Robotics Materials Database).

The names to import are re-exported by :mod:`pneumorph.materials`.
"""

__all__: list[str] = []  # the names to import are re-exported by the parent package

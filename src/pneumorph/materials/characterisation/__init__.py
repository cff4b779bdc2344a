"""Test data of rubber-like materials and what is read from it (appendix A, section 3.2.6).

- :mod:`~pneumorph.materials.characterisation.curves`: test curves as checked records;
- :mod:`~pneumorph.materials.characterisation.testdata`: reading stress-stretch files;
- :mod:`~pneumorph.materials.characterisation.datasets`: the data sets shipped with pneumorph;
- :mod:`~pneumorph.materials.characterisation.analyses`: Poisson's ratio, thermal expansion
  and the bilinear composite's transition from test data.

The names to import are re-exported by :mod:`pneumorph.materials`.
"""

__all__: list[str] = []  # the names to import are re-exported by the parent package

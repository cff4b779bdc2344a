"""Silicone materials: closed-form hyperelastic models, the library, fitting, characterisation.

The most used names are available here; the sub-packages hold the rest:
:mod:`~pneumorph.materials.laws` (closed-form models, FElupe materials, the 2D model's filler
law), :mod:`~pneumorph.materials.library` (material records, files and the built-in
library), :mod:`~pneumorph.materials.characterisation` (test data and what is read from it)
and :mod:`~pneumorph.materials.fitting` (fits of models to test data).

Examples
--------
>>> import pneumorph.materials as pm
>>> ms15 = pm.get("mold_star_15")
>>> round(ms15.shear_modulus, 4)
0.1314
>>> round(float(ms15.model.uniaxial(2.0)), 4)
0.1991
"""

from pneumorph.materials.characterisation.analyses import bilinear, characterise_bulk_modulus, thermal_expansion
from pneumorph.materials.characterisation.datasets import list_datasets, load_dataset, read_test_data
from pneumorph.materials.characterisation.testdata import TestCurve, TestData, read_curve
from pneumorph.materials.fitting.comparison import compare
from pneumorph.materials.fitting.fit import FitResult, fit
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.materials.laws.hyperelastic import (
    HyperelasticModel,
    MooneyRivlin,
    NeoHooke,
    Ogden,
    StabilityReport,
    Yeoh,
    drucker_stability,
    mode_stretches,
    ogden_marc_to_felupe,
)
from pneumorph.materials.library.builtin import get, get_filler, load_library, names, register_toml
from pneumorph.materials.library.material import Material

__all__ = [
    "FillerLaw",
    "FitResult",
    "HyperelasticModel",
    "Material",
    "MooneyRivlin",
    "NeoHooke",
    "Ogden",
    "StabilityReport",
    "TestCurve",
    "TestData",
    "Yeoh",
    "bilinear",
    "characterise_bulk_modulus",
    "compare",
    "drucker_stability",
    "fit",
    "get",
    "get_filler",
    "list_datasets",
    "load_dataset",
    "load_library",
    "mode_stretches",
    "names",
    "ogden_marc_to_felupe",
    "read_curve",
    "read_test_data",
    "register_toml",
    "thermal_expansion",
]

"""Silicone materials: closed-form hyperelastic models, the library, fitting, characterisation.

The most used names are available here; the sub-modules hold the rest:
:mod:`~pneumorph.materials.hyperelastic` (closed-form models),
:mod:`~pneumorph.materials.library` (the material library and user TOML files),
:mod:`~pneumorph.materials.filler` (the 2D model's pressure-dependent filler law),
:mod:`~pneumorph.materials.testdata` and :mod:`~pneumorph.materials.datasets` (test data),
:mod:`~pneumorph.materials.fitting`, :mod:`~pneumorph.materials.characterise`, and
:mod:`~pneumorph.materials.felupe_models` (FElupe constitutive materials; imports FElupe).

Examples
--------
>>> import pneumorph.materials as pm
>>> ms15 = pm.get("mold_star_15")
>>> round(ms15.shear_modulus, 4)
0.1314
>>> round(float(ms15.model.uniaxial(2.0)), 4)
0.1991
"""

from pneumorph.materials.characterise import bilinear, characterise_bulk_modulus, thermal_expansion
from pneumorph.materials.comparison import compare
from pneumorph.materials.datasets import list_datasets, load_dataset, read_test_data
from pneumorph.materials.filler import FillerLaw
from pneumorph.materials.fitting import FitResult, fit
from pneumorph.materials.hyperelastic import (
    MODES,
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
from pneumorph.materials.library import get, get_filler, load_library, names, register_toml
from pneumorph.materials.material import Material
from pneumorph.materials.testdata import TestCurve, TestData, read_curve

__all__ = [
    "MODES",
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

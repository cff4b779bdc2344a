"""Silicone materials: closed-form hyperelastic models, the library, fitting, characterisation."""

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

__all__ = [
    "MODES",
    "HyperelasticModel",
    "MooneyRivlin",
    "NeoHooke",
    "Ogden",
    "StabilityReport",
    "Yeoh",
    "drucker_stability",
    "mode_stretches",
    "ogden_marc_to_felupe",
]

"""Finite-element building blocks on FElupe: load stepping, cavity volume, fast kernels, the materials' laws
(the Ogden silicone, the Ogden matrix with crimped fibres)."""

from pneumorph.fem.cavity import cavity_volume
from pneumorph.fem.fibre import CrimpedFibreOgden
from pneumorph.fem.ogden import OgdenCompressible
from pneumorph.fem.stepping import RampStatistics, StepSettings, ramp

__all__ = ["CrimpedFibreOgden", "OgdenCompressible", "RampStatistics", "StepSettings", "cavity_volume", "ramp"]

"""Finite-element building blocks on FElupe: load stepping, cavity volume, fast kernels."""

from pneumorph.fem.cavity import cavity_volume
from pneumorph.fem.ogden import OgdenCompressible
from pneumorph.fem.stepping import RampStatistics, StepSettings, ramp

__all__ = ["OgdenCompressible", "RampStatistics", "StepSettings", "cavity_volume", "ramp"]

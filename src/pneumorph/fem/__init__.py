"""Finite-element building blocks on FElupe: load stepping, cavity volume."""

from pneumorph.fem.cavity import cavity_volume
from pneumorph.fem.stepping import RampStatistics, StepSettings, ramp

__all__ = ["RampStatistics", "StepSettings", "cavity_volume", "ramp"]

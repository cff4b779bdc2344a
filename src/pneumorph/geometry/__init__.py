"""Geometry: orientation vectors, the articulating unit and the actuator assembly."""

from pneumorph.geometry.orientation import mirror, parse_orientation
from pneumorph.geometry.unit import UnitSpec

__all__ = ["UnitSpec", "mirror", "parse_orientation"]

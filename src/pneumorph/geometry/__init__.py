"""Geometry: orientation vectors, the articulating unit and the actuator assembly."""

from pneumorph.geometry.orientation import mirror, parse_orientation

__all__ = ["mirror", "parse_orientation"]

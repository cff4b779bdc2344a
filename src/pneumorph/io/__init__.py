"""Exports for other tools: ParaView (VTK) files and provenance records."""

from pneumorph.io.provenance import provenance
from pneumorph.io.vtk import write_vtk_series

__all__ = ["provenance", "write_vtk_series"]

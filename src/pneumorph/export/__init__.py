"""Export: the actuator's parts as watertight meshes (STL), its casting mould, and solver decks."""

# Solver decks (pneumorph.export.calculix) and CalculiX's run and results (pneumorph.export.ccx).
from pneumorph.export.calculix import calculix_deck, write_calculix_deck
from pneumorph.export.ccx import read_dat_displacements, read_frd_displacements, run_calculix, tip_positions

# Parts and moulds (pneumorph.export.parts, .moulds, .figures).
from pneumorph.export.figures import plot_mould
from pneumorph.export.moulds import Mould, MouldCheck, MouldSpec, casting_mould
from pneumorph.export.parts import (
    BaseBlock,
    LayerPiece,
    actuator_parts,
    actuator_solids,
    check_materials,
    layer_pieces,
    write_stl,
)

__all__ = [
    # parts and moulds
    "BaseBlock",
    "LayerPiece",
    "Mould",
    "MouldCheck",
    "MouldSpec",
    "actuator_parts",
    "actuator_solids",
    "casting_mould",
    "check_materials",
    "layer_pieces",
    "plot_mould",
    "write_stl",
]

# solver decks
__all__ += [
    "calculix_deck",
    "read_dat_displacements",
    "read_frd_displacements",
    "run_calculix",
    "tip_positions",
    "write_calculix_deck",
]

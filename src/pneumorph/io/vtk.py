"""ParaView files of a solved actuator: one VTU per reported pressure and a PVD series."""

from __future__ import annotations

import base64
import json
import sys
import zlib
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import NDArray

from pneumorph import __version__

_REGION_IDS = {"body": 0, "layer": 1, "filler": 2}

#: VTK's number of each cell type (by FElupe's and meshio's names); these types' nodes are in VTK's order
VTK_CELL_TYPES = {"line": 3, "triangle": 5, "quad": 9, "tetra": 10, "hexahedron": 12, "triangle6": 22, "quad8": 23,
                  "tetra10": 24, "hexahedron20": 25, "quad9": 28, "hexahedron27": 29}
#: bytes of an array compressed as one zlib block (VTK's XML format, as meshio writes it)
_BLOCK = 32768
_VTU_TYPES = {np.dtype(np.float64): "Float64", np.dtype(np.int64): "Int64", np.dtype(np.int32): "Int32"}


def region_ids(names: Any) -> dict[str, int]:
    """The ``region`` cell value of every region: 0 body, 1 stiff layer, 2 filler, then the others (bottom walls of
    other materials, a base block) from 3 in name order.

    >>> region_ids(["layer", "body", "bottom:ecoflex_00_50", "base"])
    {'body': 0, 'layer': 1, 'base': 3, 'bottom:ecoflex_00_50': 4}
    """
    others = sorted(n for n in names if n not in _REGION_IDS)
    return {**{n: i for n, i in _REGION_IDS.items() if n in names}, **{n: 3 + k for k, n in enumerate(others)}}


def _contact_forces(contact: Any, k: int, npoints: int) -> dict[str, Any]:
    """``{"contact_force": (p, 3), "contact_pressure": (p,)}`` of level ``k`` of a response's contact record, or
    nothing (no obstacles)."""
    if not contact or k >= len(contact["levels"]):
        return {}
    field = np.zeros((npoints, 3))
    pressure = np.zeros(npoints)
    for entry in contact["levels"][k]["obstacles"]:
        if entry["nodes_in_contact"]:
            forces = np.asarray(entry["node_forces_n"], dtype=float)
            field[entry["nodes_in_contact"], : forces.shape[1]] += forces
            pressure[entry["nodes_in_contact"]] += entry.get("node_pressures_kpa", 0.0)
    return {"contact_force": field, "contact_pressure": pressure}


def write_vtk_series(solution: Any, folder: str | Path, stem: str = "actuator",
                     meta: dict[str, Any] | None = None) -> Path:
    """Write ``<stem>_<k>.vtu`` for every converged level and ``<stem>.pvd`` to open them all.

    Each VTU holds the undeformed points with the point data ``displacement`` (use
    ParaView's *Warp By Vector*) and the cell data ``region`` (:func:`region_ids`: 0 body,
    1 stiff layer, 2 filler, then the others; the PVD's comment names them). The PVD's time
    value is the pressure in kPa. A solve with obstacles (:mod:`pneumorph.models.fe.obstacles`) adds the point data
    ``contact_force``: the force each surface node exerts on the obstacles (N, as the response reports it), and
    ``contact_pressure``: that force over the node's share of the surface (kPa). The files are VTK's XML format,
    binary in zlib blocks, as meshio writes them; the mesh and its regions are encoded once for every file.

    Parameters
    ----------
    solution : pneumorph.models.fe.Solution
        A solved design.
    folder : str or Path
        Output folder (created).
    stem : str
        File name stem.
    meta : dict, optional
        Provenance, written as a JSON comment into the PVD file.

    Returns
    -------
    Path
        The PVD file.
    """
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    mesh = solution.mesh
    points = np.zeros((len(mesh.points), 3))
    points[:, : mesh.dim] = mesh.points
    region = np.empty(len(mesh.cells), dtype=np.int32)
    ids = region_ids(list(mesh.regions))
    for name, idx in mesh.regions.items():
        region[idx] = ids[name]
    # the mesh and its regions, the same in every file: encoded once
    head, tail = _vtu_frame(points, np.asarray(mesh.cells), mesh.cell_type, {"region": region})
    pressures = solution.response.pressures
    entries = []
    for k, u in enumerate(solution.displacements):
        if np.isnan(u).any():
            break
        disp = np.zeros_like(points)
        disp[:, : mesh.dim] = u
        name = f"{stem}_{k:02d}.vtu"
        data = {"displacement": disp, **_contact_forces(solution.response.metadata.get("contact"), k, len(points))}
        point_data = "".join(_data_array(key, value) for key, value in data.items())
        (out / name).write_text(f"{head}<PointData>\n{point_data}</PointData>\n{tail}", encoding="ascii")
        entries.append(f'    <DataSet timestep="{pressures[k] * 1e3:.6g}" file={quoteattr(name)}/>')
    comment = json.dumps({"regions": ids, **(meta or {})}, default=str).replace("--", "- -")
    pvd = out / f"{stem}.pvd"
    pvd.write_text(
        '<?xml version="1.0"?>\n'
        f"<!-- pneumorph: time = pressure in kPa; {comment} -->\n"
        '<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
        + "\n".join(entries)
        + "\n  </Collection>\n</VTKFile>\n",
        encoding="utf-8",
    )
    return pvd


def _data_array(name: str, data: NDArray[Any]) -> str:
    """One ``DataArray`` of a VTU file: binary, in zlib blocks of :data:`_BLOCK` bytes, after its header (UInt32
    block count, block size, last block's size, every compressed block's size), each base64-encoded on its own."""
    raw = np.ascontiguousarray(data).tobytes()
    blocks = [zlib.compress(raw[i : i + _BLOCK]) for i in range(0, len(raw), _BLOCK)]
    header = np.array([len(blocks), _BLOCK, len(raw) - (len(blocks) - 1) * _BLOCK, *map(len, blocks)], dtype=np.uint32)
    components = f' NumberOfComponents="{data.shape[1]}"' if data.ndim == 2 else ""
    return (f'<DataArray type="{_VTU_TYPES[data.dtype]}" Name="{name}"{components} format="binary">\n'
            f"{base64.b64encode(header.tobytes()).decode()}{base64.b64encode(b''.join(blocks)).decode()}\n"
            "</DataArray>\n")


def _vtu_frame(points: NDArray[Any], cells: NDArray[Any], cell_type: str,
               cell_data: dict[str, NDArray[Any]]) -> tuple[str, str]:
    """A VTU file of an unstructured grid (VTK's XML format, as meshio writes it) up to its point data, and after it.

    >>> head, tail = _vtu_frame(np.zeros((4, 3)), np.array([[0, 1, 2, 3]]), "quad", {"region": np.zeros(1, "i4")})
    >>> head.splitlines()[4], tail.splitlines()[-1]
    ('<Piece NumberOfPoints="4" NumberOfCells="1">', '</VTKFile>')
    """
    byte_order = "LittleEndian" if sys.byteorder == "little" else "BigEndian"
    connectivity = cells.reshape(-1)
    offsets = cells.shape[1] * np.arange(1, len(cells) + 1, dtype=connectivity.dtype)
    head = ('<?xml version="1.0"?>\n'
            f'<VTKFile type="UnstructuredGrid" version="0.1" byte_order="{byte_order}" '
            'compressor="vtkZLibDataCompressor">\n'
            f"<!--This file was written by pneumorph {__version__}-->\n"
            f'<UnstructuredGrid>\n<Piece NumberOfPoints="{len(points)}" NumberOfCells="{len(cells)}">\n'
            f"<Points>\n{_data_array('Points', points)}</Points>\n"
            f"<Cells>\n{_data_array('connectivity', connectivity)}{_data_array('offsets', offsets)}"
            f"{_data_array('types', np.full(len(cells), VTK_CELL_TYPES[cell_type], dtype=np.int64))}</Cells>\n")
    arrays = "".join(_data_array(name, values) for name, values in cell_data.items())
    return head, f"<CellData>\n{arrays}</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"

"""ParaView files of a solved actuator: one VTU per reported pressure and a PVD series."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

_REGION_IDS = {"body": 0, "layer": 1, "filler": 2}


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
    ``contact_pressure``: that force over the node's share of the surface (kPa).

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
    import meshio

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    mesh = solution.mesh
    points = np.zeros((len(mesh.points), 3))
    points[:, : mesh.dim] = mesh.points
    region = np.empty(len(mesh.cells), dtype=np.int32)
    ids = region_ids(list(mesh.regions))
    for name, idx in mesh.regions.items():
        region[idx] = ids[name]
    pressures = solution.response.pressures
    entries = []
    for k, u in enumerate(solution.displacements):
        if np.isnan(u).any():
            break
        disp = np.zeros_like(points)
        disp[:, : mesh.dim] = u
        name = f"{stem}_{k:02d}.vtu"
        data = {"displacement": disp, **_contact_forces(solution.response.metadata.get("contact"), k, len(points))}
        meshio.write(
            out / name,
            meshio.Mesh(points, [(mesh.cell_type, mesh.cells)], point_data=data, cell_data={"region": [region]}),
        )
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

"""The VTU files of a solved actuator are VTK's XML format as meshio writes it, byte for byte but for the line that
names the writer: the mesh and its regions encoded once for the series, each level's fields in its own file."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import meshio
import numpy as np
import pytest

from pneumorph import __version__
from pneumorph.io import write_vtk_series
from pneumorph.io.vtk import region_ids


def _solution(dim: int, cell_type: str, nodes: int, contact: bool) -> SimpleNamespace:
    """A solved design's shape: random points and cells (more than one compressed block of points), three
    levels, the last not converged."""
    rng = np.random.default_rng(7)
    npoints, ncells = 3000, 400
    cells = rng.integers(0, npoints, size=(ncells, nodes))
    regions = {"body": np.arange(0, 300), "layer": np.arange(300, 380), "bottom:x": np.arange(380, ncells)}
    mesh = SimpleNamespace(points=rng.uniform(0, 50, (npoints, dim)), cells=cells, cell_type=cell_type, dim=dim,
                           regions=regions)
    displacements = rng.normal(size=(3, npoints, dim))
    displacements[2] = np.nan
    metadata = {}
    if contact:
        level = {"obstacles": [{"nodes_in_contact": [3, 5], "node_forces_n": [[0.1] * dim, [0.2] * dim],
                                "node_pressures_kpa": [1.0, 2.0]}]}
        metadata["contact"] = {"levels": [level, level, level]}
    response = SimpleNamespace(pressures=np.array([0.01, 0.02, 0.03]), metadata=metadata)
    return SimpleNamespace(mesh=mesh, displacements=displacements, response=response)


@pytest.mark.parametrize(("dim", "cell_type", "nodes", "contact"),
                         [(2, "quad8", 8, False), (3, "hexahedron20", 20, True), (3, "hexahedron", 8, False)])
def test_every_vtu_is_meshios_but_for_the_writers_name(tmp_path: Path, dim: int, cell_type: str, nodes: int,
                                                       contact: bool) -> None:
    solution = _solution(dim, cell_type, nodes, contact)
    write_vtk_series(solution, tmp_path / "vtk", meta={"design": "01"})
    files = sorted((tmp_path / "vtk").glob("*.vtu"))
    assert [f.name for f in files] == ["actuator_00.vtu", "actuator_01.vtu"]  # up to the last converged level
    mesh = solution.mesh
    points = np.zeros((len(mesh.points), 3))
    points[:, :dim] = mesh.points
    ids = region_ids(list(mesh.regions))
    region = np.empty(len(mesh.cells), dtype=np.int32)
    for name, idx in mesh.regions.items():
        region[idx] = ids[name]
    for k, path in enumerate(files):
        disp = np.zeros_like(points)
        disp[:, :dim] = solution.displacements[k]
        data = {"displacement": disp}
        if contact:
            force, pressure = np.zeros_like(points), np.zeros(len(points))
            force[[3, 5], :dim] = [[0.1] * dim, [0.2] * dim]
            pressure[[3, 5]] = [1.0, 2.0]
            data |= {"contact_force": force, "contact_pressure": pressure}
        reference = tmp_path / f"meshio_{k}.vtu"
        meshio.write(reference, meshio.Mesh(points, [(cell_type, mesh.cells)], point_data=data,
                                            cell_data={"region": [region]}))
        expected = reference.read_text().replace(f"<!--This file was created by meshio v{meshio.__version__}-->",
                                                 f"<!--This file was written by pneumorph {__version__}-->")
        assert path.read_text() == expected
        back = meshio.read(path)
        np.testing.assert_array_equal(back.cells_dict[cell_type], mesh.cells)
        np.testing.assert_array_equal(back.point_data["displacement"], disp)
        np.testing.assert_array_equal(back.cell_data["region"][0], region)

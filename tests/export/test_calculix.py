"""The CalculiX/Abaqus deck of the 3D model: its text always, CalculiX's answer where ``ccx`` is installed.

The deck checks need no CalculiX: node and element counts and connectivity equal the
model's mesh, the C3D20 node order and face numbering are derived and checked, the loaded
faces are exactly those pneumorph's pressure acts on, and the materials are converted as
the module says. The comparison runs a 1-unit deck in ``ccx`` (about 10 s) and compares
the tip displacement with :meth:`Full3D.evaluate`.
"""

from __future__ import annotations

import dataclasses
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import (
    DataFormatError,
    GeometryError,
    OrientationError,
    OutputPathError,
    SettingsError,
)
from pneumorph.export.calculix import (
    C3D20_FACES,
    C3D20_NATURAL,
    c3d20_permutation,
    calculix_deck,
    calculix_mesh,
    cavity_faces,
    check_element_order,
    write_calculix_deck,
)
from pneumorph.export.ccx import (
    NodalDisplacements,
    read_dat_displacements,
    read_frd_displacements,
    run_calculix,
    tip_positions,
)
from pneumorph.fem import StepSettings
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D

#: 20 kPa in 4 levels: the notes' pressure, few levels to keep ccx short
RAMP = RampSpec(pressure=0.02, steps=StepSettings(increments=4, substeps=1, max_iterations=25))


def parse_deck(text: str) -> list[tuple[str, list[str]]]:
    """Keyword blocks of a deck, in order: (keyword line, data lines), comments dropped."""
    blocks: list[tuple[str, list[str]]] = []
    for line in text.splitlines():
        if line.startswith("**") or not line.strip():
            continue
        if line.startswith("*"):
            blocks.append((line, []))
        else:
            blocks[-1][1].append(line)
    return blocks


def block(blocks, prefix: str) -> list[str]:
    found = [data for key, data in blocks if key.upper().startswith(prefix.upper())]
    assert len(found) == 1, f"{prefix}: {len(found)} blocks"
    return found[0]


def ids(lines: list[str]) -> list[int]:
    return [int(v) for line in lines for v in line.split(",") if v.strip()]


def elements(lines: list[str], n_nodes: int) -> np.ndarray:
    """C3D20 connectivity (1-based) from *ELEMENT lines, continuation lines joined."""
    flat = ids(lines)
    return np.asarray(flat).reshape(-1, n_nodes + 1)


@pytest.fixture(scope="module")
def one_unit():
    model = Full3D(1, ramp_spec=RAMP)
    text = calculix_deck(model, "0")
    return model, text, parse_deck(text)


# -- node order and faces -------------------------------------------------------------------

def test_felupe_hexahedron20_is_c3d20_node_for_node() -> None:
    import felupe as fem

    perm = c3d20_permutation()
    assert perm.tolist() == list(range(20))
    assert np.array_equal(np.asarray(fem.QuadraticHexahedron().points)[perm], np.asarray(C3D20_NATURAL, float))


def test_face_table_follows_the_natural_coordinates_and_points_into_the_element() -> None:
    natural = np.asarray(C3D20_NATURAL, dtype=float)
    planes = {1: (2, -1), 2: (2, 1), 3: (1, -1), 4: (0, 1), 5: (1, 1), 6: (0, -1)}
    for face, nodes in C3D20_FACES.items():
        axis, side = planes[face]
        assert set(nodes) == set(np.flatnonzero(natural[:, axis] == side).tolist())
        a, b, _, d = natural[list(nodes[:4])]
        inward = np.cross(b - a, d - a)  # the manuals list each face with its normal inwards
        assert np.dot(inward, -side * np.eye(3)[axis]) > 0  # towards the centre, xi = eta = zeta = 0
        # midside nodes between consecutive corners
        corners = nodes[:4]
        for k in range(4):
            mid = natural[nodes[4 + k]]
            assert np.allclose(mid, (natural[corners[k]] + natural[corners[(k + 1) % 4]]) / 2)


def test_a_known_element_passes_and_a_mirrored_one_is_refused() -> None:
    import felupe as fem

    mesh = fem.Cube(n=2).add_midpoints_edges()  # one hexahedron20 on the unit cube
    cells = np.asarray(mesh.cells)[:, c3d20_permutation()]
    check_element_order(mesh.points, cells)
    # its corners in C3D20 order: node 1 at the origin, 2 along x, 4 along y, 5 along z
    x = np.asarray(mesh.points)[cells[0]]
    assert np.allclose(x[[0, 1, 3, 4]], [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    mirrored = cells[:, [4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11, 16, 17, 18, 19]]
    with pytest.raises(GeometryError, match="element 1: a non-positive Jacobian"):
        check_element_order(mesh.points, mirrored)
    swapped = cells.copy()
    swapped[:, [8, 9]] = swapped[:, [9, 8]]
    with pytest.raises(GeometryError, match="node 9 is not the middle"):
        check_element_order(mesh.points, swapped)


def test_cavity_faces_of_one_element() -> None:
    cells = np.arange(20)[None]
    for face, nodes in C3D20_FACES.items():
        mask = np.zeros(20, dtype=bool)
        mask[list(nodes)] = True
        e, f = cavity_faces(cells, mask)
        assert e.tolist() == [0] and f.tolist() == [face]


# -- the deck's text ----------------------------------------------------------------------

def test_mesh_nodes_and_elements_equal_the_models(one_unit) -> None:
    model, _, blocks = one_unit
    mesh, _, _ = model.build("0")
    node_lines = next(data for key, data in blocks if key == "*NODE")
    nodes = np.array([[float(v) for v in line.split(",")] for line in node_lines])
    assert len(nodes) == len(mesh.points) == 1438
    assert nodes[:, 0].tolist() == list(range(1, len(mesh.points) + 1))
    assert np.allclose(nodes[:, 1:], mesh.points, rtol=0, atol=1e-12)
    conn = elements(block(blocks, "*ELEMENT, TYPE=C3D20"), 20)
    assert conn.shape == (len(mesh.cells), 21) == (232, 21)
    assert conn[:, 0].tolist() == list(range(1, len(mesh.cells) + 1))
    assert np.array_equal(conn[:, 1:] - 1, mesh.cells)  # the identity permutation, node for node
    check_element_order(nodes[:, 1:], conn[:, 1:] - 1)
    # element sets: one per material, together all elements once
    body, layer = ids(block(blocks, "*ELSET, ELSET=BODY")), ids(block(blocks, "*ELSET, ELSET=LAYER"))
    assert np.array_equal(np.asarray(body) - 1, mesh.regions["body"])
    assert np.array_equal(np.asarray(layer) - 1, mesh.regions["layer"])
    assert sorted(body + layer) == list(range(1, len(mesh.cells) + 1))


def test_boundary_sets_and_tip(one_unit) -> None:
    model, _, blocks = one_unit
    mesh = calculix_mesh(model, "0")
    base = np.asarray(ids(block(blocks, "*NSET, NSET=BASE"))) - 1
    sym = np.asarray(ids(block(blocks, "*NSET, NSET=SYMMETRY"))) - 1
    tip = np.asarray(ids(block(blocks, "*NSET, NSET=TIP"))) - 1
    assert np.allclose(mesh.points[base, 0], 0.0) and len(base) == mesh.base_points.sum()
    assert np.allclose(mesh.points[sym, 2], model.unit.width / 2) and len(sym) == mesh.symmetry_points.sum()
    assert np.array_equal(tip, mesh.end_points)
    assert block(blocks, "*BOUNDARY") == ["BASE, 1, 3, 0.", "SYMMETRY, 3, 3, 0."]


def test_loaded_faces_are_pneumorphs_pressure_faces(one_unit) -> None:
    """Every (element, Pn) face holds the nodes of one face FElupe's pressure acts on, and all of them."""
    model, _, blocks = one_unit
    mesh, body, _ = model.build("0")
    felupe_faces = {frozenset(f.tolist()) for f in body.walls[0].region.mesh.cells_faces}
    conn = elements(block(blocks, "*ELEMENT, TYPE=C3D20"), 20)[:, 1:] - 1
    loads = block(blocks, "*DLOAD")
    deck_faces = set()
    x0, x1, y0, y1 = model.unit.cavity
    for line in loads:
        e, face, value = (v.strip() for v in line.split(","))
        assert re.fullmatch(r"P[1-6]", face) and float(value) == pytest.approx(20e3)  # 20 kPa in Pa
        nodes = conn[int(e) - 1, list(C3D20_FACES[int(face[1])])]
        deck_faces.add(frozenset(nodes.tolist()))
        # the face lies on the cavity's wall, its element outside the cavity: the
        # element's outward normal points into the cavity, so +P inflates it
        centre = mesh.points[nodes].mean(axis=0)
        element_centre = mesh.points[conn[int(e) - 1]].mean(axis=0)
        inside = (x0 < element_centre[0] < x1) and (y0 < element_centre[1] < y1)
        assert not (inside and element_centre[2] > model.unit.side_wall)
        assert x0 - 1e-9 <= centre[0] <= x1 + 1e-9 and y0 - 1e-9 <= centre[1] <= y1 + 1e-9
    assert deck_faces == felupe_faces and len(loads) == len(felupe_faces)
    # the loaded area per outward direction is the cavity's (half) walls: floor and
    # ceiling, the two end walls, the side wall; nothing on the open symmetry plane
    area: dict[tuple[int, ...], float] = {}
    for line in loads:
        e, face, _ = (v.strip() for v in line.split(","))
        corners = mesh.points[conn[int(e) - 1, list(C3D20_FACES[int(face[1])][:4])]]
        inward = np.cross(corners[1] - corners[0], corners[3] - corners[0])  # parallelogram faces here
        key = tuple(np.round(-inward / np.linalg.norm(inward)).astype(int).tolist())
        area[key] = area.get(key, 0.0) + float(np.linalg.norm(inward))
    length, height = x1 - x0, y1 - y0
    depth = model.unit.width / 2 - model.unit.side_wall
    expected = {(0, 1, 0): length * depth, (0, -1, 0): length * depth, (1, 0, 0): height * depth,
                (-1, 0, 0): height * depth, (0, 0, 1): length * height}
    assert area.keys() == expected.keys()
    for key, value in expected.items():
        assert area[key] == pytest.approx(value, rel=1e-12), key


def test_materials_in_calculix_convention(one_unit) -> None:
    model, text, blocks = one_unit
    assert text.count("*MATERIAL") == 2 and text.count("*HYPERELASTIC, OGDEN, N=3") == 2
    for role, material in (("BODY", model.body), ("LAYER", model.layer)):
        name = f"{role}_{material.name.upper()}"
        index = next(i for i, (key, _) in enumerate(blocks) if key == f"*MATERIAL, NAME={name}")
        _, data = blocks[index + 1]
        values = [float(v) for line in data for v in line.split(",")]
        mu, alpha, d = values[0:6:2], values[1:6:2], values[6:]
        assert alpha == pytest.approx(material.model.alpha, rel=1e-14)
        pairs = zip(material.model.mu, material.model.alpha, strict=True)
        assert mu == pytest.approx([m * a / 2 * 1e6 for m, a in pairs])
        assert sum(mu) == pytest.approx(material.shear_modulus * 1e6)  # CalculiX's mu0 = sum mu_i
        assert d == pytest.approx([2 / (material.bulk_modulus.value * 1e6), 1e30, 1e30])
        assert (f"*SOLID SECTION, ELSET={role}, MATERIAL={name}", []) in blocks


def test_step_levels_and_outputs(one_unit) -> None:
    _, text, blocks = one_unit
    assert "*STEP, NLGEOM, INC=10000" in text
    static = block(blocks, "*STATIC")
    # a twentieth of the first level first, then at most one level per increment
    assert [float(v) for v in static[0].split(",")] == pytest.approx([0.0125, 1.0, 0.25e-6, 0.25])
    # residual against a fixed force: 0.005 x 20000 = 100 micronewtons; up to 10 cut-backs
    assert block(blocks, "*CONTROLS, PARAMETERS=FIELD") == ["0.005, 0.01, , 20000"]
    assert block(blocks, "*CONTROLS, PARAMETERS=TIME INCREMENTATION") == ["4, 8, 9, 16, 10, 4, 12, 10"]
    assert [float(v) for v in block(blocks, "*TIME POINTS")[0].split(",")] == [0.25, 0.5, 0.75, 1.0]
    assert block(blocks, "*NODE PRINT, NSET=TIP, TIME POINTS=LEVELS") == ["U"]
    assert block(blocks, "*NODE FILE, TIME POINTS=LEVELS") == ["U"]
    assert block(blocks, "*AMPLITUDE, NAME=RAMP") == ["0., 0., 1., 1."]
    assert text.rstrip().endswith("*END STEP")


def test_write_is_atomic_and_errors_are_specific(tmp_path: Path) -> None:
    model = Full3D(2, ramp_spec=RAMP)
    path = write_calculix_deck(model, "01", tmp_path / "a.inp")
    assert path.read_text() == calculix_deck(model, "01")
    assert [p.name for p in tmp_path.iterdir()] == ["a.inp"]  # no temporary left behind
    with pytest.raises(OrientationError):
        calculix_deck(model, "012")
    with pytest.raises(OrientationError):
        calculix_deck(model, "0")
    with pytest.raises(SettingsError, match="3D model"):
        calculix_deck(Reduced2D(2, ramp_spec=RAMP), "01")
    with pytest.raises(SettingsError, match="gravity"):
        calculix_deck(Full3D(2, ramp_spec=RAMP, gravity="hanging"), "01")
    with pytest.raises(SettingsError, match="residual_force"):
        calculix_deck(model, "01", residual_force=0.0)
    with pytest.raises(OutputPathError):
        write_calculix_deck(model, "01", tmp_path)
    with pytest.raises(DataFormatError):
        read_dat_displacements(tmp_path / "missing.dat")
    bad = tmp_path / "bad.dat"
    bad.write_text(" displacements (vx,vy,vz) for set TIP and time  0.1E+00\n\n  1 x y z\n")
    with pytest.raises(DataFormatError, match="row 3"):
        read_dat_displacements(bad)
    mesh = calculix_mesh(model, "01")
    with pytest.raises(DataFormatError, match="lack end-face node"):
        tip_positions([NodalDisplacements(1.0, np.array([1]), np.zeros((1, 3)))], mesh)


def test_full_model_has_no_symmetry_plane() -> None:
    text = calculix_deck(Full3D(1, ramp_spec=RAMP, half=False), "1")
    assert "SYMMETRY" not in text and "BASE, 1, 3, 0." in text


# -- CalculiX against pneumorph -------------------------------------------------------------

def _with_bulk_factor(model: Full3D, factor: float) -> Full3D:
    for role in ("body", "layer"):
        material = getattr(model, role)
        bulk = dataclasses.replace(material.bulk_modulus, value=material.bulk_modulus.value * factor)
        setattr(model, role, dataclasses.replace(material, bulk_modulus=bulk))
    return model


def _relative_tip_difference(model: Full3D, folder: Path) -> np.ndarray:
    """(|u_ccx| - |u_pneumorph|) / |u_pneumorph| of the tip displacement at every level."""
    design = "0"
    ours = model.evaluate(design)
    theirs = run_calculix(model, design, folder, threads=1, timeout=120, full_output=True)
    assert np.allclose(theirs.pressures, ours.pressures)
    # the .frd file holds the same displacements as the .dat file (to its 6 digits)
    frd = read_frd_displacements(theirs.deck.with_suffix(".frd"))
    times, tip = tip_positions(frd, calculix_mesh(model, design))
    assert np.allclose(times, model.ramp.steps.levels()) and np.allclose(tip, theirs.tip, rtol=0, atol=1e-5)
    x0 = calculix_mesh(model, design)
    x0 = x0.points[x0.end_points][:, :2].mean(axis=0)
    u_ours, u_theirs = ours.tip - x0, theirs.tip - x0
    # same direction: the difference is in the magnitude
    cos = np.sum(u_ours * u_theirs, axis=1) / np.linalg.norm(u_ours, axis=1) / np.linalg.norm(u_theirs, axis=1)
    assert np.all(cos > 1 - 1e-4)
    return (np.linalg.norm(u_theirs, axis=1) - np.linalg.norm(u_ours, axis=1)) / np.linalg.norm(u_ours, axis=1)


@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed (Debian: calculix-ccx)")
def test_calculix_tip_agrees_within_the_volumetric_difference(tmp_path: Path) -> None:
    """1 unit, 20 kPa in 4 levels (ccx 2.20, 2 cores, about 8 s per run).

    Measured: CalculiX's tip displacement is 4.31 % smaller at 20 kPa (0.89, 1.83, 2.93,
    4.31 % at the four levels; 4.29 % with 10 levels; 4.94 % for "01", in line with the
    notes' 4.9-5.2 % for 2-4 units): its volumetric term K (J-1) is stiffer than Eq 2.12's
    3K (J^(-1/3) - J^(-2/3)) at J > 1. With the bulk moduli x100 in both codes the
    volumetric terms nearly coincide and the tips agree to 0.016 % (measured) - the deck's
    mesh, loads, supports and deviatoric Ogden terms are pneumorph's.
    """
    diff = _relative_tip_difference(Full3D(1, ramp_spec=RAMP), tmp_path / "k1")
    assert np.all(diff < 0)  # CalculiX is the stiffer one, at every level
    assert np.all(np.diff(diff) < 0)  # and more so as J grows
    assert -0.055 < diff[-1] < -0.035  # measured -4.31 %; the notes: 4.9-5.2 % for 2-4 units
    stiff = _relative_tip_difference(_with_bulk_factor(Full3D(1, ramp_spec=RAMP), 100.0), tmp_path / "k100")
    assert np.all(np.abs(stiff) < 1e-3)  # measured 0.016 % at 20 kPa; 0.1 % allows solver tolerances


@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed (Debian: calculix-ccx)")
def test_calculix_solves_a_sideways_unit_as_pneumorph_does(tmp_path: Path) -> None:
    """The deck of a sideways unit (`l` of the spatial library: full width, no symmetry plane), 20 kPa in 4 levels.

    Measured (ccx 2.20, 2 cores, 29 s): the tip moves the same way in space (cosine above 0.99999 at every level) and
    4.65 % less at 20 kPa (`al`: 5.39 %), the volumetric term's difference the planar decks show too (4.3 % for one
    planar unit).
    """
    from pneumorph.models.factory import make_model

    model = make_model(1, {"fidelity": "3d", "library": "spatial", "pressure_kpa": 20, "increments": 4})
    ours = model.evaluate("l")
    theirs = run_calculix(model, "l", tmp_path, threads=1, timeout=300)
    assert theirs.tip.shape == ours.tip.shape == (4, 3)
    u_ours, u_theirs = ours.tip - ours.reference_tip, theirs.tip - ours.reference_tip
    assert abs(u_ours[-1, 2]) > 0.3  # it leaves the plane: 0.43 mm across the width at 20 kPa
    cos = np.sum(u_ours * u_theirs, axis=1) / np.linalg.norm(u_ours, axis=1) / np.linalg.norm(u_theirs, axis=1)
    assert np.all(cos > 1 - 1e-4)
    diff = np.linalg.norm(u_theirs, axis=1) / np.linalg.norm(u_ours, axis=1) - 1
    assert np.all(diff < 0) and -0.06 < diff[-1] < -0.035

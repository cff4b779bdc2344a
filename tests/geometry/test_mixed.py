"""Meshes of mixed designs: one-type meshes as the reference commit made them, exact volumes, conforming interfaces."""

from __future__ import annotations

import shutil
import subprocess
import sys
import types
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from pneumorph.errors import GeometryError, OrientationError
from pneumorph.geometry.alphabet import parse_design
from pneumorph.geometry.assembly import ActuatorMesh, assemble, unit_starts
from pneumorph.geometry.features import PHYSICAL_PASSAGE, BaseBlock
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.geometry.unit import UnitSpec

#: the reference commit for one-type meshes (without unit libraries): its assemble is what they must equal
BEFORE_LIBRARIES = "137ba49"
REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def legacy() -> Any:
    """``pneumorph.geometry.assembly`` as it was at :data:`BEFORE_LIBRARIES`, read from git."""
    if shutil.which("git") is None or not (REPO / ".git").exists():
        pytest.skip("needs the git history of the repository")
    done = subprocess.run(["git", "show", f"{BEFORE_LIBRARIES}:src/pneumorph/geometry/assembly.py"], cwd=REPO,
                          capture_output=True, text=True)
    if done.returncode != 0:
        pytest.skip(f"commit {BEFORE_LIBRARIES} is not in this clone")
    module = types.ModuleType("_assembly_before_libraries")
    sys.modules[module.__name__] = module  # dataclasses look their module up
    try:
        exec(compile(done.stdout, module.__name__, "exec"), module.__dict__)
        yield module
    finally:
        del sys.modules[module.__name__]


def _assert_same_mesh(a: ActuatorMesh, b: ActuatorMesh) -> None:
    for key in ("points", "cells", "cavity_points", "tracked", "end_points", "base_points"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key
    assert a.cell_type == b.cell_type and a.orientation == b.orientation and a.spec == b.spec
    assert sorted(a.regions) == sorted(b.regions)
    assert all(np.array_equal(a.regions[r], b.regions[r]) for r in a.regions)
    if a.symmetry_points is None:
        assert b.symmetry_points is None
    else:
        assert b.symmetry_points is not None and np.array_equal(a.symmetry_points, b.symmetry_points)


CASES = [
    (UnitSpec(), "0110", {"dim": 2}),
    (UnitSpec(), "010011001110001", {"dim": 2}),
    (UnitSpec(), "010011", {"dim": 3, "half": True}),
    (UnitSpec(), "01", {"dim": 3}),
    (UnitSpec(), "0110", {"dim": 3, "passage": PHYSICAL_PASSAGE}),
    (UnitSpec(), "01", {"dim": 3, "half": True, "base": BaseBlock(length=6.0, margin=1.5)}),
    (UnitSpec(), "01", {"dim": 2, "base": BaseBlock(length=6.0)}),
    (UnitSpec(slit_width=1.0, slit_depth=6.0, end_cap=3.0), "0010", {"dim": 2}),
    (UnitSpec(element_order=1, element_size=0.75), "01", {"dim": 2}),
    (UnitSpec(pitch=10.3, end_wall=2.9), "0101101", {"dim": 2}),
]


@pytest.mark.parametrize(("spec", "design", "options"), CASES)
def test_todays_designs_mesh_exactly_as_before(legacy: Any, spec: UnitSpec, design: str,
                                               options: dict[str, Any]) -> None:
    before = legacy.assemble(spec, design, **options)
    _assert_same_mesh(before, assemble(spec, design, **options))
    _assert_same_mesh(before, assemble(UnitLibrary.single(spec), design, **options))
    if spec == UnitSpec():  # the built-in library's first type is today's unit, in any design of it
        over = assemble(builtin_library(), design, **options)
        _assert_same_mesh(before, over)
        assert over.design == design.translate(str.maketrans("01", "aA"))


def _measure(mesh: ActuatorMesh, cells: np.ndarray | None = None) -> float:
    """Area (2D) or volume (3D) of cells by Gauss quadrature; every element must be valid."""
    import felupe as fem

    chosen = mesh.cells if cells is None else mesh.cells[cells]
    sub = fem.Mesh(mesh.points, chosen, mesh.cell_type)
    region = fem.RegionQuadraticQuad(sub) if mesh.dim == 2 else fem.RegionQuadraticHexahedron(sub)
    assert (region.dV > 0).all(), "an inverted or degenerate element"
    return float(region.dV.sum())


def _cavity(u: UnitSpec, dim: int) -> float:
    """The closed-form size of a unit's cavity: its section, times its width in 3D; none if solid."""
    if u.solid:
        return 0.0
    area = u.cavity_length * u.cavity_height
    return area if dim == 2 else area * (u.width - 2 * u.side_wall)


def _box(u: UnitSpec, dim: int) -> float:
    return u.pitch * u.height * (1.0 if dim == 2 else u.width)


MIXED = ["aesr", "AsSeRa", "sssAe", "reE"]


@pytest.mark.parametrize("design", MIXED)
def test_mixed_2d_meshes_have_each_units_areas(design: str) -> None:
    lib = builtin_library()
    m = assemble(lib, design, dim=2)
    units = parse_design(design, lib).units(lib)
    assert m.unit_specs == units and m.length == pytest.approx(sum(u.pitch for u in units))
    assert _measure(m, m.regions["filler"]) == pytest.approx(sum(_cavity(u, 2) for u in units), rel=1e-12)
    assert _measure(m, m.regions["layer"]) == pytest.approx(sum(u.pitch * u.layer for u in units), rel=1e-12)
    body = sum(_box(u, 2) - u.pitch * u.layer - _cavity(u, 2) for u in units)
    assert _measure(m, m.regions["body"]) == pytest.approx(body, rel=1e-12)


@pytest.mark.parametrize(("design", "half"), [("aesr", False), ("AsSeRa", True)])
def test_mixed_3d_meshes_have_each_units_solid_volume(design: str, half: bool) -> None:
    lib = builtin_library()
    m = assemble(lib, design, dim=3, half=half)
    units = parse_design(design, lib).units(lib)
    solid = sum(_box(u, 3) - _cavity(u, 3) for u in units) / (2 if half else 1)
    assert _measure(m) == pytest.approx(solid, rel=1e-12)
    assert "filler" not in m.regions and np.array_equal(np.unique(m.cells), np.arange(len(m.points)))


@pytest.mark.parametrize(("design", "dim"), [("aesr", 2), ("AsSeRa", 2), ("aesr", 3), ("sAe", 3)])
def test_mixed_meshes_conform_at_every_unit_interface(design: str, dim: int) -> None:
    m = assemble(builtin_library(), design, dim=dim)
    rounded = np.round(m.points, 9)
    assert len(np.unique(rounded, axis=0)) == len(m.points)  # no two points at the same place
    centroid_x = m.points[m.cells[:, : 4 if dim == 2 else 8]][..., 0].mean(axis=1)
    for x in m.unit_bounds[1:-1]:
        on_face = np.isclose(m.points[:, 0], x)
        left = np.unique(m.cells[centroid_x < x])
        right = np.unique(m.cells[centroid_x > x])
        face_left, face_right = np.intersect1d(left, np.flatnonzero(on_face)), np.intersect1d(right,
                                                                                             np.flatnonzero(on_face))
        assert len(face_left) > 0 and np.array_equal(face_left, face_right)  # the same nodes from both sides


def test_each_unit_keeps_its_own_layout_and_tracked_vertices() -> None:
    lib = builtin_library()
    m = assemble(lib, "aSrE", dim=2)
    starts = unit_starts(m.unit_specs)
    assert np.array_equal(m.unit_bounds, np.concatenate([[0.0], np.cumsum([u.pitch for u in m.unit_specs])]))
    H = m.spec.height
    for i, (u, o) in enumerate(zip(m.unit_specs, m.orientation, strict=True)):
        x0, x1, y0, y1 = u.cavity
        if o == "1":
            y0, y1 = H - y1, H - y0
        expected = [[starts[i] + x0, y0], [starts[i] + x1, y0], [starts[i] + x1, y1], [starts[i] + x0, y1]]
        np.testing.assert_allclose(m.points[m.tracked[i]], expected, atol=1e-12)
        span = (m.points[:, 0] > starts[i] + 1e-9) & (m.points[:, 0] < starts[i + 1] - 1e-9)
        assert m.cavity_points[span].any() != u.solid  # the near-rigid unit has no pressurised walls
    np.testing.assert_allclose(m.points[m.end_points, 0], m.length)


def test_a_mixed_design_turned_over_is_the_mirror_image() -> None:
    lib = builtin_library()
    a, b = assemble(lib, "aSre", dim=2), assemble(lib, parse_design("aSre", lib).mirror(), dim=2)
    assert b.design == "AsRE"
    H = a.spec.height
    mirrored = a.points * [1, -1] + [0, H]
    key = lambda p: np.lexsort(np.round(p, 9).T)  # noqa: E731
    np.testing.assert_allclose(mirrored[key(mirrored)], b.points[key(b.points)], atol=1e-12)
    np.testing.assert_allclose(a.unit_centres()[:, 1], H - b.unit_centres()[:, 1])


def test_an_extending_unit_is_the_same_either_way_up() -> None:
    lib = builtin_library()
    a, b = assemble(lib, "e", dim=2), assemble(lib, "E", dim=2)
    np.testing.assert_allclose(a.points, b.points)
    assert all(np.array_equal(a.regions[r], b.regions[r]) for r in a.regions)


def test_bad_mixed_designs_are_refused() -> None:
    lib = builtin_library()
    with pytest.raises(OrientationError, match="contains 'x'"):
        assemble(lib, "aax", dim=2)
    with pytest.raises(OrientationError, match="only the digits 0 and 1"):
        assemble(UnitSpec(), "0102", dim=2)
    with pytest.raises(GeometryError, match="solid unit 'near_rigid'"):
        assemble(lib, "ara", dim=3, passage=PHYSICAL_PASSAGE)
    m = assemble(lib, "aea", dim=3, passage=PHYSICAL_PASSAGE)  # the extending unit's cavity takes a passage
    assert m.cavity_points.sum() > assemble(lib, "aea", dim=3).cavity_points.sum()


def test_a_mixed_2d_mesh_solves_and_each_type_does_its_part(monkeypatch: pytest.MonkeyPatch) -> None:
    """Before the models take a library: Reduced2D's own build, given the mixed mesh, solves 2 units at 10 kPa.

    The extending and the near-rigid unit bend less than the bending one (the curl is then mostly
    the first unit's), and the extending unit lengthens more than the near-rigid one.
    """
    from pneumorph.models import fe
    from pneumorph.models.fe import base as febase

    lib, responses = builtin_library(), {}
    for design in ("aa", "ae", "ar"):
        monkeypatch.setattr(febase, "assemble",  # FEModel.mesh's assemble
                            lambda spec, orientation, *a, _d=design, **k: assemble(lib, _d, *a, **k))
        responses[design] = fe.Reduced2D(2, ramp_spec=fe.RampSpec(pressure=0.01)).evaluate("00")
    assert all(r.converged for r in responses.values())
    curl = {d: r.curl[-1] for d, r in responses.items()}
    assert 0 < curl["ae"] < curl["aa"] and 0 < curl["ar"] < curl["aa"]
    assert responses["ae"].tip[-1][0] > responses["ar"].tip[-1][0]

"""Sideways units: the stiff layer on a side face, meshed whole, checked in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import GeometryError, SettingsError, UnitLibraryError
from pneumorph.fem import cavity_volume
from pneumorph.geometry.assembly import ActuatorMesh, assemble
from pneumorph.geometry.features import check_passage
from pneumorph.geometry.grid import cross_section_lines
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, Reduced2D


def _volumes(mesh: ActuatorMesh) -> np.ndarray:
    """Volume of every hex20 cell by Gauss quadrature (all positive for a valid mesh)."""
    import felupe as fem

    region = fem.RegionQuadraticHexahedron(fem.Mesh(mesh.points, mesh.cells, mesh.cell_type))
    assert (region.dV > 0).all(), "an inverted or degenerate element"
    return region.dV.sum(axis=0)


def _centroids(mesh: ActuatorMesh, cells: np.ndarray) -> np.ndarray:
    return mesh.points[mesh.cells[cells, :8]].mean(axis=1)


def _one_line(exc: pytest.ExceptionInfo[BaseException]) -> str:
    text = str(exc.value)
    assert "\n" not in text and text
    return text


def test_the_spatial_library_joins_a_sideways_unit_to_the_bending_unit() -> None:
    lib = builtin_library("spatial")
    a, side = lib["a"], lib["l"]
    assert lib.symbols == ("a", "l") and a == UnitSpec() and side.layer_side
    assert (side.height, side.width) == (a.height, a.width)  # one outer section: one cast body
    for mine, theirs in zip(cross_section_lines(a), cross_section_lines(side), strict=True):
        np.testing.assert_array_equal(mine, theirs)
    assert "l" not in lib.symmetric  # `l` and `L` are different bodies
    assert builtin_library().symbols == ("a", "e", "r", "s")  # `builtin` stays planar
    assert not any(u.layer_side for u in builtin_library().units)


@pytest.mark.parametrize("design", ["l", "L"])
def test_a_sideways_unit_has_its_layer_on_a_side_and_exact_volumes(design: str) -> None:
    u = builtin_library("spatial")["l"]
    m = assemble(builtin_library("spatial"), design, dim=3)
    vol = _volumes(m)
    z0, z1 = u.cavity_z
    cavity = u.cavity_length * u.cavity_height * (z1 - z0)
    assert vol[m.regions["layer"]].sum() == pytest.approx(u.pitch * u.height * u.layer, rel=1e-12)
    assert vol[m.regions["body"]].sum() == pytest.approx(u.pitch * u.height * (u.width - u.layer) - cavity, rel=1e-12)
    z = _centroids(m, m.regions["layer"])[:, 2]
    # orientation 0: the layer on the face z = width; turned over (L): on z = 0
    assert ((z > u.width - u.layer) if design == "l" else (z < u.layer)).all()
    assert m.axes == 3 and m.symmetry_points is None


def test_the_pressurised_walls_enclose_each_units_cavity() -> None:
    lib = builtin_library("spatial")
    model = Full3D(3, library=lib)
    enclosed = cavity_volume(model.build("alL")[1].walls)
    a, side = lib["a"], lib["l"]
    expected = (a.cavity_length * a.cavity_height * (a.width - 2 * a.side_wall)
                + 2 * side.cavity_length * side.cavity_height * (side.cavity_z[1] - side.cavity_z[0]))
    assert enclosed == pytest.approx(expected, rel=1e-9)


def test_turning_a_sideways_unit_over_mirrors_it_across_the_width() -> None:
    lib = builtin_library("spatial")
    a, b = assemble(lib, "alA", dim=3), assemble(lib, "aLA", dim=3)
    W = lib["a"].width
    key = lambda p: np.lexsort(np.round(p, 9).T)  # noqa: E731
    mirrored = a.points * [1, 1, -1] + [0, 0, W]
    np.testing.assert_allclose(mirrored[key(mirrored)], b.points[key(b.points)], atol=1e-12)
    for region in ("body", "layer"):
        za, zb = _centroids(a, a.regions[region]), _centroids(b, b.regions[region])
        np.testing.assert_allclose(np.sort(W - za[:, 2]), np.sort(zb[:, 2]), atol=1e-12)
    np.testing.assert_allclose(a.unit_centres(axes=3), b.unit_centres(axes=3), atol=1e-12)  # on the axis


def test_planar_designs_over_the_spatial_library_mesh_as_today() -> None:
    today = assemble(UnitSpec(), "0110", dim=3, half=True)
    spatial = assemble(builtin_library("spatial"), "aAAa", dim=3, half=True)
    for key in ("points", "cells", "cavity_points", "tracked", "end_points", "base_points", "symmetry_points"):
        np.testing.assert_array_equal(getattr(today, key), getattr(spatial, key))
    assert all(np.array_equal(today.regions[r], spatial.regions[r]) for r in today.regions)


def test_a_mixed_spatial_mesh_conforms_at_every_unit_interface() -> None:
    m = assemble(builtin_library("spatial"), "alLA", dim=3)
    assert len(np.unique(np.round(m.points, 9), axis=0)) == len(m.points)
    centroid_x = m.points[m.cells[:, :8]][..., 0].mean(axis=1)
    for x in m.unit_bounds[1:-1]:
        on_face = np.flatnonzero(np.isclose(m.points[:, 0], x))
        left = np.intersect1d(np.unique(m.cells[centroid_x < x]), on_face)
        right = np.intersect1d(np.unique(m.cells[centroid_x > x]), on_face)
        assert len(left) and np.array_equal(left, right)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"dim": 2}, "bends out of the 2D section's plane"),
    ({"dim": 3, "half": True}, "mesh the full width (half=False)"),
])
def test_a_sideways_design_is_refused_in_2d_and_in_a_half_model(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(GeometryError) as exc:
        assemble(builtin_library("spatial"), "aL", **kwargs)  # type: ignore[arg-type]
    assert message in _one_line(exc) and "'aL'" in str(exc.value)


@pytest.mark.parametrize(("changes", "message"), [
    ({"layer_side": "yes"}, "unit layer_side must be true or false, got 'yes'"),
    ({"layer_side": 1}, "unit layer_side must be true or false, got 1"),
    ({"layer_side": True, "layer": 0.0}, "needs a stiff layer to put on the side (layer > 0)"),
    ({"layer_side": True, "slit_width": 0.5, "slit_depth": 2.0}, "takes no slit"),
    ({"layer_side": True, "layer": 12.0}, "2 x 1.5 mm + side layer 12 mm >= width 15.0 mm"),
])
def test_bad_sideways_units_are_refused_in_one_line(changes: dict[str, object], message: str) -> None:
    with pytest.raises(GeometryError) as exc:
        UnitSpec(**changes)  # type: ignore[arg-type]
    assert message in _one_line(exc)


def test_a_passage_must_fit_the_common_width_of_a_sideways_units_cavities() -> None:
    side = builtin_library("spatial")["l"]  # cavities facing either way share 15 - 3 - 6 = 6 mm of width
    assert check_passage(side, 1.5) == pytest.approx(check_passage(UnitSpec(), 1.5))
    with pytest.raises(GeometryError) as exc:
        check_passage(side, 7.0)
    assert "common width of two cavities facing either way" in _one_line(exc)


def test_the_library_checks_refuse_bad_sideways_entries_in_one_line(tmp_path: Path) -> None:
    with pytest.raises(UnitLibraryError) as exc:  # a 2 mm layer puts the cavity's side off the 1.5 mm lines
        UnitLibrary(("a", "l"), (UnitSpec(), UnitSpec(cavity_height=9.0, layer=2.0, layer_side=True)))
    assert "grid lines across the width (z) differ" in _one_line(exc)
    with pytest.raises(UnitLibraryError) as exc:  # the layer moved to the side, the cavity not grown: 9 mm high
        UnitLibrary(("a", "l"), (UnitSpec(), UnitSpec(layer_side=True)))
    assert "their heights differ (12 mm and 9 mm)" in _one_line(exc)
    path = tmp_path / "lib.toml"
    path.write_text('[[units]]\nsymbol = "a"\n[[units]]\nsymbol = "l"\nunit = { layer_side = "yes" }\n')
    with pytest.raises(UnitLibraryError) as exc:
        UnitLibrary.from_toml(path)
    assert "unit 'l' (entry 2)" in _one_line(exc) and "layer_side must be true or false" in str(exc.value)
    with pytest.raises(UnitLibraryError) as exc:
        builtin_library("sideways")
    assert _one_line(exc) == "no built-in unit library 'sideways'; the built-in ones: builtin, spatial, modes"


def test_the_2d_model_refuses_a_sideways_unit_in_one_line() -> None:
    with pytest.raises(SettingsError) as exc:
        Reduced2D(3, library=builtin_library("spatial"))
    assert "unit type 'l' is sideways" in _one_line(exc) and "3D model" in str(exc.value)
    with pytest.raises(SettingsError) as exc:
        Reduced2D(3, unit=builtin_library("spatial")["l"])
    assert _one_line(exc).startswith("the unit is sideways")


def test_the_default_unit_and_the_builtin_library_are_described_as_before() -> None:
    assert "layer_side" not in UnitSpec().to_dict()
    assert UnitSpec(layer_side=True, cavity_height=9.0).to_dict()["layer_side"] is True
    assert builtin_library().fingerprint() == "fa6117dd0d8c7a04"  # as before sideways units existed

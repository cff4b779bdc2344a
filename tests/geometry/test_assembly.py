"""Unit specification and actuator assembly: topology, symmetry, validation."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import GeometryError, OrientationError
from pneumorph.geometry.assembly import assemble
from pneumorph.geometry.unit import UnitSpec


def cell_areas(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """Areas of the straight-edged quad8 cells from their corner nodes (shoelace)."""
    c = points[cells[:, :4]]
    x, y = c[..., 0], c[..., 1]
    return 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1))


def test_fifteen_unit_2d_mesh_matches_the_measured_size() -> None:
    """The feasibility unit (1.5 mm walls, 7.5 x 12 mm cavity), 15 units at 1.5 mm:
    1,260 quad8 cells and 4,015 points (8,030 dofs), as measured independently."""
    m = assemble(UnitSpec(end_wall=1.5, cavity_height=12.0), "0" * 15, dim=2)
    assert m.cell_type == "quad8"
    assert (len(m.cells), len(m.points)) == (1260, 4015)


def test_region_areas_are_the_section_areas() -> None:
    u = UnitSpec()
    m = assemble(u, "0110", dim=2)
    area = {k: cell_areas(m.points, m.cells[v]).sum() for k, v in m.regions.items()}
    n = 4
    assert area["filler"] == pytest.approx(n * u.cavity_length * u.cavity_height)
    assert area["layer"] == pytest.approx(n * u.pitch * u.layer)
    assert area["body"] == pytest.approx(n * u.pitch * (u.height - u.layer) - area["filler"])


def test_inverted_design_is_the_mirror_image() -> None:
    u = UnitSpec(slit_width=1.0, slit_depth=6.0)
    a = assemble(u, "0010", dim=2)
    b = assemble(u, "1101", dim=2)
    mirrored = a.points * [1, -1] + [0, u.height]
    key = lambda p: np.lexsort(np.round(p, 9).T)  # noqa: E731
    np.testing.assert_allclose(mirrored[key(mirrored)], b.points[key(b.points)], atol=1e-12)
    np.testing.assert_allclose(a.unit_centres()[:, 1], u.height - b.unit_centres()[:, 1])


def test_tracked_points_are_the_cavity_vertices() -> None:
    u = UnitSpec()
    m = assemble(u, "01", dim=2)
    x0, x1, y0, y1 = u.cavity
    np.testing.assert_allclose(m.points[m.tracked[0]], [[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    H = u.height
    np.testing.assert_allclose(
        m.points[m.tracked[1]],
        [[u.pitch + x0, H - y1], [u.pitch + x1, H - y1], [u.pitch + x1, H - y0], [u.pitch + x0, H - y0]],
    )
    np.testing.assert_allclose(m.unit_centres(), [[5.25, 4.5], [15.75, 7.5]])


def test_slit_removes_material_and_end_cap_adds_it() -> None:
    u = UnitSpec(slit_width=1.0, slit_depth=6.0, end_cap=3.0)
    m = assemble(u, "000", dim=2)
    total = cell_areas(m.points, m.cells).sum()
    assert total == pytest.approx((3 * u.pitch + 3.0) * u.height - 3 * 1.0 * 6.0)
    assert m.length == pytest.approx(34.5)
    assert np.allclose(m.points[m.end_points, 0], 34.5)


def test_3d_mesh_has_empty_cavities_and_tracks_the_mid_plane() -> None:
    u = UnitSpec()
    m = assemble(u, "01", dim=3)
    assert m.cell_type == "hexahedron20" and "filler" not in m.regions
    np.testing.assert_allclose(m.points[m.tracked][..., 2], u.width / 2)
    # the cavity walls are exactly the points of the cavity boxes' surfaces
    x0, _x1, _y0, _y1 = u.cavity
    p = m.points[m.cavity_points]
    assert np.all((p[:, 0] >= x0 - 1e-9) & (p[:, 2] >= u.side_wall - 1e-9) & (p[:, 2] <= u.width - u.side_wall + 1e-9))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"pitch": -1.0}, "pitch must be positive"),
        ({"end_wall": 5.25}, "leave no cavity"),
        ({"slit_width": 1.0, "slit_depth": 9.0}, "reaches the stiff layer"),
        ({"side_wall": 7.5}, "side walls leave no cavity"),
        ({"slit_width": 1.0}, "needs both a width and a depth"),
        ({"slit_width": 1.0, "slit_depth": 15.0}, "reaches the stiff layer"),
        ({"wall": float("nan")}, "finite number"),
    ],
)
def test_impossible_units_are_rejected(kwargs: dict, message: str) -> None:
    with pytest.raises(GeometryError, match=message):
        UnitSpec(**kwargs)


def test_units_load_from_toml(tmp_path: Path) -> None:
    good = tmp_path / "u.toml"
    good.write_text("[unit]\npitch = 12.0\nlayer = 2.5\nname = 'wide'\n")
    u = UnitSpec.from_toml(good)
    assert (u.pitch, u.layer, u.name, u.wall) == (12.0, 2.5, "wide", 1.5)
    bad = tmp_path / "bad.toml"
    bad.write_text("[unit]\npich = 12.0\n")
    with pytest.raises(GeometryError, match="unknown unit parameter\\(s\\) pich"):
        UnitSpec.from_toml(bad)
    with pytest.raises(GeometryError, match="expected a \\[unit\\] table"):
        (tmp_path / "empty.toml").write_text("x = 1\n")
        UnitSpec.from_toml(tmp_path / "empty.toml")


def test_bad_orientation_and_dimension() -> None:
    with pytest.raises(OrientationError):
        assemble(UnitSpec(), "012")
    with pytest.raises(GeometryError, match="dim must be 2 or 3"):
        assemble(UnitSpec(), "01", dim=1)


@pytest.mark.parametrize("dim", [2, 3])
def test_a_unit_of_any_decimals_has_its_turned_over_units_mirrored_about_the_end_face(dim: int) -> None:
    """The chain tables mirror a design about the end face's centre: a turned-over unit's centre must sit exactly
    there (an identified unit's 1.591632525 mm wall and 2.96848611 mm layer put its grid lines 1e-6 mm off
    symmetric when each was rounded on its own, and its table could not be built)."""
    from pneumorph.geometry.unit import UnitSpec

    unit = UnitSpec(wall=1.591632525, side_wall=1.527421929, layer=2.96848611, element_size=3.0)
    mesh = assemble(unit, "0110", dim, half=True)
    centres = mesh.unit_centres(axes=2)
    tip_y = mesh.points[mesh.end_points][:, 1].mean()
    assert abs(centres[0, 1] - (2 * tip_y - centres[1, 1])) < 1e-12
    assert abs(centres[3, 1] - (2 * tip_y - centres[2, 1])) < 1e-12
    assert abs(centres[0, 1] - centres[1, 1]) > 2.0  # the two orientations do differ

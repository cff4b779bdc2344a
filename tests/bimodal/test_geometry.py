"""Layered geometry of the bimodal actuator (section 3.3): dimensions, labels, volumes."""

from __future__ import annotations

import pytest

from pneumorph.bimodal.geometry import ASSUMED, BimodalSpec, cell_volumes, mesh_actuator, node_count
from pneumorph.errors import GeometryError


def test_defaults_are_the_dissertations_actuator() -> None:
    s = BimodalSpec()
    # section 3.3.1: 157.5 x 15 x 17.5 mm Mold Star body, 15 voids; 3.3.2: 1 mm seal; 5 mm composite
    assert (s.voids * s.pitch, s.width, s.body_height, s.voids, s.seal, s.bilinear) == (157.5, 15.0, 17.5, 15, 1.0, 5.0)
    # the free end (not given): a 6 mm wall beyond the last void, with which all three crimp ratios reverse
    assert (s.end_wall + s.end_cap, s.length) == (6.0, 162.0)
    assert s.height == pytest.approx(5.0 + 1.0 + 17.5 + 2.0)
    # the void runs from the seal (y = 6) to the top wall (y = 6 + 17.5 - 1.5)
    assert s.void == (1.5, 9.0, 6.0, 22.0)
    assert s.void_volume == pytest.approx(7.5 * 16.0 * 12.0)
    for key in ("top_wall", "end_wall", "side_wall", "strip", "tip_point", "end_cap"):
        assert key in ASSUMED


@pytest.mark.parametrize("half", [False, True])
def test_layer_volumes(half: bool) -> None:
    s = BimodalSpec(voids=2, element_size=3.0)
    w = s.width / (2 if half else 1)
    v = cell_volumes(mesh_actuator(s, half=half))
    L = s.length
    assert v["bilinear"] == pytest.approx(L * 5.0 * w)
    assert v["seal"] == pytest.approx(L * 1.0 * w)
    assert v["strip"] == pytest.approx(L * 2.0 * w)
    assert v["body"] == pytest.approx(L * 17.5 * w - 2 * s.void_volume * w / s.width)


def test_pressurised_walls_enclose_the_voids() -> None:
    """The void-wall boundary encloses exactly the voids (half model: half of them)."""
    import felupe as fem

    from pneumorph.fem import cavity_volume

    s = BimodalSpec(voids=2, element_size=3.0)
    for half, factor in ((True, 0.5), (False, 1.0)):
        m = mesh_actuator(s, half=half)
        mesh = fem.Mesh(m.points, m.cells, m.cell_type)
        walls = fem.RegionQuadraticHexahedronBoundary(mesh, mask=m.void_points)
        field = fem.FieldContainer([fem.Field(walls, dim=3)])
        # the divergence theorem about the origin: the mid-plane z = 7.5 adds x.n = 7.5 dA
        # on the cut (half model) - shift the origin onto it instead
        if half:
            mesh_shift = fem.Mesh(m.points - [0, 0, s.width / 2], m.cells, m.cell_type)
            walls = fem.RegionQuadraticHexahedronBoundary(mesh_shift, mask=m.void_points)
            field = fem.FieldContainer([fem.Field(walls, dim=3)])
        assert cavity_volume(field) == pytest.approx(factor * 2 * s.void_volume, rel=1e-9)


def test_end_cap_closes_the_last_void() -> None:
    s = BimodalSpec(voids=1, element_size=3.0, end_cap=3.0)
    assert s.length == 13.5
    v = cell_volumes(mesh_actuator(s, half=False))
    assert v["body"] == pytest.approx(13.5 * 17.5 * 15.0 - s.void_volume)


def test_tip_corners_on_the_end_face() -> None:
    s = BimodalSpec(voids=2, element_size=3.0)
    m = mesh_actuator(s)
    assert m.points[m.tip].tolist() == [[s.length, 0.0, 7.5], [s.length, s.height, 7.5]]


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"voids": 0}, "1 to 100 voids"),
        ({"end_wall": 5.25}, "end walls leave no void"),
        ({"side_wall": 7.5}, "side walls"),
        ({"top_wall": 17.5}, "top wall"),
        ({"bilinear": 0.0}, "bilinear must be a positive"),
        ({"end_cap": -1.0}, "end_cap"),
    ],
)
def test_impossible_geometry_is_rejected(kwargs: dict, words: str) -> None:
    with pytest.raises(GeometryError, match=words):
        BimodalSpec(**kwargs)


def test_station_one_void_short_of_the_tip() -> None:
    s = BimodalSpec(voids=3, element_size=3.0)
    m = mesh_actuator(s)
    assert m.points[m.station].tolist() == [[21.0, 0.0, 7.5], [21.0, s.height, 7.5]]


@pytest.mark.parametrize(("voids", "size", "cap"), [(1, 3.0, 4.5), (2, 2.5, 0.0), (3, 1.5, 4.5), (4, 2.0, 1.0),
                                                    (2, 1.0, 4.5)])
@pytest.mark.parametrize(("half", "quadratic"), [(True, True), (False, True), (True, False), (False, False)])
def test_the_node_count_is_the_meshs(voids: int, size: float, cap: float, half: bool, quadratic: bool) -> None:
    """node_count (the grid's nodes less those inside the voids) is the number of points mesh_actuator makes, for
    several voids, element sizes and end caps, half and full width, 8- and 20-node cells."""
    spec = BimodalSpec(voids=voids, element_size=size, end_cap=cap)
    assert node_count(spec, half, quadratic) == len(mesh_actuator(spec, half=half, quadratic=quadratic).points)

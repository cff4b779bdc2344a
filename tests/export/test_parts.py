"""Part meshes: watertight, the analytic volumes, the assembly's regions, STL round trip."""

from __future__ import annotations

import manifold3d as m3
import numpy as np
import pytest
import trimesh

from pneumorph.errors import GeometryError, OrientationError
from pneumorph.export import (
    BaseBlock,
    actuator_parts,
    actuator_solids,
    layer_pieces,
    write_stl,
)
from pneumorph.export.parts import box, to_manifold
from pneumorph.geometry.assembly import assemble
from pneumorph.geometry.library import builtin_library
from pneumorph.geometry.unit import UnitSpec

DEFAULT = "001111010001001"
SLIT = UnitSpec(slit_width=1.0, slit_depth=4.0, end_cap=2.0)


def analytic(spec: UnitSpec, n: int, base: BaseBlock | None = None) -> dict[str, float]:
    """Volumes by hand (mm^3): boxes minus the cavities and the slits."""
    base = BaseBlock() if base is None else base
    P, W, H, s, lay = spec.pitch, spec.width, spec.height, spec.side_wall, spec.layer
    cavity_length = P - 2 * spec.end_wall - spec.slit_width
    cavity = cavity_length * spec.cavity_height * (W - 2 * s)
    slit = spec.slit_width * spec.slit_depth * W
    length = n * P + spec.end_cap
    return {
        "body": length * (H - lay) * W - n * cavity - n * slit,
        "layer": length * lay * W,
        "base_block": base.length * (H + 2 * base.margin) * (W + 2 * base.margin),
    }


def check_parts(parts: dict[str, trimesh.Trimesh], expected: dict[str, float]) -> None:
    for name, mesh in parts.items():
        assert mesh.is_watertight and mesh.is_volume, name
        assert mesh.is_winding_consistent and mesh.volume > 0, name
    layers = sum(m.volume for k, m in parts.items() if k.startswith("layer_"))
    for name, got in (("body", parts["body"].volume), ("layer", layers), ("base_block", parts["base_block"].volume)):
        assert abs(got / expected[name] - 1) < 5e-3, name  # within 0.5 %, the parts' acceptance criterion
        assert got == pytest.approx(expected[name], rel=1e-9), name  # what the boxes give


def test_default_design_volumes_are_the_analytic_ones():
    spec = UnitSpec()
    parts = actuator_parts(spec, DEFAULT)
    expected = analytic(spec, 15)
    # 15 x (10.5 x 9 x 15 - 4.5 x 6 x 12), 157.5 x 3 x 15, 10 x 12 x 15
    assert expected == {"body": 16402.5, "layer": 7087.5, "base_block": 1800.0}
    check_parts(parts, expected)
    assert list(parts) == ["body", *(f"layer_{k}" for k in range(1, 9)), "base_block"]
    # the body: one shell outside, one void per cavity, each the cavity's volume
    shells = sorted(round(s.volume(), 9) for s in actuator_solids(spec, DEFAULT)["body"].decompose())
    assert shells == [-324.0] * 15 + [16402.5 + 15 * 324.0]


def test_layer_pieces_follow_the_orientation_runs():
    spec = UnitSpec()
    pieces = layer_pieces(spec, DEFAULT)
    runs = [(p.first, p.last, p.side, p.length) for p in pieces]
    assert runs == [(0, 1, "top", 21.0), (2, 5, "bottom", 42.0), (6, 6, "top", 10.5), (7, 7, "bottom", 10.5),
                    (8, 10, "top", 31.5), (11, 11, "bottom", 10.5), (12, 13, "top", 21.0), (14, 14, "bottom", 10.5)]
    parts = actuator_parts(spec, DEFAULT)
    for k, p in enumerate(pieces, start=1):
        lo, hi = parts[f"layer_{k}"].bounds
        y = (9.0, 12.0) if p.side == "top" else (0.0, 3.0)
        assert np.allclose([*lo, *hi], [p.x0, y[0], 0.0, p.x1, y[1], 15.0], atol=0)
    assert [(p.side, p.length) for p in layer_pieces(spec, "0" * 15)] == [("top", 157.5)]


def test_parts_are_the_regions_of_the_assembled_mesh():
    """The union of the 3D mesh's body (layer) cells is the body (the layer pieces), exactly."""
    for spec in (UnitSpec(element_size=20.0, element_order=1),
                 UnitSpec(slit_width=1.0, slit_depth=4.0, end_cap=2.0, element_size=20.0, element_order=1)):
        _assert_regions(assemble(spec, DEFAULT, dim=3), actuator_solids(spec, DEFAULT))


@pytest.mark.parametrize(("name", "design"), [("spatial", "aLlAl"), ("builtin", "aResA")])
def test_library_parts_are_the_regions_of_the_assembled_mesh(name, design):
    """Mixed designs: sideways units' strips on the right (as built) and left (turned) faces, a near-rigid unit
    without a cavity, an extending one without a strip, a short one; watertight, and the mesh's regions exactly."""
    library = builtin_library(name)
    solids = actuator_solids(library, design)
    for part, solid in actuator_parts(library, design).items():
        assert solid.is_watertight and solid.is_volume, part
    _assert_regions(assemble(library, design, dim=3), solids)


def _assert_regions(mesh, solids):
    for region, names in (("body", ["body"]), ("layer", [k for k in solids if k.startswith("layer_")])):
        corners = mesh.points[mesh.cells[mesh.regions[region]]]
        lo, hi = corners.min(axis=1), corners.max(axis=1)
        boxes = [box((a[0], b[0], a[1], b[1], a[2], b[2])) for a, b in zip(lo, hi, strict=True)]
        cells = m3.Manifold.batch_boolean(boxes, m3.OpType.Add)
        mine = m3.Manifold.batch_boolean([solids[k] for k in names], m3.OpType.Add)
        assert (cells - mine).volume() < 1e-9 and (mine - cells).volume() < 1e-9, region
        assert cells.volume() == pytest.approx(mine.volume(), rel=1e-12)


def test_parts_do_not_overlap_and_fill_the_actuator():
    spec = UnitSpec()
    solids = actuator_solids(spec, DEFAULT)
    names = list(solids)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            assert (solids[a] ^ solids[b]).volume() < 1e-9, (a, b)
    whole = m3.Manifold.batch_boolean([solids[k] for k in names if k != "base_block"], m3.OpType.Add)
    assert whole.volume() == pytest.approx(157.5 * 12 * 15 - 15 * 324.0, rel=1e-12)


@pytest.mark.parametrize("design, spec, n", [("0", UnitSpec(), 1), ("1", UnitSpec(), 1), ("01", UnitSpec(), 2),
                                             ("1", SLIT, 1), ("01", SLIT, 2), ("0110", SLIT, 4)])
def test_small_designs_and_slits(design, spec, n):
    parts = actuator_parts(spec, design)
    check_parts(parts, analytic(spec, n))
    assert len([k for k in parts if k.startswith("layer_")]) == len(layer_pieces(spec, design))


def test_one_unit_and_01_numbers():
    one, two = actuator_parts(UnitSpec(), "0"), actuator_parts(UnitSpec(), "01")
    assert one["body"].volume == pytest.approx(1093.5, rel=1e-12)  # 10.5 x 9 x 15 - 324
    assert two["body"].volume == pytest.approx(2187.0, rel=1e-12)
    # "01": the second unit's body is 3 mm higher (its layer is underneath)
    assert np.allclose(two["body"].bounds, [[0, 0, 0], [21, 12, 15]])
    assert np.allclose(two["layer_2"].bounds, [[10.5, 0, 0], [21, 3, 15]])
    slit = actuator_parts(SLIT, "0")
    # (12.5 x 9 x 15) - slit 1 x 4 x 15 - cavity 3.5 x 6 x 12; layer 12.5 x 3 x 15
    assert slit["body"].volume == pytest.approx(1687.5 - 60 - 252, rel=1e-12)
    assert slit["layer_1"].volume == pytest.approx(562.5, rel=1e-12)


def test_base_block_settings():
    parts = actuator_parts(UnitSpec(), "01", BaseBlock(length=8.0, margin=2.0))
    assert parts["base_block"].volume == pytest.approx(8 * 16 * 19, rel=1e-12)
    assert np.allclose(parts["base_block"].bounds, [[-8, -2, -2], [0, 14, 17]])
    assert "base_block" not in actuator_parts(UnitSpec(), "01", base_block=None)
    with pytest.raises(GeometryError, match="base block length"):
        BaseBlock(length=0.0)
    with pytest.raises(GeometryError, match="base block margin"):
        BaseBlock(margin=float("nan"))


def test_stl_files_round_trip(tmp_path):
    parts = actuator_parts(UnitSpec(), DEFAULT)
    paths = write_stl(parts, tmp_path / "stl")
    assert [p.name for p in paths] == [f"{k}.stl" for k in parts]
    assert sorted(p.name for p in (tmp_path / "stl").iterdir()) == sorted(p.name for p in paths)  # no temp files
    for path, (name, mesh) in zip(paths, parts.items(), strict=False):
        assert path.stat().st_size == 84 + 50 * len(mesh.faces)  # binary STL
        back = trimesh.load_mesh(path)
        assert back.is_watertight and back.is_volume, name
        assert back.volume == pytest.approx(mesh.volume, rel=1e-6), name  # float32 coordinates


def test_errors():
    with pytest.raises(OrientationError):
        actuator_parts(UnitSpec(), "0120")
    with pytest.raises(GeometryError, match="not a plain file name"):
        write_stl({"../body": actuator_parts(UnitSpec(), "0")["body"]}, "/tmp")
    with pytest.raises(GeometryError, match="do not close a volume"):
        to_manifold(np.zeros((3, 3)), np.array([[0, 1, 2]]))
    with pytest.raises(GeometryError, match="empty box"):
        box((0, 0, 0, 1, 0, 1))

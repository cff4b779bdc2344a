"""The casting mould: watertight parts that do not overlap, whose empty space is the body."""

from __future__ import annotations

import math

import manifold3d as m3
import pytest

from pneumorph.errors import GeometryError
from pneumorph.export import MouldSpec, actuator_solids, casting_mould, plot_mould
from pneumorph.export import moulds as moulds_module
from pneumorph.export.parts import box, to_manifold
from pneumorph.geometry.unit import UnitSpec

DEFAULT = "001111010001001"


def solid(mesh) -> m3.Manifold:
    return to_manifold(mesh.vertices, mesh.faces)


def xor(a: m3.Manifold, b: m3.Manifold) -> float:
    return (a - b).volume() + (b - a).volume()


def ngon(radius: float, n: int) -> float:
    """Area of the regular polygon the round holes and pins are made of."""
    return n / 2 * radius**2 * math.sin(2 * math.pi / n)


def expected_rest(spec: UnitSpec, n_units: int, ms: MouldSpec) -> float:
    """Empty space besides the cast, by hand: the lid's holes and the clearance gaps (mm^3)."""
    c, n = ms.clearance, ms.segments
    holes = 2 * (ngon(ms.pour_diameter / 2, n) + ngon(ms.vent_diameter / 2, n)) * ms.plate
    r, length = ms.pin_diameter / 2, spec.width - spec.side_wall + 2 * ms.pin_depth
    pins = 4 * (ngon(r + c, n) * (length + 2 * c) - ngon(r, n) * length)
    x0, x1, y0, y1 = spec.cavity
    inset, depth = min(x1 - x0, y1 - y0) / 4, ms.tenon_depth
    a, b = x1 - x0 - 2 * inset, y1 - y0 - 2 * inset
    tenons = n_units * ((a + 2 * c) * (b + 2 * c) * (depth + c) - a * b * depth)
    return holes + pins + tenons


def check_negative(spec: UnitSpec, design: str, ms: MouldSpec) -> dict[str, float]:
    """Independent of the module's own check: the empty space, pocket by pocket."""
    mould = casting_mould(spec, design, ms)
    for name, mesh in mould.parts.items():
        assert mesh.is_watertight and mesh.is_volume, name
    parts = {name: solid(mesh) for name, mesh in mould.parts.items()}
    names = list(parts)
    worst = max((parts[a] ^ parts[b]).volume() for i, a in enumerate(names) for b in names[i + 1:])
    assert worst < 1e-9
    empty = m3.Manifold.batch_boolean([box(mould.outer), *parts.values()], m3.OpType.Subtract)
    n, s, W, H = len(design), spec.side_wall, spec.width, spec.height
    L = n * spec.pitch + spec.end_cap
    body = actuator_solids(spec, design)["body"]
    # the body's pocket holds the body above z = side_wall, the sheet's pocket the rest
    in_body_pocket = empty ^ box((0.0, L, 0.0, H, s, W))
    dx, dy, dz = mould.sheet_offset
    in_sheet_pocket = empty ^ box((0.0, L, dy, dy + H, W - s, W))
    upper = body ^ box((0.0, L, 0.0, H, s, W))
    lower = (body ^ box((0.0, L, 0.0, H, 0.0, s))).translate((dx, dy, dz))
    errors = {"body_pocket": xor(in_body_pocket, upper), "sheet_pocket": xor(in_sheet_pocket, lower)}
    # and the pieces glued back are the body
    errors["glued"] = xor(in_body_pocket + in_sheet_pocket.translate((-dx, -dy, -dz)), body)
    errors["rest"] = empty.volume() - body.volume() - expected_rest(spec, n, ms)
    for key, value in errors.items():
        assert abs(value) < 1e-7, key
    return {"mould": mould, "worst": worst, "empty": empty.volume(), **errors}


def test_default_design_mould_is_the_body_negative():
    spec, ms = UnitSpec(), MouldSpec()
    out = check_negative(spec, DEFAULT, ms)
    mould = out["mould"]
    assert list(mould.parts)[:3] == ["base_plate", "side_walls", "lid"]
    assert sum(k.startswith("core_") for k in mould.parts) == 15 and sum(k.startswith("pin_") for k in mould.parts) == 4
    c = mould.check
    assert c.ok and all(c.watertight.values()) and len(c.watertight) == 22
    assert c.max_overlap < 1e-9 and c.cavity_error < 1e-9 and c.reassembly_error < 1e-9
    assert c.cavity_volume_change == 0.0
    assert c.cast_volume == pytest.approx(16402.5, rel=1e-12)  # the body, in two pieces
    # 15 x (10.5 x 9 x 13.5 - 324) above the plane z = 1.5, 15 x 10.5 x 9 x 1.5 below
    assert mould.cast["open_body"].volume == pytest.approx(14276.25, rel=1e-12)
    assert mould.cast["side_sheet"].volume == pytest.approx(2126.25, rel=1e-12)
    assert c.gaps_volume + c.openings_volume == pytest.approx(expected_rest(spec, 15, ms), rel=1e-9)
    assert c.gap_distance == pytest.approx(4.5 / 4 - 0.2)  # the tenon's setback less the clearance
    # the outer box: 6 mm walls, both pockets side by side, 5 mm plates
    assert mould.outer == (-6.0, 163.5, -6.0, 36.0, -3.5, 20.0)


@pytest.mark.parametrize("design, spec", [("0", UnitSpec()), ("01", UnitSpec()), ("1", UnitSpec()),
                                          ("0110", UnitSpec(slit_width=1.0, slit_depth=4.0, end_cap=2.0))])
def test_small_designs(design, spec):
    out = check_negative(spec, design, MouldSpec())
    assert out["mould"].check.ok
    assert len(out["mould"].parts) == 3 + len(design) + 4


def test_clearance_and_draft():
    spec = UnitSpec()
    check_negative(spec, "01", MouldSpec(clearance=0.0))
    check_negative(spec, "01", MouldSpec(clearance=0.5, segments=12))
    mould = casting_mould(spec, DEFAULT, MouldSpec(draft=1.0))
    # the drafted core: the cavity at its root, each side in by 12 tan(1 deg) at its tip
    d = 12 * math.tan(math.radians(1.0))
    a0, a1, am = 4.5 * 6, (4.5 - 2 * d) * (6 - 2 * d), (4.5 - d) * (6 - d)
    frustum = 12 / 6 * (a0 + a1 + 4 * am)
    assert mould.check.cavity_volume_change == pytest.approx(15 * (324 - frustum), rel=1e-9)
    assert mould.check.cavity_volume_change == pytest.approx(385.351, abs=1e-3)
    assert mould.check.ok and mould.check.reassembly_error < 1e-9


def test_bad_settings_name_the_parameter():
    spec = UnitSpec()
    with pytest.raises(GeometryError, match=r"clearance 1\.2 mm is not smaller than the core tenon's setback 1\.125"):
        casting_mould(spec, DEFAULT, MouldSpec(clearance=1.2, wall=8.0))
    with pytest.raises(GeometryError, match="clearance 2 mm is too large"):
        MouldSpec(clearance=2.0)
    with pytest.raises(GeometryError, match="clearance must be >= 0"):
        MouldSpec(clearance=-0.1)
    with pytest.raises(GeometryError, match="draft must be >= 0"):
        MouldSpec(draft=-1.0)
    with pytest.raises(GeometryError, match="draft 10 degrees narrows"):
        casting_mould(spec, DEFAULT, MouldSpec(draft=10.0))
    with pytest.raises(GeometryError, match="pour_diameter 8 mm does not fit"):
        casting_mould(spec, DEFAULT, MouldSpec(pour_diameter=8.0))
    with pytest.raises(GeometryError, match="pin_depth"):
        MouldSpec(pin_depth=5.0)
    with pytest.raises(GeometryError, match="segments"):
        MouldSpec(segments=3)


def test_overlapping_parts_are_refused(monkeypatch):
    """A tenon wider than its pocket: the check finds the overlap and refuses the mould."""
    original = moulds_module._core
    monkeypatch.setattr(moulds_module, "_core", lambda cav, tip, inset, depth: original(cav, tip, inset - 0.5, depth))
    with pytest.raises(GeometryError, match="parts overlap by up to"):
        casting_mould(UnitSpec(), "01")
    unchecked = casting_mould(UnitSpec(), "01", check=False)
    assert math.isnan(unchecked.check.max_overlap)


def test_exploded_drawing(tmp_path):
    mould = casting_mould(UnitSpec(), "01")
    path = tmp_path / "mould.png"
    fig = plot_mould(mould, path)
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000
    assert [p.name for p in tmp_path.iterdir()] == ["mould.png"]  # no temporary file left
    # every triangle of every part and of the two cast pieces is drawn
    n_triangles = sum(len(m.faces) for m in mould.parts.values()) + sum(len(m.faces) for m in mould.cast.values())
    assert len(fig.axes[0].collections[0].get_facecolors()) == n_triangles
    # the lid is drawn highest: 3 mould heights (3 x 20 mm) up
    assert mould.explode["lid"] == (0.0, 0.0, 60.0) and mould.explode["base_plate"] == (0.0, 0.0, -20.0)


def check_library_negative(library, design: str, ms: MouldSpec) -> dict:
    """The empty space of a mixed design's mould, pocket by pocket, from its units by hand: above z = 1.5 the open
    body, except under a turned-over sideways unit (its strip on z = 0..3, then a 1.5 mm wall): above z = 4.5 there,
    the wall cast in the sheet."""
    from pneumorph.geometry.alphabet import parse_design

    mould = casting_mould(library, design, ms)
    parts = {name: solid(mesh) for name, mesh in mould.parts.items()}
    names = list(parts)
    assert max((parts[a] ^ parts[b]).volume() for i, a in enumerate(names) for b in names[i + 1:]) < 1e-9
    empty = m3.Manifold.batch_boolean([box(mould.outer), *parts.values()], m3.OpType.Subtract)
    ref = library[library.default]
    s, W, H, P = ref.side_wall, ref.width, ref.height, ref.pitch
    body = actuator_solids(library, design)["body"]
    turned = [i for i, c in enumerate(parse_design(design, library).text) if c == "L"]
    below = m3.Manifold.batch_boolean([box((-1.0, len(design) * P + 1, -1.0, H + 1, -1.0, s)),
                                       *[box((i * P, (i + 1) * P, -1.0, H + 1, -1.0, 4.5)) for i in turned]],
                                      m3.OpType.Add)
    upper, pieces = body - below, body ^ below
    lifted = [box((i * P, (i + 1) * P, -1.0, H + 1, 2.0, 5.0)) for i in turned]  # the walls of the L units
    flat = m3.Manifold.batch_boolean([m3.Manifold.batch_boolean([pieces, *lifted], m3.OpType.Subtract),
                                      *[(pieces ^ b).translate((0.0, 0.0, -3.0)) for b in lifted]], m3.OpType.Add)
    dx, dy, dz = mould.sheet_offset
    in_body_pocket = empty ^ box((0.0, len(design) * P, 0.0, H, s, W))
    for i in turned:  # a plinth holds its core's tenon and the clearance gap around it: not the cast
        in_body_pocket -= box((i * P, (i + 1) * P, -1.0, H + 1, 0.0, 4.5))
    in_sheet_pocket = empty ^ box((0.0, len(design) * P, dy, dy + H, W - s, W))
    return {"mould": mould, "body_pocket": xor(in_body_pocket, upper),
            "sheet_pocket": xor(in_sheet_pocket, flat.translate((dx, dy, dz))), "upper": upper.volume(),
            "sheet": pieces.volume()}


@pytest.mark.parametrize(("library", "design", "sheet"), [
    ("spatial", "aLlAl", 10.5 * 1.5 * (9 + 12 + 12 + 9 + 12)),  # the sheet: each unit's footprint, 1.5 mm
    ("spatial", "LLa", 10.5 * 1.5 * (12 + 12 + 9)),
    ("builtin", "aResA", 1.5 * (10.5 * (9 + 9 + 12 + 9) + 7.0 * 9)),  # s: the short unit, 7 mm
])
def test_a_mixed_design_is_cast_with_its_turned_over_sideways_units_on_plinths(library: str, design: str,
                                                                                sheet: float) -> None:
    from pneumorph.geometry.library import builtin_library

    out = check_library_negative(builtin_library(library), design, MouldSpec())
    mould, c = out["mould"], out["mould"].check
    assert c.ok and c.reassembly_error < 1e-9 and c.cavity_error < 1e-9 and c.cavity_volume_change == 0.0
    assert out["body_pocket"] < 1e-7 and out["sheet_pocket"] < 1e-7  # the empty space is the cast, by hand
    assert mould.cast["side_sheet"].volume == pytest.approx(sheet, rel=1e-12) == out["sheet"]
    assert mould.cast["open_body"].volume == pytest.approx(out["upper"], rel=1e-12)
    plate = solid(mould.parts["base_plate"])
    for i, unit in enumerate(design):  # a plinth of the base plate, z = 1.5..4.5, under each L only
        probe = box((i * 10.5 + 0.2, i * 10.5 + 0.6, 0.2, 0.6, 2.0, 4.0))
        assert ((plate ^ probe).volume() > 0) == (unit == "L"), (design, i)


def test_a_mould_the_side_sheet_or_the_lid_cannot_serve_is_refused_in_one_line() -> None:
    from pneumorph.geometry.library import builtin_library

    with pytest.raises(GeometryError, match="no unit's face on z = width is free of its strip"):
        casting_mould(builtin_library("spatial"), "ll")
    thick = UnitSpec(layer_side=True, wall=3.0, cavity_height=6.0)  # turned over: a 3 mm wall under its cavity
    with pytest.raises(GeometryError, match=r"would be 1\.5 and 3 mm thick") as exc:
        MouldSpec().check(thick, "01")
    assert "\n" not in str(exc.value)

"""Unit types of the library (section 8.4): the new parameters, and earlier units described as before."""

from __future__ import annotations

import pytest

from pneumorph.errors import GeometryError
from pneumorph.geometry.features import check_passage
from pneumorph.geometry.grid import cross_section_lines
from pneumorph.geometry.unit import OPTIONAL_FIELDS, UnitSpec

#: UnitSpec().to_dict() as computed at commit 137ba49, before the unit types existed: model
#: fingerprints (chain tables, caches) hash this dictionary, so it must not change.
DEFAULT_DESCRIPTION = {
    "pitch": 10.5, "width": 15.0, "wall": 1.5, "side_wall": 1.5, "end_wall": 3.0, "layer": 3.0,
    "cavity_height": 6.0, "slit_width": 0.0, "slit_depth": 0.0, "end_cap": 0.0,
    "body_material": "mold_star_15", "layer_material": "smooth_sil_950", "element_size": 1.5,
    "element_order": 2, "name": "unit", "filler_coefficients": [], "filler_range_kpa": [0.0, 45.0],
    "filler_poisson_ratio": 0.3, "filler_source": "",
}


def test_the_default_unit_is_described_exactly_as_before() -> None:
    d = UnitSpec().to_dict()
    assert d == DEFAULT_DESCRIPTION
    assert list(d) == list(DEFAULT_DESCRIPTION)  # same keys in the same order (JSON text of provenance)
    assert [type(v) for v in d.values()] == [type(v) for v in DEFAULT_DESCRIPTION.values()]


@pytest.mark.parametrize("changes", [{"pitch": 7.0, "end_wall": 1.5}, {"slit_width": 1.0, "slit_depth": 6.0},
                                     {"element_size": 0.75, "name": "fine"}])
def test_existing_units_keep_their_description(changes: dict[str, object]) -> None:
    expected = {**DEFAULT_DESCRIPTION, **changes}
    assert UnitSpec(**changes).to_dict() == expected  # type: ignore[arg-type]


def test_new_fields_appear_only_away_from_their_default() -> None:
    for key, default in OPTIONAL_FIELDS.items():
        assert key not in UnitSpec(**{key: default}).to_dict()
    solid = UnitSpec(solid=True)
    assert solid.to_dict() == {**DEFAULT_DESCRIPTION, "solid": True}
    assert UnitSpec.from_dict(solid.to_dict()) == solid
    assert not solid.is_builtin_shape() and solid.filler_law() is None


def test_the_unit_types_share_the_default_cross_section_lines() -> None:
    default = cross_section_lines(UnitSpec())
    for unit in (UnitSpec(wall=3.0, layer=0.0), UnitSpec(solid=True), UnitSpec(pitch=7.0, end_wall=1.5)):
        y, z = cross_section_lines(unit)
        assert y.tolist() == default[0].tolist() and z.tolist() == default[1].tolist()


def test_an_extending_unit_has_no_layer_and_a_symmetric_section() -> None:
    u = UnitSpec(wall=3.0, layer=0.0)
    _, _, y0, y1 = u.cavity
    assert u.height == pytest.approx(12.0)
    assert y0 == pytest.approx(u.height - y1)  # the section is its own mirror image


def test_bad_unit_types_are_refused() -> None:
    with pytest.raises(GeometryError, match="layer must be >= 0"):
        UnitSpec(layer=-1.0)
    with pytest.raises(GeometryError, match="solid must be true or false"):
        UnitSpec(solid=1)  # type: ignore[arg-type]
    with pytest.raises(GeometryError, match="solid unit"):
        check_passage(UnitSpec(solid=True), 1.5)


@pytest.mark.parametrize("fidelity", ["2d", "3d"])
def test_the_shipped_chain_tables_describe_the_default_unit_as_it_is_described_now(fidelity: str) -> None:
    import json

    from pneumorph.models.chain.sources import shipped_path

    source = json.loads(shipped_path(fidelity).read_text(encoding="utf-8"))["source"]
    now = UnitSpec().to_dict()
    if fidelity == "3d":  # the 3D model has no filler: its description leaves the filler's fields out
        now = {k: v for k, v in now.items() if not k.startswith("filler_")}
    assert source["description"]["unit"] == now

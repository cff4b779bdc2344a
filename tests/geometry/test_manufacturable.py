"""A unit a user describes must be one a mould can cast: walls, layer, cavity and slit sizes, the unit's size."""

from __future__ import annotations

from pathlib import Path

import pytest

from pneumorph.cli import main
from pneumorph.errors import GeometryError, UnitLibraryError
from pneumorph.geometry.library import BUILTIN_LIBRARIES, UnitLibrary, builtin_library
from pneumorph.geometry.limits import (
    MAX_UNIT_MM,
    MIN_FEATURE_MM,
    MIN_WALL_MM,
    ManufacturingError,
    check_manufacturable,
)
from pneumorph.geometry.unit import UnitSpec

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(("text", "says"), [
    ("wall = 1e-6", "unit wall 1e-06 mm is thinner than the thinnest wall a mould casts, MIN_WALL_MM = 1 mm"),
    ("side_wall = 0.5", "unit side_wall 0.5 mm is thinner"),
    ("end_wall = 0.9\npitch = 8.0", "unit end_wall 0.9 mm is thinner"),
    ("layer = 0.2", "unit layer 0.2 mm is thinner"),
    ("cavity_height = 0.5", "unit cavity_height 0.5 mm is smaller than the smallest cavity or slit a mould casts, "
                            "MIN_FEATURE_MM = 1 mm"),
    ("end_wall = 4.9", "unit cavity length 0.7 mm is smaller"),  # 10.5 - 2 x 4.9
    ("slit_width = 0.3\nslit_depth = 4.0", "unit slit_width 0.3 mm is smaller"),
    ("pitch = 300.0", "unit pitch 300 mm is larger than a unit's mould part printed in one piece, MAX_UNIT_MM = 250"),
    ("width = 260.0", "unit width 260 mm is larger"),
])
def test_a_unit_file_a_mould_cannot_cast_is_refused(tmp_path: Path, text: str, says: str) -> None:
    path = tmp_path / "u.toml"
    path.write_text(f"[unit]\n{text}\n")
    with pytest.raises(ManufacturingError) as info:
        UnitSpec.from_toml(path)
    assert says in str(info.value) and "Ellis 2020" in str(info.value)


def test_the_limits_are_the_edges_of_what_passes() -> None:
    edge = UnitSpec(wall=MIN_WALL_MM, side_wall=MIN_WALL_MM, end_wall=MIN_WALL_MM, layer=MIN_WALL_MM,
                    cavity_height=MIN_FEATURE_MM, slit_width=MIN_FEATURE_MM, slit_depth=MIN_FEATURE_MM)
    check_manufacturable(edge)
    check_manufacturable(UnitSpec(pitch=MAX_UNIT_MM, width=MAX_UNIT_MM))
    check_manufacturable(UnitSpec(layer=0.0, wall=3.0))  # no layer, no slit: no part to check
    with pytest.raises(ManufacturingError, match="MIN_WALL_MM"):
        check_manufacturable(UnitSpec(wall=MIN_WALL_MM - 0.01))
    # units made inside an analysis (a tolerance's thinner walls) are not refused: only described ones are
    assert UnitSpec(wall=0.5).wall == 0.5


def test_every_shipped_unit_library_and_example_unit_passes() -> None:
    units = [u for name in BUILTIN_LIBRARIES for u in builtin_library(name).units]
    for path in sorted((ROOT / "examples").rglob("*.toml")):
        text = path.read_text(encoding="utf-8")
        if "[[units]]" in text:
            units += list(UnitLibrary.from_toml(path).units)
        elif text.lstrip().startswith("[unit]") or "\n[unit]" in text:
            units.append(UnitSpec.from_toml(path))
    assert len(units) >= 9
    for unit in units:
        check_manufacturable(unit)


def test_a_library_entry_a_mould_cannot_cast_names_its_entry() -> None:
    with pytest.raises(UnitLibraryError) as info:
        UnitLibrary.from_dict({"units": [{"symbol": "a", "unit": {}}, {"symbol": "t", "unit": {"wall": 1e-6}}]})
    assert str(info.value).startswith("unit library: unit 't' (entry 2): unit wall 1e-06 mm is thinner than the "
                                      "thinnest wall a mould casts, MIN_WALL_MM = 1 mm")
    assert isinstance(info.value, GeometryError)


def test_export_of_a_thin_unit_is_refused_before_any_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    unit = tmp_path / "thin.toml"
    unit.write_text("[unit]\nwall = 1e-6\n")
    out = tmp_path / "stl"
    assert main(["export", "0101", "--unit", str(unit), "--stl", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "MIN_WALL_MM" in err and "Traceback" not in err
    assert not out.exists()
    # the same unit inline in a model file
    model = tmp_path / "model.toml"
    model.write_text("[model]\n[model.unit]\nwall = 1e-6\n")
    assert main(["export", "0101", "--model-file", str(model), "--stl", str(out)]) == 2
    assert "MIN_WALL_MM" in capsys.readouterr().err and not out.exists()

"""Unit libraries: the built-in file, the file format, and every way a library can be wrong."""

from __future__ import annotations

from pathlib import Path

import pytest

from pneumorph.errors import GeometryError, PneumorphError, UnitLibraryError
from pneumorph.geometry.library import UnitLibrary, builtin_library, check_joinable
from pneumorph.geometry.unit import UnitSpec


def _write(folder: Path, text: str, name: str = "lib.toml") -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


def test_the_builtin_library_holds_the_default_unit_and_three_modes() -> None:
    lib = builtin_library()
    assert lib.symbols == ("a", "e", "r", "s") and lib.default == "a"
    assert lib["a"] == UnitSpec() and lib["a"].to_dict() == UnitSpec().to_dict()
    assert lib["e"].layer == 0 and lib["e"].cavity[2] == pytest.approx(lib["e"].height - lib["e"].cavity[3])
    assert lib["r"].solid and not lib["a"].solid
    assert lib["s"].pitch < lib["a"].pitch and lib["s"].cavity_length > 0
    assert builtin_library() == lib and builtin_library().fingerprint() == lib.fingerprint()


def test_a_library_file_takes_inline_units_and_unit_files(tmp_path: Path) -> None:
    _write(tmp_path, "[unit]\npitch = 7.0\nend_wall = 1.5\nname = 'short'\n", "short.toml")
    path = _write(tmp_path, """
[library]
name = "mine"
[[units]]
symbol = "b"
mode = "bending"
unit = {}
[[units]]
symbol = "s"
unit = "short.toml"
[[units]]
symbol = "r"
[units.unit]
solid = true
""")
    lib = UnitLibrary.from_toml(path)
    assert lib.name == "mine" and lib.symbols == ("b", "s", "r") and lib.default == "b"
    assert lib["s"] == UnitSpec(pitch=7.0, end_wall=1.5, name="short") and lib["r"] == UnitSpec(solid=True)
    assert lib.modes == ("bending", "short", "unit")  # an entry without a mode is labelled by its unit's name
    with pytest.raises(UnitLibraryError, match=r"no unit 'x' in 'mine'; its symbols: b, s, r"):
        lib["x"]


@pytest.mark.parametrize(("symbol", "message"), [
    ('"ab"', "one character"), ('""', "one character"), ("3", "one character"),
    ('"0"', "is a digit; the digits 0 and 1 write the orientation"),
    ('"A"', "is upper case; upper case writes a unit turned 180 degrees"),
    ('"#"', "not allowed; symbols are the lower-case letters a-z"),
    ('"é"', "not allowed"),
])
def test_bad_symbols_are_refused_with_the_reason(tmp_path: Path, symbol: str, message: str) -> None:
    path = _write(tmp_path, f"[[units]]\nsymbol = {symbol}\n")
    with pytest.raises(UnitLibraryError, match=message) as info:
        UnitLibrary.from_toml(path)
    assert str(path) in str(info.value) and "entry 1" in str(info.value)


def test_a_repeated_symbol_is_refused(tmp_path: Path) -> None:
    path = _write(tmp_path, '[[units]]\nsymbol = "a"\n[[units]]\nsymbol = "e"\n[[units]]\nsymbol = "a"\n')
    with pytest.raises(UnitLibraryError, match=r"symbol 'a' is given twice \(units 1 and 3\)"):
        UnitLibrary.from_toml(path)


@pytest.mark.parametrize(("text", "message"), [
    ('colour = "red"\n[[units]]\nsymbol = "a"\n', r"unknown key\(s\) colour in the file; known: library, units"),
    ('[library]\nnmae = "x"\n[[units]]\nsymbol = "a"\n', r"unknown key\(s\) nmae in \[library\]"),
    ('[[units]]\nsymbol = "a"\npitch = 7.0\n', r"unknown key\(s\) pitch in \[\[units\]\] entry 1; known: symbol"),
    ('[[units]]\nsymbol = "a"\nunit = {pich = 7.0}\n', r"unit 'a' \(entry 1\): unknown unit parameter\(s\) pich"),
    ('[[units]]\nmode = "x"\n', "entry 1 has no symbol"),
    ('[library]\nname = "x"\n', r"expected \[\[units\]\] entries"),
    ('[[units]]\nsymbol = "a"\nunit = 3\n', "a table of parameters or the path of a unit file"),
    ('[[units]]\nsymbol = "a"\nunit = "missing.toml"\n', r"unit 'a' \(entry 1\): .*missing.toml"),
    ("[[units]\n", "not valid TOML"),
])
def test_bad_library_files_get_one_clear_error(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(UnitLibraryError, match=message):
        UnitLibrary.from_toml(_write(tmp_path, text))


def test_a_unit_that_does_not_validate_is_named_by_its_symbol(tmp_path: Path) -> None:
    path = _write(tmp_path, '[[units]]\nsymbol = "a"\n[[units]]\nsymbol = "w"\nunit = {wall = -1.0}\n')
    with pytest.raises(UnitLibraryError, match=r"unit 'w' \(entry 2\): unit wall must be positive") as info:
        UnitLibrary.from_toml(path)
    assert isinstance(info.value, GeometryError) and isinstance(info.value, PneumorphError)


@pytest.mark.parametrize(("other", "message"), [
    (UnitSpec(cavity_height=4.5), "heights differ"),
    (UnitSpec(wall=2.0, cavity_height=5.0), r"grid lines across the height \(y\) differ"),
    (UnitSpec(element_size=0.75), "element_size differ"),
    (UnitSpec(width=18.0), "width differ"),
    (UnitSpec(body_material="ecoflex_0030"), "body_material differ"),
    (UnitSpec(layer_material="mold_star_15"), "stiff layers are of different materials"),
    (UnitSpec(end_cap=3.0), "end_cap differ"),
])
def test_units_that_cannot_be_joined_are_refused(other: UnitSpec, message: str) -> None:
    with pytest.raises(UnitLibraryError, match=rf"units 'a' and 'x' cannot be joined: .*{message}"):
        UnitLibrary(("a", "x"), (UnitSpec(), other))


def test_units_that_can_be_joined() -> None:
    # an extending unit has no layer, so its layer material does not count; a thicker wall on the 1.5 mm lines does
    check_joinable({"a": UnitSpec(), "e": UnitSpec(wall=3.0, layer=0.0, layer_material="ecoflex_0030"),
                    "t": UnitSpec(wall=3.0, cavity_height=3.0), "s": UnitSpec(pitch=7.0, end_wall=1.5)})

"""Designs over a library's alphabet : notation, canonical text, and clear errors."""

from __future__ import annotations

import pytest

from pneumorph.errors import OrientationError
from pneumorph.geometry.alphabet import Design, parse_design
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.geometry.orientation import mirror, parse_orientation
from pneumorph.geometry.unit import UnitSpec


@pytest.mark.parametrize("design", ["0", "0101", "1 1 0_0,1", [0, 1, 1]])
def test_zero_one_designs_are_unchanged_over_the_default_library(design: str | list[int]) -> None:
    d = parse_design(design, UnitLibrary.single())
    assert d.text == parse_orientation(design) == d.orientation
    assert d.symbols == "a" * len(d.text) and d.units(UnitLibrary.single()) == (UnitSpec(),) * len(d.text)
    assert d.mirror().text == mirror(d.text) and str(d) == d.text


def test_letters_give_type_and_orientation() -> None:
    lib = builtin_library()
    d = parse_design("aAeE rRsS", lib)
    assert (d.symbols, d.orientation, d.text) == ("aaeerrss", "01010101", "aAeErRsS")
    assert [u.name for u in d.units(lib)] == ["unit", "unit", "extending", "extending", "near_rigid", "near_rigid",
                                             "short", "short"]
    assert parse_design(d, lib) == d and parse_design(d.text, lib, n_units=8) == d
    assert d.mirror().text == "AaEeRrSs" and d.mirror().mirror() == d


def test_a_parsed_design_is_checked_against_the_library_not_read_again() -> None:
    lib = builtin_library()
    d = parse_design("aAeE", lib)
    assert parse_design(d, lib) is d  # parsed once: the same object
    one_type = parse_design("0110", UnitLibrary.single())
    assert parse_design(one_type, lib).text == "aAAa"  # the library's canonical text
    assert parse_design(parse_design("aAAa", lib), UnitLibrary.single()).text == "0110"
    with pytest.raises(OrientationError, match=r"uses 'e', which is no symbol of the unit library 'single'"):
        parse_design(d, UnitLibrary.single())
    with pytest.raises(OrientationError, match="has 4 units, expected 5"):
        parse_design(d, lib, n_units=5)


def test_digits_are_the_first_type_and_letters_of_a_one_type_library_read_as_digits() -> None:
    lib = builtin_library()
    assert parse_design("01e", lib) == parse_design("aAe", lib)
    assert parse_design("0110", lib).text == "aAAa"
    assert parse_design([1, 0], lib).text == "Aa"
    assert parse_design("aAa", UnitLibrary.single()).text == "010"


@pytest.mark.parametrize(("design", "message"), [
    ("aXe", r"design 'aXe' contains 'X', which is no symbol of the unit library 'builtin'; allowed: a/A \(bending\)"),
    ("a2qe", r"contains '2', 'q', which are no symbol"),
    ("a e #", r"contains '#'"),
])
def test_unknown_symbols_are_named_with_the_allowed_ones(design: str, message: str) -> None:
    with pytest.raises(OrientationError, match=message) as info:
        parse_design(design, builtin_library())
    assert "e/E (extending), r/R (near-rigid), s/S (short-pitch), and 0/1 for a" in str(info.value)


def test_a_one_type_library_names_its_only_symbol() -> None:
    with pytest.raises(OrientationError, match="only the digits 0 and 1 are allowed"):
        parse_design("012", UnitLibrary.single())  # parse_orientation's message, as before
    with pytest.raises(OrientationError, match=r"contains 'e', .*allowed: a/A \(unit\), and 0/1 for a"):
        parse_design("aae", UnitLibrary.single())


@pytest.mark.parametrize(("design", "n", "message"), [
    ("", None, "empty"), (" , ", None, "empty"), ("aae", 4, "has 3 units, expected 4"), ("012", None, r"contains '2'"),
    ("0101", 3, "has 4 units, expected 3"), ("a" * 101, None, "at most 100"),
])
def test_empty_long_and_wrong_length_designs_are_refused(design: str, n: int | None, message: str) -> None:
    with pytest.raises(OrientationError, match=message):
        parse_design(design, builtin_library(), n_units=n)


def test_a_design_is_plain_hashable_data() -> None:
    d = parse_design("aEr", builtin_library())
    assert {d: 1}[Design("aer", "010", "aEr")] == 1

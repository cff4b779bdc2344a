"""Orientation vectors: validation and mirroring."""

import pytest

from pneumorph.errors import OrientationError
from pneumorph.geometry import mirror, parse_orientation


def test_accepts_strings_and_sequences() -> None:
    assert parse_orientation("010 011", 6) == "010011"
    assert parse_orientation((0, 1, 1)) == "011"


@pytest.mark.parametrize(
    ("design", "n", "message"),
    [
        ("", None, "empty"),
        ("0102", None, "'2'"),
        ("01a1", None, "'a'"),
        ("0101", 5, "has 4 units, expected 5"),
        ([0, "x"], None, "sequence of 0/1"),
    ],
)
def test_rejects_bad_designs(design, n, message) -> None:
    with pytest.raises(OrientationError, match=message):
        parse_orientation(design, n)


def test_mirror_inverts_every_unit() -> None:
    assert mirror("000111010") == "111000101"
    assert mirror(mirror("0110")) == "0110"

"""Turning and switch pressures of a tip path (hand-computed cases)."""

from __future__ import annotations

import pytest

from pneumorph.bimodal.switch import find_switch


def test_switch_interpolates_the_sign_change() -> None:
    s = find_switch([5, 10, 15, 20, 25], [0.5, 1.5, 1.0, 0.25, -0.75])
    assert (s.first_direction, s.turning, s.peak) == (1, 10.0, 1.5)
    assert s.switch == pytest.approx(20 + 5 * 0.25 / 1.0)


def test_first_direction_negative() -> None:
    s = find_switch([1, 2, 3], [-1.0, -0.5, 2.0])
    assert (s.first_direction, s.turning, s.peak) == (-1, 1.0, -1.0)
    assert s.switch == pytest.approx(2 + 0.5 / 2.5)


def test_turning_without_switch() -> None:
    s = find_switch([1, 2, 3], [1.0, 2.0, 1.5])
    assert (s.turning, s.switch) == (2.0, None)


def test_monotonic_path_has_neither() -> None:
    s = find_switch([1, 2, 3], [1.0, 2.0, 3.0])
    assert (s.turning, s.peak, s.switch) == (None, None, None)
    assert s.to_dict()["switch_kpa"] is None


def test_empty_and_mismatched() -> None:
    assert find_switch([], []).first_direction == 0
    with pytest.raises(ValueError, match="equal length"):
        find_switch([1, 2], [1.0])

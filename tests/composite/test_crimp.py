"""Analytical transition strain, Eqs 3.1-3.4, against Table 3.3 and closed forms."""

from __future__ import annotations

import math

import pytest

from pneumorph.composite.crimp import (
    Crimp,
    effective_length,
    flute_count,
    flute_length,
    limit_transition_strain,
    transition_strain,
)
from pneumorph.errors import CrimpError, PneumorphError

L0 = 176.25  # mm, Fig 3.4
A = 1.5  # mm, section 3.2.1


@pytest.mark.parametrize(("cr", "printed"), [(0.25, 39.0), (0.3, 54.4)])
def test_table_3_3_analytical_column(cr: float, printed: float) -> None:
    """Table 3.3, 'Analytical': 39.0 % and 54.4 % for L0 = 176.25 mm, to 0.5 percentage points."""
    eps = Crimp.from_ratio(cr, A, L0).transition_strain
    assert 100 * eps == pytest.approx(printed, abs=0.5)


def test_crimp_ratio_0_2_gives_what_the_equations_give() -> None:
    """CR 0.2: lambda = 7.5 mm, s = sqrt(3^2 + 3.75^2), N = (176.25 - 3.75) / 7.5 = 23 exactly.

    Eq 3.4 gives (46 s - L0) / L0 = 25.34 %, not the printed 27.9 % (see docs/composite.md).
    """
    c = Crimp.from_ratio(0.2, A, L0)
    s = math.sqrt(9.0 + 3.75**2)
    assert c.flutes == 23.0
    assert c.transition_strain == pytest.approx((46 * s - L0) / L0, rel=1e-14)
    assert 100 * c.transition_strain == pytest.approx(25.34, abs=0.005)
    # the printed 27.9 % is 2.6 points above, and 0.16 points below the whole-length limit
    assert 100 * c.limit_transition_strain == pytest.approx(28.06, abs=0.005)


def test_equations_by_hand() -> None:
    # 3-4-5 triangle: 2A = 3, lambda/2 = 4 -> s = 5
    assert flute_length(1.5, 8.0) == 5.0
    assert flute_count(100.0, 8.0) == pytest.approx(12.0)  # (100 - 4) / 8
    assert effective_length(1.5, 8.0, 100.0) == pytest.approx(120.0)  # 2 * 12 * 5
    assert transition_strain(1.5, 8.0, 100.0) == pytest.approx(0.20)
    assert limit_transition_strain(1.5, 8.0) == pytest.approx(0.25)


@pytest.mark.parametrize("cr", [0.2, 0.25, 0.3])
def test_eq_3_4_falls_short_of_the_whole_length_limit_by_s_over_L0(cr: float) -> None:
    """Eq 3.4 = (2 s / lambda)(1 - lambda / (2 L0)) - 1, so limit - Eq 3.4 = s / L0 exactly."""
    c = Crimp.from_ratio(cr, A, L0)
    assert c.limit_transition_strain - c.transition_strain == pytest.approx(c.flute_length / L0, rel=1e-12)


def test_transition_grows_with_crimp_ratio() -> None:
    eps = [Crimp.from_ratio(cr, A, L0).transition_strain for cr in (0.2, 0.25, 0.3)]
    assert eps[0] < eps[1] < eps[2]


def test_wave_shape() -> None:
    c = Crimp(amplitude=1.5, wavelength=6.0, length=60.0)
    assert [float(c.y(x)) for x in (0.0, 1.5, 3.0, 4.5, 6.0, 7.5)] == pytest.approx([0, 1.5, 0, -1.5, 0, 1.5])
    assert c.to_dict()["crimp_ratio"] == 0.25


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"amplitude": 0.0, "wavelength": 5.0, "length": 176.25}, "amplitude"),
        ({"amplitude": -1.5, "wavelength": 5.0, "length": 176.25}, "amplitude"),
        ({"amplitude": 1.5, "wavelength": 0.0, "length": 176.25}, "wavelength"),
        ({"amplitude": 1.5, "wavelength": 200.0, "length": 176.25}, "longer than the coupon"),
        ({"amplitude": 1.5, "wavelength": 5.0, "length": -1.0}, "length"),
        ({"amplitude": float("nan"), "wavelength": 5.0, "length": 176.25}, "amplitude"),
        ({"amplitude": 1.5, "wavelength": float("inf"), "length": 176.25}, "wavelength"),
    ],
)
def test_impossible_crimps_are_rejected(kwargs: dict[str, float], message: str) -> None:
    with pytest.raises(CrimpError, match=message) as info:
        Crimp(**kwargs)
    assert isinstance(info.value, PneumorphError) and isinstance(info.value, ValueError)


@pytest.mark.parametrize("cr", [0.0, -0.3, float("nan")])
def test_non_positive_crimp_ratio_is_rejected(cr: float) -> None:
    with pytest.raises(CrimpError, match="crimp ratio"):
        Crimp.from_ratio(cr, A, L0)


def test_crimp_ratio_too_small_for_the_coupon() -> None:
    """CR 0.005 with A = 1.5 mm means lambda = 300 mm, longer than L0."""
    with pytest.raises(CrimpError, match="300 mm is longer than the coupon"):
        Crimp.from_ratio(0.005, A, L0)

"""Virtual strain gauges (section 3.2.6) and the sample size of Eq 3.5."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pneumorph.composite.coupon import CouponResult
from pneumorph.composite.gauges import (
    Gauges,
    gauge_strains,
    gauge_study,
    place_gauges,
    sample_size,
)


def test_eq_3_5_gives_385() -> None:
    """95 % confidence (Z = 1.96), 5 % margin, spread 0.5: 1.96^2 x 0.25 / 0.05^2 = 384.15 -> 385."""
    assert sample_size(0.95, 0.05, 0.5) == 385
    assert sample_size() == 385
    z99 = 2.5758293035489
    assert sample_size(0.99, 0.05, 0.5) == math.ceil(z99**2 * 0.25 / 0.0025)
    assert sample_size(0.95, 0.05, 0.2) == math.ceil(1.959963984540054**2 * 0.16 / 0.0025)
    with pytest.raises(ValueError, match="margin"):
        sample_size(margin=0.0)


def test_placement_is_seeded_and_inside_the_surface() -> None:
    a = place_gauges(500, 176.25, np.random.default_rng(7))
    b = place_gauges(500, 176.25, np.random.default_rng(7))
    assert np.array_equal(a.start, b.start) and np.array_equal(a.length, b.length)
    assert set(np.unique(a.length)) == {5.0 * k for k in range(1, 11)}
    assert np.all(a.start >= 0.0) and np.all(a.start + a.length <= 176.25)
    with pytest.raises(ValueError, match="fits"):
        place_gauges(3, 4.0, np.random.default_rng(0))


def _periodic_surface(period: float, mean: float = 0.3, amp: float = 0.5):
    """Local strain mean + amp cos(2 pi X / period): x(X) = (1 + mean) X + amp p/(2 pi) sin(2 pi X / p)."""
    x0 = np.linspace(0.0, 150.0, 6001)
    x = (1 + mean) * x0 + amp * period / (2 * np.pi) * np.sin(2 * np.pi * x0 / period)
    return x0, x


def test_gauges_of_whole_periods_read_the_mean_exactly() -> None:
    """Lengths in multiples of 5 mm on a 5 mm periodic strain: every gauge reads the mean (why
    the dissertation ties the 5 mm step to the wavelength)."""
    x0, x = _periodic_surface(5.0)
    g = place_gauges(385, 150.0, np.random.default_rng(3))
    assert np.allclose(gauge_strains(g, x0, x), 0.3, atol=1e-6)


def _expectation(x0: np.ndarray, xs: np.ndarray, span: float) -> np.ndarray:
    """Mean gauge strain over the placement distribution (uniform length step, uniform start)."""
    lengths = [5.0 * k for k in range(1, 11) if 5.0 * k <= span]
    total = 0.0
    for L in lengths:
        starts = np.linspace(0.0, span - L, 8001)
        vals = gauge_strains(Gauges(start=starts, length=np.full(starts.size, L)), x0, xs)
        total = total + np.trapezoid(vals, starts, axis=-1) / (span - L)
    return np.asarray(total) / len(lengths)


def test_gauge_average_converges_to_the_surface_average() -> None:
    """7.5 mm period (CR 0.2): single gauges scatter, their average converges as 1/sqrt(n).

    The limit is the expectation over the placement; it differs from the surface average
    (0.3) only because gauge starts are uniform where the gauge fits, which covers the two
    ends less: for the amplitude ``a`` and period ``p`` the difference is at most
    ``a p^2 / (pi^2 L (S - L))`` for a gauge of length L on a surface of length S.
    """
    x0, x = _periodic_surface(7.5)
    errors = {}
    for n in (10, 385, 10000):
        errs = [abs(gauge_strains(place_gauges(n, 150.0, np.random.default_rng(s)), x0, x).mean() - 0.3)
                for s in range(20)]
        errors[n] = float(np.sqrt(np.mean(np.square(errs))))
    assert errors[10] > errors[385] > errors[10000]
    single = gauge_strains(place_gauges(1000, 150.0, np.random.default_rng(0)), x0, x)
    assert single.std() > 0.01  # single gauges do scatter
    expectation = float(_expectation(x0, x, 150.0))
    bound = np.mean([0.5 * 7.5**2 / (np.pi**2 * L * (150.0 - L)) for L in 5.0 * np.arange(1, 11)])
    assert abs(expectation - 0.3) <= bound
    mean = gauge_strains(place_gauges(10000, 150.0, np.random.default_rng(99)), x0, x).mean()
    assert abs(mean - expectation) < 4 * single.std() / np.sqrt(10000)


def test_gauges_on_the_simulated_coupon(coarse_coupons: dict[float, CouponResult]) -> None:
    """On the FE surface the average of many gauges converges to its expectation over the
    placement (computed by quadrature), which weights the coupon's ends less than the
    averaged surface strain does; with CR 0.3 (lambda = 5 mm) the gauge transition is the
    engineering one."""
    r = coarse_coupons[0.3]
    x0, xs = r.surface_x0, r.surface[:, :, 0]
    span = x0[-1] - x0[0]
    expectation = _expectation(x0, xs, span)
    errors = {}
    for n in (10, 385, 5000):
        errs = [np.max(np.abs(gauge_strains(place_gauges(n, span, np.random.default_rng(s)), x0, xs).mean(axis=1)
                              - expectation)) for s in range(10)]
        errors[n] = float(np.mean(errs))
    assert errors[10] > errors[385] > errors[5000]
    assert errors[5000] < 0.002

    study = gauge_study(r, rng=11)
    assert len(study.gauges) == 385
    assert study.transition_strain == pytest.approx(r.transition("engineering").transition_strain, abs=0.005)
    assert study.gauge_transitions.size > 0.9 * 385
    assert study.std_transition >= 0.0

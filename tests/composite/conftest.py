"""Coarse composite coupons shared by the tests (about one second each)."""

from __future__ import annotations

import pytest

from pneumorph.composite.coupon import CouponResult, CouponSpec, simulate_coupon

#: Short coupon with one cell per flute and per row: the transition of a coupon crimped
#: from end to end does not depend on its length (it is 2 s / lambda - 1).
COARSE_LENGTH = 60.0
LEVELS = 30


def coarse_strain_max(spec: CouponSpec) -> float:
    """Run far enough past the knee that the last ten of 30 levels lie on the stiff branch."""
    return 1.5 * spec.crimp.limit_transition_strain + 0.05


@pytest.fixture(scope="session")
def coarse_coupons() -> dict[float, CouponResult]:
    """FE coupons of the three crimp ratios of Table 3.1 (coarse mesh, 60 mm long)."""
    out = {}
    for cr in (0.2, 0.25, 0.3):
        spec = CouponSpec.from_ratio(cr, length=COARSE_LENGTH, per_flute=1, rows=1)
        out[cr] = simulate_coupon(spec, strain_max=coarse_strain_max(spec), levels=LEVELS)
    return out

"""The 3D fibre law of the composite against chapter 3's analytic model and the plane-strain FE coupon."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.bimodal.paper import THICKNESS, paper_composite, uniaxial_stress
from pneumorph.composite import Crimp
from pneumorph.composite.coupon import CouponResult
from pneumorph.errors import CrimpError
from pneumorph.materials import get
from pneumorph.materials.characterisation.analyses import bilinear

#: Table 3.3's printed analytical transition strains
TABLE_3_3_ANALYTICAL = {0.2: 0.279, 0.25: 0.390, 0.3: 0.544}


def law_curve(cr: float, coupon: CouponResult) -> np.ndarray:
    """The law's force per mm of width (N/mm) at the coupon's engineering strains, in the coupon's plane strain."""
    return THICKNESS * uniaxial_stress(paper_composite(cr), 1.0 + coupon.engineering_strain, plane_strain=True)


@pytest.mark.parametrize("cr", [0.2, 0.25, 0.3])
def test_transition_strain_within_ten_percent_of_the_analytic_model(coarse_coupons: dict[float, CouponResult],
                                                                    cr: float) -> None:
    """The two-line transition of the law's own stress-strain curve (as section 3.2.6 reads a test) lies within
    10 % of the analytic model for a crimp over the whole length (2 s / lambda - 1) and of Table 3.3's printed
    analytical values."""
    coupon = coarse_coupons[cr]
    eps = bilinear(coupon.engineering_strain, law_curve(cr, coupon), secondary_points=10).transition_strain
    analytic = Crimp.from_ratio(cr, 1.5, 176.25).limit_transition_strain
    assert eps == pytest.approx(analytic, rel=0.10)
    assert eps == pytest.approx(TABLE_3_3_ANALYTICAL[cr], rel=0.10)
    # and the plane-strain coupon's FE transition to 0.1 percentage points
    assert eps == pytest.approx(coupon.transition("engineering").transition_strain, abs=1e-3)


@pytest.mark.parametrize("cr", [0.2, 0.25, 0.3])
def test_stiff_branch_is_the_coupons(coarse_coupons: dict[float, CouponResult], cr: float) -> None:
    """Past the transition the law carries the straight paper's ``E t L0 / L_paper`` per unit strain, as the coupon
    does, and the same force at the same strain."""
    coupon = coarse_coupons[cr]
    force = law_curve(cr, coupon)
    paper = get("paper_purco_80gsm")
    assert paper.youngs_modulus is not None and paper.thickness is not None
    straight = paper.youngs_modulus.value * paper.thickness.value / (1.0 + Crimp.from_ratio(cr, 1.5, 60.0)
                                                                     .limit_transition_strain)
    line = bilinear(coupon.engineering_strain, force, secondary_points=10)
    assert line.secondary_modulus == pytest.approx(straight, rel=2e-3)
    assert line.secondary_modulus == pytest.approx(coupon.transition("engineering").secondary_modulus, rel=2e-3)
    np.testing.assert_allclose(force[-10:], coupon.force[-10:], rtol=0.01)


def test_stiffens_along_the_crimp_not_across() -> None:
    law = paper_composite(0.2)
    along, across = uniaxial_stress(law, [1.4]), uniaxial_stress(law, [1.4], axis=2)
    assert along[0] > 100 * across[0]
    assert across[0] == pytest.approx(float(uniaxial_stress(paper_composite(0.3), [1.4], axis=2)[0]), rel=1e-12)


def test_bad_layers() -> None:
    with pytest.raises(CrimpError):
        paper_composite(0.2, thickness=2.0)
    with pytest.raises(CrimpError):
        paper_composite(-0.2)
    with pytest.raises(CrimpError):
        paper_composite(0.2, paper="mold_star_15")
    with pytest.raises(CrimpError):
        paper_composite(0.2, transition=0.01)  # inside the blend


def test_a_measured_transition_strain() -> None:
    """Table 3.2's measured 15.2 % for CR 0.2 in place of the analytic 28.1 %: the paper straightens there and its
    slope is the straight paper's over that length, E t / (H 1.152)."""
    law = paper_composite(0.2, transition=0.152)
    assert law.straight == pytest.approx(1.152, rel=1e-12)
    assert law.slope == pytest.approx(6500.0 * 0.107 / (5.0 * 1.152), rel=1e-3)
    stress = uniaxial_stress(law, [1.12, 1.25]) - uniaxial_stress(paper_composite(0.3), [1.12, 1.25])
    np.testing.assert_allclose(stress, [0.0, law.slope * (1.25 - 1.152)], rtol=1e-9, atol=1e-12)

"""The 3D fibre law of the composite against the plane-strain FE coupon: table and figure of docs/bimodal.md.

For each crimp ratio: the coupon of :mod:`pneumorph.composite.coupon` (60 mm long, one cell per
flute and per row, as the tests' coarse coupons) and the law of
:func:`pneumorph.bimodal.paper.paper_composite` pulled along the crimp in the coupon's plane
strain, both read by the two-line method of section 3.2.6; the figure is
docs/figures/bimodal-paper-calibration.png.

    OMP_NUM_THREADS=1 python docs/scripts/paper_calibration.py
"""

from __future__ import annotations

from pathlib import Path

from pneumorph.bimodal.paper import THICKNESS, paper_composite, uniaxial_stress
from pneumorph.composite import Crimp
from pneumorph.composite.coupon import CouponSpec, simulate_coupon
from pneumorph.materials.characterisation.analyses import bilinear
from pneumorph.plot.figure import new_figure, save_figure

DOCS = Path(__file__).resolve().parents[1]
TABLE_3_3 = {0.2: 27.9, 0.25: 39.0, 0.3: 54.4}


def main() -> None:
    fig = new_figure(6.4, 4.2)
    ax = fig.add_subplot(1, 1, 1)
    print("| CR | Eq 3.4 (L0 = 176.25 mm) | 2 s / lambda - 1 | Table 3.3 analytical | coupon FE | 3D law "
          "| law / analytic | coupon stiff slope (N) | law stiff slope (N) | coupon primary (kPa) "
          "| law primary (kPa) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for cr, colour in zip((0.2, 0.25, 0.3), ("C0", "C1", "C2"), strict=True):
        spec = CouponSpec.from_ratio(cr, length=60.0, per_flute=1, rows=1)
        coupon = simulate_coupon(spec, strain_max=1.5 * spec.crimp.limit_transition_strain + 0.05, levels=30)
        e = coupon.engineering_strain
        force = THICKNESS * uniaxial_stress(paper_composite(cr), 1.0 + e, plane_strain=True)
        c, law = coupon.transition("engineering"), bilinear(e, force, secondary_points=10)
        analytic = spec.crimp.limit_transition_strain
        print(f"| {cr:g} | {100 * Crimp.from_ratio(cr, 1.5, 176.25).transition_strain:.2f} | {100 * analytic:.2f} "
              f"| {TABLE_3_3[cr]:.1f} | {100 * c.transition_strain:.2f} | **{100 * law.transition_strain:.2f}** "
              f"| {law.transition_strain / analytic:.4f} | {c.secondary_modulus:.1f} | {law.secondary_modulus:.1f} "
              f"| {1e3 * c.primary_modulus / THICKNESS:.1f} | {1e3 * law.primary_modulus / THICKNESS:.1f} |")
        ax.plot(100 * e, coupon.force, "o", ms=3, color=colour, label=f"CR {cr:g}, coupon FE (2D, paper as trusses)")
        ax.plot(100 * e, force, "-", color=colour, label=f"CR {cr:g}, 3D fibre law (plane strain)")
    ax.set_xlabel("engineering strain (%)")
    ax.set_ylabel("force per mm of width (N/mm)")
    ax.set_ylim(-2, 60)
    ax.legend(fontsize=7)
    ax.set_title("The crimped paper as fibres against the coupon")
    save_figure(fig, DOCS / "figures" / "bimodal-paper-calibration.png",
                description="coupon FE and the 3D fibre law, force against engineering strain")


if __name__ == "__main__":
    main()

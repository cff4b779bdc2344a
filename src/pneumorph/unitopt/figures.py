"""The figure of the unit optimisation: Omega against h_b, the front and the base unit (drawing only)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from pneumorph.plot.figure import new_figure, save_figure

if TYPE_CHECKING:
    from pneumorph.unitopt.records import UnitOptimisation


def plot_front(result: UnitOptimisation, path: str | Path) -> Path:
    """Every solved candidate (h_b, Omega), the Pareto front, the chosen points and the base unit.

    Grey: feasible candidates; red crosses: over the strain limit; the front as a line with
    its points; the base unit (the built-in one) as a star. Failed ramps are not drawn
    (they have no Omega at the design pressure); the title counts them.
    """
    fig = new_figure(6.0, 4.5)
    ax = fig.add_subplot()
    limit = result.settings.strain_limit
    ok = [c for c in result.candidates if c.measures is not None]
    feasible = [c.measures for c in ok if c.feasible(limit) and c.measures is not None]
    over = [c.measures for c in ok if not c.feasible(limit) and c.measures is not None]
    ax.scatter([m.balloon_mm for m in feasible], [m.omega_deg for m in feasible], s=12, color="0.6",
               label=f"feasible ({len(feasible)})")
    if over:
        ax.scatter([m.balloon_mm for m in over], [m.omega_deg for m in over], s=16, marker="x", color="tab:red",
                   label=f"strain > {limit:g} ({len(over)})")
    front = [c.measures for c in result.front if c.measures is not None]
    ax.plot([m.balloon_mm for m in front], [m.omega_deg for m in front], "o-", color="tab:blue", ms=5,
            label=f"Pareto front ({len(front)})")
    for label, c in result.chosen().items():
        if c.measures is not None:
            ax.annotate(label, (c.measures.balloon_mm, c.measures.omega_deg), textcoords="offset points",
                        xytext=(5, -10), fontsize=8)
    b = result.base.measures
    if b is not None:
        ax.plot([b.balloon_mm], [b.omega_deg], "*", color="tab:orange", ms=14, label="built-in unit")
    failed = len(result.candidates) - len(ok)
    s = result.settings
    ax.set_xlabel("ballooning height h_b (mm)")
    ax.set_ylabel("bending angle per unit Omega (deg)")
    ax.set_title(f"unit optimisation: {len(result.candidates)} units, {failed} failed ramps; "
                 f"{s.pressure * 1e3:g} kPa, {s.n_units}-unit 3D probe", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path, description=f"unit optimisation front, seed {s.seed}")


__all__ = ["plot_front"]

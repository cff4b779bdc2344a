"""Figures of the composite coupon: load-strain curves (Fig 3.7), deformed shape (Fig 3.4),
surface strain over half a wavelength (Fig 3.5) and transition strains (Fig 3.8).

Each function returns a matplotlib Figure and saves it when given a path; the pneumorph
version and the coupon data go into a caption.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any, cast

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.layout_engine import ConstrainedLayoutEngine

from pneumorph import __version__
from pneumorph.composite.coupon import CouponResult
from pneumorph.plot.figure import new_figure, save_figure


def _caption(fig: Figure, text: str) -> None:
    """Provenance line under the axes (space for it is kept free by the layout)."""
    cast(ConstrainedLayoutEngine, fig.get_layout_engine()).set(rect=(0.0, 0.035, 1.0, 0.965))
    fig.text(0.005, 0.005, f"pneumorph {__version__} | {text}", fontsize=6, color="0.4", va="bottom")


def _save(fig: Figure, path: str | Path | None, dpi: int) -> None:
    if path is not None:
        save_figure(fig, path, dpi=dpi)


def _label(r: CouponResult) -> str:
    return f"CR {r.spec.crimp.crimp_ratio:.3g}"


def plot_load_strain(results: Sequence[CouponResult], path: str | Path | None = None, dpi: int = 150) -> Figure:
    """Force against averaged surface strain and engineering strain, with the two-line fits.

    Examples
    --------
    >>> from pneumorph.composite.coupon import CouponSpec, simulate_coupon
    >>> r = simulate_coupon(CouponSpec.from_ratio(0.3, length=20.0, per_flute=1, rows=1), levels=14)
    >>> len(plot_load_strain([r]).axes)
    4
    """
    fig = new_figure(10, 7.0)
    grid = fig.subplots(2, 2, sharex="col")
    knee = 0.0
    for row, zoom in ((grid[0], False), (grid[1], True)):
        titles = ("Averaged surface strain", "Engineering strain")
        for ax, kind, title in zip(row, ("surface", "engineering"), titles, strict=True):
            for i, r in enumerate(results):
                colour = f"C{i}"
                eps = r.strain(kind)  # type: ignore[arg-type]
                t = r.transition(kind)  # type: ignore[arg-type]
                knee = max(knee, float(np.interp(t.transition_strain, eps, r.force)))
                ax.plot(100 * eps, r.force, "-", color=colour, lw=1.4,
                        label=f"{_label(r)}: transition {100 * t.transition_strain:.1f} %")
                xs = np.array([0.0, t.transition_strain])
                ax.plot(100 * xs, t.primary.slope * xs + t.primary.intercept, ":", color=colour, lw=0.9)
                xs2 = np.array([t.transition_strain, eps[-1]])
                ax.plot(100 * xs2, t.secondary.slope * xs2 + t.secondary.intercept, "--", color=colour, lw=0.9)
                ax.plot(100 * t.transition_strain, t.transition_stress, "o", color=colour, ms=4)
            ax.grid(alpha=0.3)
            if zoom:
                ax.set_xlabel(f"{title} (%)")
            else:
                ax.set_title(title)
                ax.legend(fontsize=8, loc="upper left")
    top = max(float(np.max(r.force)) for r in results)
    grid[0, 0].set_ylim(-0.02 * top, 1.02 * top)
    grid[0, 1].set_ylim(-0.02 * top, 1.02 * top)
    grid[1, 0].set_ylim(0.0, 3.0 * knee)
    grid[1, 1].set_ylim(0.0, 3.0 * knee)
    grid[0, 0].set_ylabel("Force (N per mm of width)")
    grid[1, 0].set_ylabel("Force, primary branch (N per mm)")
    specs = results[0].spec
    _caption(fig, f"plane strain, L0 {specs.crimp.length:g} mm, T {specs.thickness:g} mm, "
                  f"A {specs.crimp.amplitude:g} mm, {specs.matrix} + {specs.paper}; two-line fits dotted/dashed")
    _save(fig, path, dpi)
    return fig


def _level_at(result: CouponResult, strain: float | None) -> int:
    if strain is None:
        return len(result.force) - 1
    return int(np.argmin(np.abs(result.engineering_strain - strain)))


def plot_deformed(
    result: CouponResult,
    strain: float | None = None,
    window: float | None = None,
    path: str | Path | None = None,
    dpi: int = 150,
) -> Figure:
    """Deformed coupon over its faint reference outline (cf. Fig 3.4).

    Parameters
    ----------
    result : CouponResult
        Its ``snapshots`` must hold the level nearest ``strain``.
    strain : float, optional
        Engineering strain to show (nearest kept level); default the last level.
    window : float, optional
        Width (mm, reference) of the zoomed centre panel; default four wavelengths.
    """
    level = _level_at(result, strain)
    if level not in result.snapshots:
        kept = ", ".join(f"{result.engineering_strain[k]:.3g}" for k in sorted(result.snapshots))
        raise ValueError(f"no displacement snapshot at strain {result.engineering_strain[level]:.3g}; kept: {kept}")
    u = result.snapshots[level]
    x0, x = result.points, result.points + u
    crimp = result.spec.crimp
    window = 4 * crimp.wavelength if window is None else window
    fig = new_figure(11, 4.6)
    ax_all, ax_zoom = fig.subplots(2, 1, height_ratios=(1, 2))
    edges = np.concatenate([result.quads[:, [0, 1]], result.quads[:, [1, 2]], result.quads[:, [2, 3]],
                            result.quads[:, [3, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    centre = 0.5 * crimp.length
    lo, hi = centre - window / 2, centre + window / 2
    for ax, zoom in ((ax_all, False), (ax_zoom, True)):
        sel = np.ones(len(edges), dtype=bool)
        if zoom:
            sel = np.all((x0[edges, 0] >= lo - 1e-9) & (x0[edges, 0] <= hi + 1e-9), axis=1)
        segs0, segs = x0[edges[sel]], x[edges[sel]]
        # the deformed centre window is shifted back so that both outlines overlap
        shift = 0.0
        if zoom:
            mid_nodes = np.unique(edges[sel])
            shift = float(np.mean(x[mid_nodes, 0] - x0[mid_nodes, 0]))
        ax.add_collection(LineCollection(segs0, colors="mediumpurple", linewidths=0.3, alpha=0.5))
        ax.add_collection(LineCollection(segs - np.array([shift, 0.0]), colors="0.25", linewidths=0.35))
        p = result.paper_nodes
        keep = np.ones(p.size, dtype=bool)
        if zoom:
            keep = (x0[p, 0] >= lo - 1e-9) & (x0[p, 0] <= hi + 1e-9)
        ax.plot(x0[p[keep], 0], x0[p[keep], 1], color="mediumpurple", lw=1.0, alpha=0.7)
        ax.plot(x[p[keep], 0] - shift, x[p[keep], 1], color="C3", lw=1.4)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)" if not zoom else f"x (mm); deformed centre shifted back by {shift:.1f} mm")
        ax.set_ylabel("y (mm)")
    ax_all.set_title(f"{_label(result)}: end displacement {result.engineering_strain[level] * crimp.length:.1f} mm "
                     f"(engineering strain {100 * result.engineering_strain[level]:.1f} %)")
    _caption(fig, "faint purple: reference; grey: deformed mesh; red: paper")
    _save(fig, path, dpi)
    return fig


def half_wave_profile(result: CouponResult, strain: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Nodal axial surface strain from above the centre peak to above the next valley.

    Returns reference distances from the peak (mm) and the strain at the top-surface nodes
    (mean of the two adjacent segment strains) at the level nearest ``strain``.
    """
    level = _level_at(result, strain)
    _, seg = result.surface_profile(level)
    x0 = result.surface_x0
    nodal = np.empty_like(x0)
    nodal[1:-1] = 0.5 * (seg[1:] + seg[:-1])
    nodal[0], nodal[-1] = seg[0], seg[-1]
    crimp = result.spec.crimp
    peak = 0.5 * crimp.length
    sel = (x0 >= peak - 1e-9) & (x0 <= peak + crimp.wavelength / 2 + 1e-9)
    return x0[sel] - peak, nodal[sel]


def plot_surface_strain(
    result: CouponResult, strain: float | None = None, path: str | Path | None = None, dpi: int = 150
) -> Figure:
    """Surface strain along half a wavelength, peak to valley of the paper (cf. Fig 3.5)."""
    level = _level_at(result, strain)
    d, e = half_wave_profile(result, strain)
    fig = new_figure(6.4, 4.0)
    ax = fig.subplots()
    ax.plot(d, 100 * e, "o-", ms=3)
    ax.axhline(100 * result.surface_strain[level], color="0.5", ls="--", lw=0.8,
               label=f"averaged surface strain {100 * result.surface_strain[level]:.1f} %")
    ax.set_xlabel("distance along the surface from above a paper peak (mm, reference)")
    ax.set_ylabel("axial surface strain (%)")
    ax.set_title(f"{_label(result)} at engineering strain {100 * result.engineering_strain[level]:.1f} %")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    _caption(fig, "strain of the top surface, nodal average of adjacent segments; coupon centre")
    _save(fig, path, dpi)
    return fig


def plot_transitions(rows: Sequence[dict[str, Any]], path: str | Path | None = None, dpi: int = 150) -> Figure:
    """Transition strain against crimp ratio: Eq 3.4, its long-coupon limit, FE and Table 3.3.

    ``rows`` are dictionaries with ``crimp_ratio``, ``analytical``, ``limit``, ``fe_engineering``,
    ``fe_surface`` and optionally ``table_analytical``, ``table_numerical`` (fractions).
    """
    from pneumorph.composite.crimp import Crimp

    fig = new_figure(6.4, 4.4)
    ax = fig.subplots()
    cr = np.array([r["crimp_ratio"] for r in rows])
    first = rows[0]
    grid = np.linspace(0.1, max(0.4, cr.max() + 0.05), 200)
    amp, length = first.get("amplitude", 1.5), first.get("length", 176.25)
    ax.plot(grid, [100 * Crimp.from_ratio(c, amp, length).transition_strain for c in grid], "-", color="C0",
            lw=1.0, label=f"Eqs 3.1-3.4 (L0 = {length:g} mm)")
    ax.plot(grid, [100 * Crimp.from_ratio(c, amp, length).limit_transition_strain for c in grid], ":",
            color="C0", lw=1.0, label="2 s / lambda - 1 (crimp over the whole length)")
    ax.plot(cr, [100 * r["fe_engineering"] for r in rows], "s", color="C1", label="FE, engineering strain")
    ax.plot(cr, [100 * r["fe_surface"] for r in rows], "^", color="C2", label="FE, averaged surface strain")
    if all("table_numerical" in r for r in rows):
        ax.plot(cr, [100 * r["table_numerical"] for r in rows], "x", color="k", ms=7,
                label="Table 3.3, numerical (engineering)")
    if all("table_analytical" in r for r in rows):
        ax.plot(cr, [100 * r["table_analytical"] for r in rows], "+", color="C3", ms=9,
                label="Table 3.3, analytical")
    ax.set_xlabel("crimp ratio A / lambda")
    ax.set_ylabel("transition strain (%)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    _caption(fig, f"A = {amp:g} mm")
    _save(fig, path, dpi)
    return fig

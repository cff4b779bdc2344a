"""Figures of the bimodal actuator: tip paths labelled with pressure (Figs 3.12-3.14) and
deformed mid-plane outlines.

Each function returns a matplotlib Figure and saves it when given a path.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from pneumorph.bimodal.model import BimodalResult
from pneumorph.plot.figure import new_figure, save_figure


def _save(fig: Figure, path: str | Path | None, dpi: int) -> None:
    if path is not None:
        save_figure(fig, path, dpi=dpi)


def plot_tip_paths(
    runs: Sequence[tuple[str, BimodalResult]],
    title: str = "",
    path: str | Path | None = None,
    dpi: int = 150,
) -> Figure:
    """Tip path (axial against transverse displacement, pressures in kPa beside the points)
    and transverse tip displacement against pressure, one series per run.

    Examples
    --------
    >>> from pneumorph.bimodal.switch import find_switch
    >>> p = np.array([0.005, 0.01]); tip = np.array([[0.1, 0.2], [0.3, 0.1]])
    >>> r = BimodalResult(0.3, p, tip, np.zeros((3, 2, 2)), 0.01, True, "", find_switch(p, tip[:, 1]))
    >>> len(plot_tip_paths([("a", r)]).axes)
    2

    The switch (dotted) is named in the legend of the pressure plot:

    >>> p = np.array([0.005, 0.01, 0.015]); tip = np.array([[0.1, 0.2], [0.3, 0.3], [0.4, -0.2]])
    >>> r = BimodalResult(0.3, p, tip, np.zeros((3, 2, 2)), 0.01, True, "", find_switch(p, tip[:, 1]))
    >>> [t.get_text() for t in plot_tip_paths([("a", r)]).axes[1].get_legend().get_texts()]
    ['a', 'a: switch at 13.0 kPa']
    """
    fig = new_figure(11, 5.0)
    ax, ax2 = fig.subplots(1, 2)
    for i, (label, r) in enumerate(runs):
        c = f"C{i}"
        v = np.concatenate([[0.0], r.tip[:, 1]])
        u = np.concatenate([[0.0], r.tip[:, 0]])
        p = np.concatenate([[0.0], 1e3 * r.pressures])
        s = r.switch
        extra = []
        if s.turning is not None:
            extra.append(f"turns at {1e3 * s.turning:.3g} kPa")
        extra.append(f"switch {1e3 * s.switch:.1f} kPa" if s.switch is not None else "no switch")
        if not r.completed:
            extra.append(f"ramp ends at {p[-1]:g} kPa")
        full = f"{label}: " + ", ".join(extra)
        ax.plot(v, u, "o-", color=c, ms=3.5, lw=1.2, label=full)
        for vi, ui, pi in zip(v[1:], u[1:], p[1:], strict=False):
            ax.annotate(f"{pi:.3g}", (vi, ui), textcoords="offset points", xytext=(4, 2), fontsize=6, color=c)
        ax2.plot(p, v, "o-", color=c, ms=3.5, lw=1.2, label=label)
        if s.switch is not None:
            ax2.axvline(1e3 * s.switch, color=c, ls=":", lw=1, label=f"{label}: switch at {1e3 * s.switch:.1f} kPa")
    for a in (ax, ax2):
        a.axhline(0, color="0.6", lw=0.6)
        a.grid(alpha=0.3)
    ax.axvline(0, color="0.6", lw=0.6)
    ax.set_xlabel("transverse tip displacement u_y (mm; + towards the Smooth-Sil strip)")
    ax.set_ylabel("axial tip displacement u_x (mm)")
    ax.legend(fontsize=7, loc="best")
    ax2.set_xlabel("pressure (kPa)")
    ax2.set_ylabel("transverse tip displacement u_y (mm)")
    ax2.legend(fontsize=7, loc="best")
    ax.set_title(title, fontsize=10)
    _save(fig, path, dpi)
    return fig


def plot_outlines(
    result: BimodalResult,
    pressures_kpa: Sequence[float] | None = None,
    title: str = "",
    path: str | Path | None = None,
    dpi: int = 150,
) -> Figure:
    """Mid-plane outline of the actuator, unloaded and at some converged pressures.

    Examples
    --------
    >>> from pneumorph.bimodal.switch import find_switch
    >>> p = np.array([0.005]); o = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 0.1], [1, 1.1]]], float)
    >>> r = BimodalResult(0.3, p, np.zeros((1, 2)), o, 0.005, True, "", find_switch(p, [0.0]))
    >>> len(plot_outlines(r).axes)
    1
    """
    fig = new_figure(9, 4.5)
    ax = fig.subplots()
    p = 1e3 * result.pressures
    if pressures_kpa is None:
        picks = sorted({len(p) // 2, len(p) - 1} - {-1}) if len(p) else []
        if result.switch.turning is not None:
            picks = sorted(set(picks) | {int(np.argmin(abs(p - 1e3 * result.switch.turning)))})
    else:
        picks = [int(np.argmin(abs(p - q))) for q in pressures_kpa]
    ref = result.outline[0]
    ax.fill(ref[:, 0], ref[:, 1], color="0.85", ec="0.5", lw=0.8, label="unloaded")
    for i, k in enumerate(picks):
        o = result.outline[k + 1]
        ax.plot(np.append(o[:, 0], o[0, 0]), np.append(o[:, 1], o[0, 1]), color=f"C{i}", lw=1.2,
                label=f"{p[k]:g} kPa")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    _save(fig, path, dpi)
    return fig

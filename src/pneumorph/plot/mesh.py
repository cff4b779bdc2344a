"""The figure of a mesh-convergence study: each quantity against the representative cell size."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from matplotlib.figure import Figure

from pneumorph import __version__
from pneumorph.plot.figure import new_figure, save_figure

_PANELS = (("curl", "curl at the last level (deg)"), ("tip_y", "tip height at the last level (mm)"),
           ("value", "objective at its best level"))


def plot_mesh_study(study: Any, path: str | Path | None = None, unit: str = "mm",
                    fingerprint: str = "") -> Figure:
    """Curl, tip height and objective of every design against the cell size, with their Richardson limits.

    Each design's values are joined coarse to fine; its extrapolated limit is drawn at
    ``h = 0`` with the estimated error as a bar (Roache's grid convergence index).

    Parameters
    ----------
    study : pneumorph.sensitivity.MeshStudy
    path : str or Path, optional
        Write the figure there (PNG, SVG or PDF by the extension).
    unit : str
        The objective's unit, for its axis label.
    """
    fig = new_figure(12.0, 4.2)
    labels = {"value": f"objective at its best level ({unit})"}
    for k, (quantity, label) in enumerate(_PANELS):
        ax = fig.add_subplot(1, len(_PANELS), k + 1)
        for j, design in enumerate(study.designs):
            conv = study.convergence(design, quantity)
            if conv is None:
                continue
            color = f"C{j % 10}"
            ax.plot(conv.sizes, conv.values, "o-", color=color, ms=4, label=design)
            if conv.extrapolated is not None:
                ax.errorbar([0.0], [conv.extrapolated], yerr=[[conv.error], [conv.error]], fmt="s", color=color,
                            ms=4, capsize=3)
                ax.plot([0.0, conv.sizes[-1]], [conv.extrapolated, conv.values[-1]], ":", color=color, lw=1)
        ax.set_xlabel("representative cell size h = (V/N)^(1/3) (mm)")
        ax.set_ylabel(labels.get(quantity, label))
        ax.set_xlim(left=-0.08)
        ax.grid(True, color="0.9")
        if k == 0:
            ax.legend(fontsize=7, title="design (base first)", title_fontsize=7)
    order = "" if study.order is None else f"; two-mesh limits with the assumed order {study.order:g}"
    fig.suptitle(f"Mesh convergence; objective: {study.objective}\n(squares at h = 0: Richardson limit +- grid "
                 f"convergence index{order})", fontsize=9)
    fig.text(0.01, 0.005, f"pneumorph {__version__}" + (f" | {fingerprint}" if fingerprint else ""), fontsize=6,
             color="0.4")
    if path is not None:
        save_figure(fig, path, "mesh convergence study")
    return fig

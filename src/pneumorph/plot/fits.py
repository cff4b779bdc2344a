"""Test data against fitted hyperelastic models, one panel per mode (cf. Figs A.9-A.11).

Examples
--------
>>> from pneumorph.materials.characterisation.datasets import load_dataset
>>> from pneumorph.materials.fitting.fit import fit
>>> data = load_dataset("treloar1944")
>>> fig = plot_fits(data, [fit("yeoh", data)])
>>> len(fig.axes)
3
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import cast

import numpy as np
from matplotlib.figure import Figure
from matplotlib.layout_engine import ConstrainedLayoutEngine

from pneumorph import __version__
from pneumorph.materials.characterisation.testdata import TestData
from pneumorph.materials.fitting.fit import FitResult
from pneumorph.plot.figure import new_figure, save_figure

_TITLES = {"uniaxial": "Uniaxial", "equibiaxial": "Equibiaxial", "planar": "Planar (pure shear)"}


def provenance(data: TestData, results: Sequence[FitResult]) -> dict[str, str]:
    """Metadata written into the figure file (keys valid for both PNG and SVG)."""
    sources = ", ".join(Path(s).name for s in data.sources) or data.name
    models = ", ".join(r.model_name for r in results)
    return {
        "Title": f"Hyperelastic fits to {data.name}",
        "Creator": f"pneumorph {__version__}",
        "Source": sources,
        "Description": f"models: {models}; nominal stress against stretch; "
        f"weighting: {', '.join(sorted({r.weighting for r in results})) or '-'}",
    }


def plot_fits(
    data: TestData,
    results: Sequence[FitResult],
    path: str | Path | None = None,
    *,
    title: str | None = None,
    dpi: int = 150,
) -> Figure:
    """Plot measured nominal stress and every fitted model, one panel per mode.

    Parameters
    ----------
    data : TestData
        The measurements (markers).
    results : sequence of FitResult
        Fitted models (lines over the stretch range of each mode's data), labelled with
        their name and R^2 for that mode.
    path : str or Path, optional
        Save to this file; the format follows the extension (``.png``, ``.svg``, ``.pdf``).
        Provenance (pneumorph version, data file, models) goes into the file metadata and
        a caption.
    title : str, optional
        Figure title; default the data name.
    dpi : int
        Resolution of raster output.

    Returns
    -------
    matplotlib.figure.Figure
    """
    modes = data.modes
    width = 4.2 * len(modes) + 0.6
    meta = provenance(data, results)
    caption = textwrap.fill(f"{meta['Creator']} | data: {meta['Source']} | {meta['Description']}",
                            width=int(width * 24))
    nlines = caption.count("\n") + 1
    fig = new_figure(width, 4.4)
    cast(ConstrainedLayoutEngine, fig.get_layout_engine()).set(rect=(0.0, 0.03 * nlines, 1.0, 1.0 - 0.03 * nlines))
    axes = fig.subplots(1, len(modes), squeeze=False)[0]
    for ax, mode in zip(axes, modes, strict=False):
        c = data.curve(mode)
        every = max(1, len(c) // 60)
        ax.plot(c.stretch, c.stress, "o", ms=4, mfc="none", color="k", markevery=every,
                label=f"data ({len(c)} points)")
        lo, hi = min(1.0, float(c.stretch[0])), float(c.stretch[-1])
        lam = np.linspace(lo, hi, 300)
        for r in results:
            label = r.model_name + (f"  R$^2$={r.r2[mode]:.6f}" if mode in r.r2 else " (not fitted)")
            ax.plot(lam, r.predict(mode, lam), "-" if mode in r.r2 else ":", lw=1.4, label=label)
        ax.axhline(0.0, color="0.7", lw=0.6)
        ax.set_title(_TITLES[mode])
        ax.set_xlabel("stretch $\\lambda$ [-]")
        ax.set_ylabel("nominal stress [MPa]")
        ax.legend(fontsize=7, loc="upper left")
        ax.grid(alpha=0.3)
    fig.suptitle(title or data.name)
    fig.text(0.005, 0.005, caption, fontsize=5.5, color="0.4", ha="left", va="bottom")
    if path is not None:
        save_figure(fig, path, meta["Description"], dpi=dpi, fields={"Title": meta["Title"], "Source": meta["Source"]})
    return fig

"""Figures of a sensitivity study: centrelines against the reference (Figs D.1-D.4, E.2, E.3, E.5)
and, for mould tolerances, the curl of every case (Fig E.6)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from pneumorph import __version__
from pneumorph.plot.figure import new_figure, save_figure


def plot_study(result: Any, path: str | Path | None = None) -> Figure:
    """The reference's centreline and every variant's, at the compared level; tolerances add their curls.

    Parameters
    ----------
    result : pneumorph.sensitivity.StudyResult
    path : str or Path, optional
        Write the figure there (PNG, SVG or PDF by the extension).
    """
    study = result.study
    tolerances = study.name == "tolerances"
    fig = new_figure(11.0 if tolerances else 6.5, 5.0)
    ax = fig.add_subplot(1, 2 if tolerances else 1, 1)
    ref = result.reference.outcome.response
    level = study.level
    ok = [c for c in result.cases if c.outcome.ok]
    if ref is not None and result.reference.outcome.ok:
        line = ref.centreline(level)
        ax.plot(line[:, 0], line[:, 1], "k.-", lw=2.0, ms=4, label=f"{study.reference.label} (reference)", zorder=3)
        undeformed = np.vstack([[0.0, ref.reference_centres[0, 1]], ref.reference_centres, ref.reference_tip])
        ax.plot(undeformed[:, 0], undeformed[:, 1], "-", color="0.75", lw=1.0, label="undeformed")
    if tolerances:
        curls = np.array([c.difference.curl_deg for c in ok if c.difference is not None])
        lo, hi = (int(np.argmin(curls)), int(np.argmax(curls))) if len(curls) else (-1, -1)
        for i, c in enumerate(ok):
            line = c.outcome.response.centreline(level)
            style: dict[str, Any] = {"color": "tab:blue" if i == lo else "tab:red" if i == hi else "0.55",
                                     "lw": 1.4 if i in (lo, hi) else 0.5}
            label = "minimum curl" if i == lo else "maximum curl" if i == hi else None
            ax.plot(line[:, 0], line[:, 1], "-", label=label, **style)
    else:
        for c in ok:
            line = c.outcome.response.centreline(level)
            d = c.difference.distance_mm if c.difference is not None else float("nan")
            ax.plot(line[:, 0], line[:, 1], ".-", ms=3, lw=1.2, label=f"{c.case.label} (max distance {d:.2f} mm)")
            if c.matching_kpa is not None:
                r = c.outcome.response
                j = int(np.argmin(np.abs(r.pressures * 1e3 - c.matching_kpa)))
                line = r.centreline(j)
                ax.plot(line[:, 0], line[:, 1], "--", lw=1.2,
                        label=f"{c.case.label} at {r.pressures[j] * 1e3:.4g} kPa (closest {c.matching_kpa:.1f} kPa)")
    for c in result.cases:  # a ramp that failed: its closest converged shape, and the reference at that pressure
        r = c.outcome.response
        if c.outcome.ok or r is None or c.matching_kpa is None or ref is None:
            continue
        j = int(np.argmin(np.abs(r.pressures * 1e3 - c.matching_kpa)))
        line = r.centreline(j)
        p = r.pressures[j] * 1e3
        ax.plot(line[:, 0], line[:, 1], "--", color="tab:red", lw=1.4,
                label=f"{c.case.label} at {p:.4g} kPa (failed at {(c.outcome.reached or 0) * 1e3:.4g} kPa)")
        same = np.flatnonzero(np.isclose(ref.pressures * 1e3, p))
        if same.size:
            line = ref.centreline(int(same[0]))
            ax.plot(line[:, 0], line[:, 1], ":", color="k", lw=1.2, label=f"{study.reference.label} at {p:.4g} kPa")
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=7)
    p = ref.pressures[level] * 1e3 if ref is not None else float("nan")
    ax.set_title(f"{study.name}: design {study.design} at {p:.4g} kPa", fontsize=9)
    if tolerances and ok:
        bx = fig.add_subplot(1, 2, 2)
        labels = [c.case.label for c in ok]
        bars = [c.difference.curl_deg if c.difference is not None else np.nan for c in ok]
        colours = ["tab:orange" if not lab.startswith("sample") else "tab:gray" for lab in labels]
        bx.barh(range(len(ok)), bars, color=colours)
        if result.reference.outcome.ok:
            bx.axvline(float(ref.curl[level]), color="k", lw=1.2, label="nominal")
        bx.set_yticks(range(len(ok)), labels, fontsize=5)
        finite = np.array(bars, dtype=float)
        finite = finite[np.isfinite(finite)]
        if finite.size:
            pad = max(1.0, 0.1 * float(np.ptp(finite)))
            bx.set_xlim(float(finite.min()) - pad, float(finite.max()) + pad)
        bx.set_xlabel("curl [deg]; orange: extremes and corners, grey: random samples")
        bx.legend(loc="lower right", fontsize=7)
    fig.text(0.01, 0.005, f"pneumorph {__version__} | {study.reference.model.fingerprint()}", fontsize=6, color="0.4")
    if path is not None:
        save_figure(fig, path, f"{study.name} study of design {study.design}")
    return fig


__all__ = ["plot_study"]

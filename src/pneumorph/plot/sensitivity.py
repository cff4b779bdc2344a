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
    ok = [c for c in result.cases if c.outcome.ok]
    # a tolerance study lists every case by name beside its bar: the figure grows with them, readable at 8 pt
    fig = new_figure(11.0 if tolerances else 6.5, max(5.0, 1.6 + 0.16 * len(ok)) if tolerances else 5.0)
    ax = fig.add_subplot(1, 2 if tolerances else 1, 1)
    ref = result.reference.outcome.response
    level = study.level
    if ref is not None and result.reference.outcome.ok:
        _reference(ax, ref, level, study.reference.label)
    if tolerances:
        _tolerance_cases(ax, ok, level)
    else:
        _variant_cases(ax, ok, level)
    if ref is not None:
        _failed_cases(ax, result.cases, ref, study.reference.label)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=7)
    p = ref.pressures[level] * 1e3 if ref is not None else float("nan")
    ax.set_title(f"{study.name}: design {study.design} at {p:.4g} kPa", fontsize=9)
    if tolerances and ok:
        nominal = result.reference.outcome.ok and ref is not None
        _curl_panel(fig.add_subplot(1, 2, 2), ok, float(ref.curl[level]) if nominal else None)
    fig.text(0.01, 0.005, f"pneumorph {__version__} | {study.reference.model.fingerprint()}", fontsize=6, color="0.4")
    if path is not None:
        save_figure(fig, path, f"{study.name} study of design {study.design}")
    return fig


def _reference(ax: Any, ref: Any, level: int, label: str) -> None:
    """The reference's centreline at ``level`` and the undeformed one."""
    line = ref.centreline(level)
    ax.plot(line[:, 0], line[:, 1], "k.-", lw=2.0, ms=4, label=f"{label} (reference)", zorder=3)
    undeformed = np.vstack([[0.0, ref.reference_centres[0, 1]], ref.reference_centres, ref.reference_tip])
    ax.plot(undeformed[:, 0], undeformed[:, 1], "-", color="0.75", lw=1.0, label="undeformed")


def _tolerance_cases(ax: Any, ok: list[Any], level: int) -> None:
    """Every solved case of a tolerance study: the least and the most curled in colour, the others grey."""
    curls = np.array([c.difference.curl_deg for c in ok if c.difference is not None])
    lo, hi = (int(np.argmin(curls)), int(np.argmax(curls))) if len(curls) else (-1, -1)
    others = False
    for i, c in enumerate(ok):
        line = c.outcome.response.centreline(level)
        style: dict[str, Any] = {"color": "tab:blue" if i == lo else "tab:red" if i == hi else "0.55",
                                 "lw": 1.4 if i in (lo, hi) else 0.5}
        label = "minimum curl" if i == lo else "maximum curl" if i == hi else None
        if label is None and not others:  # the grey lines, named once
            label, others = "the other cases (extremes, corners, random samples)", True
        ax.plot(line[:, 0], line[:, 1], "-", label=label, **style)


def _variant_cases(ax: Any, ok: list[Any], level: int) -> None:
    """Every solved variant with its distance from the reference, and its shape at the matching pressure if any."""
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


def _failed_cases(ax: Any, cases: Any, ref: Any, label: str) -> None:
    """A ramp that failed: its closest converged shape, and the reference (``label``) at that pressure."""
    for c in cases:
        r = c.outcome.response
        if c.outcome.ok or r is None or c.matching_kpa is None:
            continue
        j = int(np.argmin(np.abs(r.pressures * 1e3 - c.matching_kpa)))
        line = r.centreline(j)
        p = r.pressures[j] * 1e3
        ax.plot(line[:, 0], line[:, 1], "--", color="tab:red", lw=1.4,
                label=f"{c.case.label} at {p:.4g} kPa (failed at {(c.outcome.reached or 0) * 1e3:.4g} kPa)")
        same = np.flatnonzero(np.isclose(ref.pressures * 1e3, p))
        if same.size:
            line = ref.centreline(int(same[0]))
            ax.plot(line[:, 0], line[:, 1], ":", color="k", lw=1.2, label=f"{label} at {p:.4g} kPa")


def _curl_panel(bx: Any, ok: list[Any], nominal: float | None) -> None:
    """Each tolerance case's curl as a bar: its change from the ``nominal`` design's curl, else the curl itself.

    Each bar starts at the nominal design's curl (zero): its change, not a bar cut off at
    145 degrees; the axis is symmetric about it, so a larger and a smaller curl read alike.
    """
    from matplotlib.patches import Patch

    labels = [c.case.label for c in ok]
    curls = np.array([c.difference.curl_deg if c.difference is not None else np.nan for c in ok], dtype=float)
    bars = curls - nominal if nominal is not None else curls
    colours = ["tab:orange" if not lab.startswith("sample") else "tab:gray" for lab in labels]
    bx.barh(range(len(ok)), bars, color=colours)
    bx.axvline(0.0, color="k", lw=1.2)
    bx.set_yticks(range(len(ok)), labels, fontsize=8)
    bx.invert_yaxis()  # the first case on top, as listed
    finite = bars[np.isfinite(bars)]
    left, right = (min(0.0, float(finite.min())), max(0.0, float(finite.max()))) if finite.size else (0.0, 0.0)
    pad = 0.1 * (right - left) or 1.0
    if nominal is not None:
        reach = max(right, -left) * 1.15 or 1.0
        bx.set_xlim(-reach, reach)
        bx.set_xlabel(f"curl change from the nominal design's {nominal:.4g} deg [deg]")
    else:  # no nominal shape to compare with: the curl itself, from zero
        bx.set_xlim(left - pad if left < 0 else 0.0, right + pad)
        bx.set_xlabel("curl [deg] (the nominal design failed)")
    handles = [Patch(color="tab:orange", label="extremes and corners of the tolerance box"),
               Patch(color="tab:gray", label="random samples"),
               *([bx.lines[0]] if nominal is not None else [])]
    if nominal is not None:
        bx.lines[0].set_label("nominal design")
    bx.legend(handles=handles, loc="best", fontsize=7)

__all__ = ["plot_study"]

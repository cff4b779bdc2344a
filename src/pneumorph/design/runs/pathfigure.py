"""The figure of a path target: the path, the unit centres as the model reports them, each joined to the point of its
stretch it is matched with (:mod:`pneumorph.design.objectives.paths`); a view from above for a path in space."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.design.objectives.paths import PathTarget
from pneumorph.design.search.scoring import Candidate
from pneumorph.models.response import Response
from pneumorph.plot.figure import new_figure, save_figure


def placed_path(objective: PathTarget, response: Response) -> PathTarget:
    """The path in mm for the response's actuator (a preset drawn for its length and axis)."""
    return objective.at(float(response.reference_tip[0]), float(response.reference_tip[1]))


def centrelines(response: Response) -> np.ndarray:
    """The base (on the actuator's axis), the unit centres and the tip at every level as the model reports them,
    (k, n + 2, 2) or, for a response in space, (k, n + 2, 3) with z from the mid-plane."""
    c = response.centres.copy()
    tip = response.tip.copy()
    if c.shape[-1] == 3:
        c[..., 2] -= response.reference_centres[None, :, 2]
        tip[:, 2] -= response.reference_tip[2]
    base = np.zeros((len(c), 1, c.shape[-1]))
    base[..., 1] = response.reference_tip[1]
    return np.concatenate([base, c, tip[:, None]], axis=1)


def centreline(response: Response, level: int) -> np.ndarray:
    """:func:`centrelines` at ``level`` as (x, y, z) points (z = 0 for a planar response), (n + 2, 3)."""
    line = centrelines(response)[level]
    out = np.zeros((len(line), 3))
    out[:, :line.shape[1]] = line
    return out


def draw_path(ax: Any, route: PathTarget, response: Response, level: int, axes: tuple[int, int] = (0, 1),
              label: str = "actuator centreline") -> np.ndarray:
    """Draw ``route`` and the response's centreline at ``level`` in the plane of ``axes`` (0 = x, 1 = y, 2 = z), each
    centre joined to its matched point; returns the points drawn (for the limits)."""
    p = route.polyline()
    line = centreline(response, level)
    matched = route.nearest(line[1:-1])
    a, b = axes
    ax.plot(p[:, a], p[:, b], "-", color="C1", lw=2, label=f"path {route.name}")
    for c, m in zip(line[1:-1], matched, strict=True):
        ax.plot([c[a], m[a]], [c[b], m[b]], "-", color="0.5", lw=0.7)
    ax.plot(line[:, a], line[:, b], "-", color="C0", lw=1.5, label=label)
    ax.plot(line[1:-1, a], line[1:-1, b], "o", color="C0", ms=4, label="unit centres")
    ax.plot(line[-1, a], line[-1, b], "s", color="C3", ms=6, label="tip")
    return np.vstack([p, line])


def plot_path(candidate: Candidate, objective: PathTarget, path: str | Path,
              compare: Sequence[tuple[str, Candidate]] = ()) -> Path:
    """The best design's centres at its best pressure along the path (side view; from above too in space).

    ``compare``: further responses of the same design drawn dotted at the candidate's level (the
    chain model's prediction beside its FE verification).

    Returns
    -------
    Path
    """
    r, k = candidate.response, candidate.level
    assert r is not None and k is not None, "a candidate without a response has no shape"
    route = placed_path(objective, r)
    others = [(name, centreline(o.response, k)) for name, o in compare if o.response is not None]
    spatial = route.spatial or r.centres.shape[-1] == 3
    views = [(0, 1), (0, 2)] if spatial else [(0, 1)]
    fig = new_figure(7.0, 5.2 * len(views) + 0.6, layout="constrained")
    axs = fig.subplots(len(views), 1, squeeze=False)[:, 0]
    n = r.n_units
    pressure = candidate.pressure * 1e3 if candidate.pressure is not None else float("nan")
    for ax, (a, b) in zip(axs, views, strict=True):
        drawn = draw_path(ax, route, r, k, (a, b))
        for i, (name, q) in enumerate(others):
            ax.plot(q[:, a], q[:, b], ":", marker="x", ms=6, color=f"C{i + 4}", lw=1.2, zorder=5, label=name)
            drawn = np.vstack([drawn, q])
        finite = drawn[np.all(np.isfinite(drawn), axis=1)]
        lo, hi = finite.min(axis=0), finite.max(axis=0)
        pad = 0.06 * float(max(np.max(hi[[a, b]] - lo[[a, b]]), 1.0))
        ax.set_xlim(lo[a] - pad, hi[a] + pad)
        ax.set_ylim(lo[b] - pad, hi[b] + pad)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)" if b == 1 else "z (mm)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    axs[0].set_title(f"{candidate.design} at {pressure:.4g} kPa - path error {candidate.value:.3g} mm, "
                     f"{candidate.value / np.sqrt(n):.3g} mm RMS per centre", fontsize=9)
    if spatial:
        axs[1].set_title("seen from above (x, z)", fontsize=9)
    return save_figure(fig, path)


__all__ = ["centreline", "centrelines", "draw_path", "placed_path", "plot_path"]

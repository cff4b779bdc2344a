"""Figures of a design run: the best profile against the target (Figs 6.6-6.11), convergence."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np

from pneumorph.design.search.genetic import GenerationStats
from pneumorph.design.runs.pathfigure import draw_path, placed_path, plot_path
from pneumorph.design.objectives.paths import PathTarget
from pneumorph.design.search.scoring import Candidate
from pneumorph.design.objectives.targets import Objective, ProfileTarget, StagedTarget
from pneumorph.plot.figure import new_figure, save_figure


def profile_points(candidate: Candidate, level: int | None = None) -> np.ndarray:
    """Base, unit centres and tip at the best level (or ``level``), heights above their undeformed positions."""
    return _centreline(candidate, level)[:, :2]


def plot_profile(candidate: Candidate, objective: Objective, path: str | Path, unit: str = "mm",
                 compare: Sequence[tuple[str, Candidate]] = ()) -> Path:
    """The best design's profile at its best pressure beside the target (or the tip goal).

    Parameters
    ----------
    candidate : Candidate
        A converged design with its response and best level.
    objective : ProfileTarget or TipGoal
    path : str or Path
        Output file (PNG or SVG by its suffix).
    compare : sequence of (label, Candidate)
        Further responses of the same design drawn dashed at the candidate's level (e.g.
        the chain model's prediction beside its FE verification).

    Returns
    -------
    Path
    """
    r = candidate.response
    assert r is not None, "a candidate without a response has no profile"
    if isinstance(objective, StagedTarget):
        return plot_stages(candidate, objective, path)
    if isinstance(objective, PathTarget):
        return plot_path(candidate, objective, path, compare)
    pts = profile_points(candidate)
    length = float(r.reference_tip[0])
    curves, what = _target_curves(candidate, objective, pts, length, unit)
    others, lines = [], []
    for name, other in compare:
        o = Candidate(other.design, other.value, candidate.level, candidate.pressure, None, other.response)
        others.append((name, profile_points(o)))
        lines.append((name, _centreline(o)))
    # true proportions (equal axes) on a figure as tall as the shape needs: a flat profile gets a flat figure
    # with its legend below, not a square of empty space
    point = None if isinstance(objective, ProfileTarget) else objective.point
    marks = [np.array([point[:2]], dtype=float)] if point is not None else []
    everything = np.vstack([pts, *[np.column_stack([x, y]) for x, y, _ in curves], *[q for _, q in others], *marks])
    finite = everything[np.all(np.isfinite(everything), axis=1)]
    lo, hi = finite.min(axis=0), finite.max(axis=0)
    span = np.maximum(hi - lo, 1.0)
    pad = 0.06 * max(span)
    width = 7.0
    axes_height = float(np.clip((width - 1.0) * (span[1] + 2 * pad) / (span[0] + 2 * pad), 1.1, 6.0))
    spatial = _in_space(candidate, objective)
    fig = new_figure(width, axes_height + 2.2 + (7.0 if spatial else 0.0), layout="constrained")
    ax = fig.add_subplot(3, 1, 1) if spatial else fig.add_subplot()
    ax.axhline(0.0, color="0.8", lw=0.8, ls="--", label="undeformed axis")
    for xs, ys, style in curves:
        ax.plot(xs, ys, **style)
    if point is not None:
        ax.plot(*point[:2], "x", color="C1", ms=10, mew=2, label="point to reach")
    fidelity = (r.metadata or {}).get("fidelity")
    ax.plot(pts[:, 0], pts[:, 1], "-", color="C0", lw=1.5,
            label="actuator centreline" + (f" ({fidelity} FE)" if compare and fidelity else ""))
    ax.plot(pts[1:-1, 0], pts[1:-1, 1], "o", color="C0", ms=4, label="unit centres")
    ax.plot(*pts[-1], "s", color="C3", ms=6, label="tip")
    for i, (name, q) in enumerate(others):
        ax.plot(q[:, 0], q[:, 1], ":", marker="x", ms=6, color=f"C{i + 4}", lw=1.2, zorder=5, label=name)
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x along the actuator (mm)")
    ax.set_ylabel("y (mm)")
    pressure = candidate.pressure * 1e3 if candidate.pressure is not None else float("nan")
    ax.set_title(f"{candidate.design} at {pressure:.4g} kPa - {what}", fontsize=9)
    # below the x label: a flat panel (the side view of a design that leaves the plane) needs a longer way down
    below = -0.22 if not spatial or axes_height > 2.5 else -0.3 - 0.3 / axes_height
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, below), ncol=3, frameon=False)
    ax.grid(alpha=0.3)
    if spatial:
        _top_view(fig.add_subplot(3, 1, 2, sharex=ax), candidate, objective, length, lines)
        _space_view(fig.add_subplot(3, 1, 3, projection="3d"), candidate, objective, length)
    return save_figure(fig, path)


def _target_curves(candidate: Candidate, objective: Objective, pts: np.ndarray, length: float,
                   unit: str) -> tuple[list[tuple[np.ndarray, np.ndarray, dict[str, Any]]], str]:
    """The target drawn in the side view (x, y) and the title's value."""
    if not isinstance(objective, ProfileTarget):
        return [], f"{objective.label}: {candidate.value:.4g} {objective.unit}"
    if objective.coordinates == "cartesian":
        xs = np.linspace(0.0, max(length, float(np.nanmax(pts[:, 0]))), 300)
        ys = objective.curve(xs, length)
    else:
        th = np.unwrap(np.arctan2(pts[1:-1, 1], pts[1:-1, 0]))
        ts = np.linspace(min(th.min(), 0.0), max(th.max(), 0.0), 300)
        rs = objective.curve(ts, length)
        xs, ys = rs * np.cos(ts), rs * np.sin(ts)
    return [(xs, np.broadcast_to(ys, xs.shape), {"color": "C1", "lw": 2, "label": f"target {objective.display}"})], \
        f"Eq 4.1 error {candidate.value:.3g} {unit}"


def _space_point(objective: Objective) -> tuple[float, ...] | None:
    """A tip goal's point off the plane ``(x, y, z)``, else None."""
    point = None if isinstance(objective, (ProfileTarget, StagedTarget)) else objective.point
    return point if point is not None and len(point) == 3 else None


def _in_space(candidate: Candidate, objective: Objective) -> bool:
    """Whether the run leaves the plane: a space-curve target, a tip point off it, or centres with a z."""
    r = candidate.response
    return bool((isinstance(objective, ProfileTarget) and objective.spatial) or _space_point(objective) is not None
                or (r is not None and r.centres.shape[-1] == 3))


def _centreline(candidate: Candidate, level: int | None = None) -> np.ndarray:
    """Base, unit centres and tip at the best level (or ``level``) as (x, y, z) from their undeformed heights and
    mid-width (z = 0 for a planar response)."""
    r, k = candidate.response, candidate.level if level is None else level
    assert r is not None and k is not None

    def off(points: np.ndarray, ref: np.ndarray) -> np.ndarray:
        out = np.zeros((len(points), 3))
        out[:, 0] = points[:, 0]
        out[:, 1:points.shape[1]] = points[:, 1:] - ref[..., 1:points.shape[1]]
        return out

    return np.vstack([np.zeros((1, 3)), off(r.centres[k], r.reference_centres), off(r.tip[k][None], r.reference_tip)])


def _space_view(ax: Any, candidate: Candidate, objective: Objective, length: float) -> None:
    """The centreline and the target in space, drawn as (x, z, y) so that the height points up."""
    line = _centreline(candidate)
    if isinstance(objective, ProfileTarget) and objective.coordinates == "cartesian":
        grid = np.linspace(0.0, max(length, float(np.nanmax(line[:, 0]))), 300)
        ax.plot(grid, np.broadcast_to(objective.curve_z(grid, length), grid.shape),
                np.broadcast_to(objective.curve(grid, length), grid.shape), color="C1", lw=2, label="target")
    elif (point := _space_point(objective)) is not None:
        ax.plot([point[0]], [point[2]], [point[1]], "x", color="C1", ms=10, mew=2, label="point to reach")
    ax.plot(line[:, 0], line[:, 2], line[:, 1], "-o", color="C0", ms=3, lw=1.5, label="actuator centreline")
    ax.plot([line[-1, 0]], [line[-1, 2]], [line[-1, 1]], "s", color="C3", ms=6)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_zlabel("y (mm)")
    ax.set_title("in space", fontsize=9)
    ax.legend(fontsize=7, frameon=False)


def _top_view(ax: Any, candidate: Candidate, objective: Objective, length: float,
              others: Sequence[tuple[str, np.ndarray]] = ()) -> None:
    """The view from above (x, z): the target's z and the centreline's (z = 0 for a planar design), and the
    centrelines ``others`` (name, points) it is compared with, as in the side view."""
    line = _centreline(candidate)
    xs, zs = line[:, 0], line[:, 2]
    ax.axhline(0.0, color="0.8", lw=0.8, ls="--")
    if isinstance(objective, ProfileTarget):
        grid = np.linspace(0.0, max(length, float(np.nanmax(xs))), 300)
        ax.plot(grid, np.broadcast_to(objective.curve_z(grid, length), grid.shape), color="C1", lw=2,
                label="target z")
    elif (point := _space_point(objective)) is not None:
        ax.plot(point[0], point[2], "x", color="C1", ms=10, mew=2)
    ax.plot(xs, zs, "-", color="C0", lw=1.5, label="actuator centreline")
    ax.plot(xs[1:-1], zs[1:-1], "o", color="C0", ms=4)
    ax.plot(xs[-1], zs[-1], "s", color="C3", ms=6)
    for i, (name, q) in enumerate(others):
        ax.plot(q[:, 0], q[:, 2], ":", marker="x", ms=6, color=f"C{i + 4}", lw=1.2, zorder=5, label=name)
    ax.set_xlabel("x along the actuator (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_title("seen from above (x, z)", fontsize=9)
    ax.legend(fontsize=7, frameon=False)
    ax.grid(alpha=0.3)


def plot_stages(candidate: Candidate, objective: StagedTarget, path: str | Path) -> Path:
    """A staged design: each stage's shape at its pressure beside its target, and the whole ramp.

    One panel per stage (the centreline at the stage's level, the target profile or the point to
    reach, the stage's value in mm), and a last panel with the centreline at every level of the
    ramp, the stages' levels drawn bold.

    Returns
    -------
    Path
    """
    r = candidate.response
    assert r is not None, "a candidate without a response has no profile"
    from pneumorph.design.objectives.fitness import stage_values

    levels = objective.levels(r.pressures)
    values = stage_values(r, objective)
    length = float(r.reference_tip[0])
    ramp = [profile_points(candidate, k) for k in range(r.n_levels)]
    finite = np.vstack([q[np.all(np.isfinite(q), axis=1)] for q in ramp] or [np.zeros((1, 2))])
    lo, hi = finite.min(axis=0), finite.max(axis=0)
    panels = len(objective.stages) + 1
    pad = 0.06 * float(max(np.max(hi - lo), 1.0))
    aspect = (hi[1] - lo[1] + 2 * pad) / (hi[0] - lo[0] + 2 * pad)
    fig = new_figure(6.4, panels * float(np.clip(5.4 * aspect + 1.1, 1.8, 4.8)) + 1.2, layout="constrained")
    axes = fig.subplots(panels, 1, squeeze=False)[:, 0]
    for ax, stage, k, v in zip(axes, objective.stages, levels, values, strict=False):
        pts = ramp[k]
        target = stage.target
        if isinstance(target, ProfileTarget):
            xs = np.linspace(0.0, max(length, float(np.nanmax(pts[:, 0]))), 300)
            ax.plot(xs, np.broadcast_to(target.curve(xs, length), xs.shape), color="C1", lw=2,
                    label=f"target {target.display}")
            what = f"Eq 4.1 error {v:.3g} mm"
        elif isinstance(target, PathTarget):  # a path is drawn where the model puts the centres, not as heights
            drawn = draw_path(ax, placed_path(target, r), r, k)[:, :2]
            lo, hi = np.minimum(lo, drawn.min(axis=0)), np.maximum(hi, drawn.max(axis=0))
            what = f"path error {v:.3g} mm (centres as the model reports them)"
            ax.set_title(f"stage at {r.pressures[k] * 1e3:.4g} kPa (weight {stage.weight:g}): {what}", fontsize=9)
            ax.legend(fontsize=7, loc="best")
            continue
        else:
            assert target.point is not None
            ax.plot(*target.point, "x", color="C1", ms=10, mew=2, label="point to reach")
            what = f"tip {v:.3g} mm from the point"
            lo, hi = np.minimum(lo, target.point), np.maximum(hi, target.point)
        ax.plot(pts[:, 0], pts[:, 1], "-o", color="C0", ms=3, lw=1.5, label="actuator centreline")
        ax.plot(*pts[-1], "s", color="C3", ms=6, label="tip")
        ax.set_title(f"stage at {r.pressures[k] * 1e3:.4g} kPa (weight {stage.weight:g}): {what}", fontsize=9)
        ax.legend(fontsize=7, loc="best")
    ax = axes[-1]
    cmap = matplotlib.colormaps["viridis"]
    for k, pts in enumerate(ramp):
        staged = k in levels
        ax.plot(pts[:, 0], pts[:, 1], "-", color=cmap(k / max(r.n_levels - 1, 1)), lw=2.0 if staged else 0.8,
                label=f"{r.pressures[k] * 1e3:.4g} kPa" + (" (a stage)" if staged else ""))
    ax.set_title(f"{candidate.design} over the ramp: weighted root-sum-square of the stages {candidate.value:.3g} mm",
                 fontsize=9)
    fig.legend(*ax.get_legend_handles_labels(), fontsize=6, ncol=5, loc="outside lower center", frameon=False)
    for ax in axes:
        ax.axhline(0.0, color="0.8", lw=0.8, ls="--")
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x along the actuator (mm)")
        ax.set_ylabel("y (mm)")
        ax.grid(alpha=0.3)
    return save_figure(fig, path)


def plot_convergence(history: Sequence[GenerationStats], path: str | Path, unit: str = "mm") -> Path:
    """Best and mean fitness of the population over the generations."""
    gens = [h.generation for h in history]
    fig = new_figure(5.6, 3.6, layout="tight")
    ax = fig.add_subplot()
    ax.plot(gens, [h.best for h in history], "o-", label="best")
    ax.plot(gens, [h.mean for h in history], "s--", label="mean")
    ax.set_xlabel("generation")
    ax.set_ylabel(f"fitness ({unit})")
    ax.legend()
    ax.grid(alpha=0.3)
    return save_figure(fig, path)

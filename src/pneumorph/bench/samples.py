"""What the page draws of an answer: the target's samples, a path, and a design's lines at every level.

Two frames, as the objectives use them:

- a *profile* (:func:`profiles`, :func:`target_samples`): heights above the undeformed axis,
  each unit centre's height less its undeformed one (Eq 4.1's frame);
- a *path* (:func:`centrelines`, :func:`path_samples`): the unit centres as the model reports
  them, y from the actuator's bottom face (the undeformed axis at ``tip_ref[1]``, 6 mm for the
  built-in unit), z from its mid-plane (:mod:`pneumorph.design.objectives.paths`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pneumorph.design.objectives.paths import PathTarget
from pneumorph.design.objectives.targets import ProfileTarget, StagedTarget, TipGoal
from pneumorph.design.runs.pathfigure import centrelines as design_centrelines

TARGET_SAMPLES = 201


def profiles(response: Any) -> list[list[list[float]]]:
    """Base, unit centres and tip at every level, heights above the undeformed axis (mm); a response in space
    (x, y, z) also gives each point's z off the undeformed axis."""
    c = response.centres.copy()
    c[..., 1:] -= response.reference_centres[None, :, 1:]
    tip = response.tip.copy()
    tip[:, 1:] -= response.reference_tip[1:]
    base = np.zeros((len(c), 1, c.shape[-1]))
    pts = np.concatenate([base, c, tip[:, None]], axis=1)
    return np.round(pts, 4).tolist()


def centrelines(response: Any) -> list[list[list[float]]]:
    """Base (on the undeformed axis), unit centres and tip at every level as the model reports them (mm): the frame
    a path is matched in, y from the bottom face; a response in space gives z from the mid-plane too
    (:func:`pneumorph.design.runs.pathfigure.centrelines`).

    The unit centres are those a :class:`~pneumorph.design.objectives.paths.PathTarget` scores
    (:func:`pneumorph.design.objectives.fitness.path_errors`); the base and the tip join them into a line.
    """
    return np.round(design_centrelines(response), 4).tolist()


def path_samples(objective: Any, length: float, axis: float) -> dict[str, Any] | None:
    """A path's polyline placed on the actuator (a preset drawn for ``length`` mm along an axis ``axis`` mm up), in
    mm: its name, x, y, and z for a path in space; None for any other objective."""
    if not isinstance(objective, PathTarget):
        return None
    route = objective.at(length, axis)
    p = route.polyline()
    out: dict[str, Any] = {"name": route.name, "x": np.round(p[:, 0], 4).tolist(), "y": np.round(p[:, 1], 4).tolist()}
    if route.spatial:
        out["z"] = np.round(p[:, 2], 4).tolist()
    return out


def uses_path(objective: Any) -> bool:
    """True for a path, or stages of which one is a path: the page then draws the centres' frame."""
    if isinstance(objective, StagedTarget):
        return any(isinstance(stage.target, PathTarget) for stage in objective.stages)
    return isinstance(objective, PathTarget)


def stage_samples(objective: Any, pressures: Any, length: float, axis: float) -> list[dict[str, Any]] | None:
    """Per stage of a staged target: its pressure (kPa), level, label, target samples, path and tip point; None
    otherwise."""
    if not isinstance(objective, StagedTarget):
        return None
    levels = objective.levels(pressures)
    return [{"pressure_kpa": round(stage.pressure * 1e3, 9), "level": int(k), "label": stage.label,
             "weight": stage.weight, "target": target_samples(stage.target, length),
             "path": path_samples(stage.target, length, axis),
             "point": list(stage.target.point) if isinstance(stage.target, TipGoal) and stage.target.point is not None
             else None}
            for stage, k in zip(objective.stages, levels, strict=True)]


def target_samples(objective: Any, length: float) -> dict[str, list[float]] | None:
    """A profile's samples over the actuator (heights above the axis; z too for a space curve); None otherwise."""
    if not isinstance(objective, ProfileTarget):
        return None
    if objective.coordinates == "cartesian":
        x = np.linspace(0.0, length, TARGET_SAMPLES)
        y = objective.curve(x, length)
        if objective.spatial:  # a space curve: its z too, for the view from above
            z = objective.curve_z(x, length)
            return {"x": np.round(x, 4).tolist(), "y": np.round(y, 4).tolist(), "z": np.round(z, 4).tolist()}
    else:
        th = np.linspace(0.0, np.pi, TARGET_SAMPLES)
        r = objective.curve(th, length)
        x, y = r * np.cos(th), r * np.sin(th)
    return {"x": np.round(x, 4).tolist(), "y": np.round(y, 4).tolist()}


__all__ = ["TARGET_SAMPLES", "centrelines", "path_samples", "profiles", "stage_samples", "target_samples",
           "uses_path"]

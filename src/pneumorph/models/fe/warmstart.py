"""A nearby model's solve started from a solved state: Newton at the top pressure instead of the ramp.

A model whose inputs differ a little from a solved one's (a material scale, a wall a tenth of a
millimetre thicker, meshed on the same grid so that node ``i`` is node ``i`` of both) has its
equilibrium at the top pressure close to the solved one's. Starting the model's own Newton
method (:meth:`~pneumorph.fem.body.PressurisedBody.stepper`, the ramp's substep) from the
solved displacements at the full pressure reaches that equilibrium in a few iterations,
where the ramp takes all its levels. The state it converges to satisfies the ramp's own
convergence test, so it is the ramp's answer to solver tolerance wherever the equilibrium is
unique (a small change of a stable inflation). Only the last level is solved; the others
stay unknown (NaN). If the iterations do not converge (the change was not small), the model
solves its ramp after all.

The identification's Jacobian (:mod:`pneumorph.identify`) moves each parameter by a step and
needs the shape there: this is its solve.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Any

import numpy as np

from pneumorph.models.fe.base import FEModel
from pneumorph.models.fe.solving import Solution, end_face_angle
from pneumorph.models.frames import record_frames


def solve_near(model: FEModel, design: str, start: Solution) -> Solution:
    """``design`` solved by ``model`` at its top pressure, Newton iterations from ``start``'s last state.

    Parameters
    ----------
    model : FEModel
        A model on the same mesh grid as ``start``'s (the same nodes), without gravity.
    design : str
    start : Solution
        A converged solve of the design by a nearby model.

    Returns
    -------
    Solution
        The last level solved (its response's other levels NaN, ``converged`` True, the
        metadata's ``warm_start`` the Newton iterations); or the full ramp's solution when
        the start does not fit (another mesh, gravity) or the iterations fail.

    Examples
    --------
    >>> from pneumorph.models.factory import make_model
    >>> coarse = {"element_size": 3.0}
    >>> nominal = make_model(2, {"pressure_kpa": 20, "unit": coarse})
    >>> near = make_model(2, {"pressure_kpa": 20, "unit": coarse, "body_bulk_scale": 1.02})
    >>> warm = solve_near(near, "01", nominal.solve("01"))
    >>> cold = near.solve("01")
    >>> float(np.abs(warm.displacements[-1] - cold.displacements[-1]).max()) < 1e-5
    True
    >>> warm.response.metadata["warm_start"] < cold.response.metadata["newton_iterations"]
    True
    """
    t0 = time.perf_counter()
    u0 = start.displacements[-1]
    if model.gravity is not None or model.obstacles or not np.all(np.isfinite(u0)):
        return model.solve(design)  # (contact: its forces are recorded level by level, friction follows the path)
    parsed = model.parse(design)
    mesh, body, set_pressure = model.build(parsed if model.mixed else parsed.text)
    if mesh.points.shape != u0.shape:
        return model.solve(design)
    body.field[0].values[:] = u0  # the prescribed values (clamped base, symmetry plane) are zero in both
    set_pressure(float(model.ramp.pressure))
    substep, _ = body.stepper(model.backend, model.tangent_reuse, model.anderson_depth)
    iterations, cause = substep(body.field, model.ramp.steps)
    if cause is not None:
        return model.solve(design)
    return _last_level(model, parsed.text, mesh, body.displacement[:, : model.dim].copy(), start, iterations, t0)


def _last_level(model: FEModel, design: str, mesh: Any, u: Any, start: Solution, iterations: int,
                t0: float) -> Solution:
    """The solution with only its last level known: centres, tip and curl (unwrapped from the start's)."""
    response = model.empty_response(mesh, design)
    displacements = np.full((len(response.pressures), *mesh.points.shape), np.nan)
    displacements[-1] = u
    response.centres[-1] = mesh.unit_centres(u, mesh.axes)
    record_frames(response, -1, mesh, u)
    response.tip[-1] = response.reference_tip + u[mesh.end_points][:, : mesh.axes].mean(axis=0)
    x_end0 = mesh.points[mesh.end_points][:, :2]
    before = float(start.response.curl[-1])
    angle = np.degrees(end_face_angle(x_end0 + u[mesh.end_points][:, :2]) - end_face_angle(x_end0))
    response.curl[-1] = before + (angle - before + 180.0) % 360.0 - 180.0  # the turn nearest the start's
    meta = {**response.metadata, "warm_start": int(iterations), "wall_time_s": time.perf_counter() - t0}
    return Solution(replace(response, converged=True, reached=float(response.pressures[-1]), metadata=meta), mesh,
                    displacements)


__all__ = ["solve_near"]

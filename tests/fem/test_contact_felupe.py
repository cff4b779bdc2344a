"""The fast core's contact against FElupe's own: a 2D finger pressed on a cylinder, solved both ways.

pneumorph's model (its fast assembler and Newton method, :class:`~pneumorph.fem.fast.contact.RigidContact`
without the penalty's blend) and FElupe's ``ContactRigidCylinder`` with the same penalty as its multiplier,
assembled by FElupe and solved by ``felupe.newtonraphson`` (the ``felupe`` backend's substeps), on the same mesh,
ramp and pressure. Both hold the node-to-surface penalty ``k g n``: their converged states agree to the
tolerance of the two Newton methods.
"""

from __future__ import annotations

import felupe as fem
import numpy as np
import pytest

from pneumorph.fem.stepping import FElupeSubstep, ramp
from pneumorph.models.fe import Reduced2D
from pneumorph.models.fe import obstacles as obstacles_module

DESIGN = "0000"
CENTRE, RADIUS = (35.0, 25.0), 5.0  # the finger of docs/grasping.md


def felupe_contact(model: Reduced2D) -> tuple[np.ndarray, np.ndarray]:
    """FElupe's ramp of ``model``'s design against the cylinder: the displacement and the force on it per mm of
    depth at the full pressure."""
    free = model.variant(obstacles=())
    mesh, body, set_pressure = free.build(DESIGN)
    mine = obstacles_module.contact_items(model.obstacles, mesh, model.body.shear_modulus)[0]
    # FElupe's rigid surfaces sit on a mesh point: a clamped base point, with the gap vectors measured from
    # the cylinder's centre instead (the point does not move, so the kinematics are the same)
    anchor = int(np.flatnonzero(mesh.base_points)[0])
    cylinder = fem.ContactRigidCylinder(body.field, mine.points, anchor, RADIUS, multiplier=mine.stiffness,
                                        curvature="trial")
    cylinder.dX = mesh.points[mine.points] - np.asarray(CENTRE)
    items = [*body.items, cylinder]
    ramp(items, body.field, lambda t: set_pressure(t * model.ramp.pressure), body.dof1, body.dof0,
         model.ramp.steps, substep=FElupeSubstep(items, body.dof1, body.dof0))
    u = body.field[0].values.copy()
    x = mesh.points[mine.points] + u[mine.points]
    gap = np.linalg.norm(x - CENTRE, axis=1) - RADIUS
    normal = (x - CENTRE) / (gap + RADIUS)[:, None]
    force = (mine.stiffness * np.minimum(gap, 0.0)[:, None] * normal).sum(axis=0)
    return u, force


@pytest.mark.slow
def test_a_finger_on_a_cylinder_as_felupe_solves_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(obstacles_module, "SMOOTHING", 0.0)  # FElupe's penalty sets in at once
    model = Reduced2D(len(DESIGN), obstacles=[{"kind": "cylinder", "centre": list(CENTRE), "radius": RADIUS}])
    solution = model.solve(DESIGN)
    last = solution.response.metadata["contact"]["levels"][-1]
    force = np.asarray(last["obstacles"][0]["force_n"]) / model.unit.width  # per mm of depth
    u_felupe, force_felupe = felupe_contact(model)
    u = solution.displacements[-1]
    assert np.linalg.norm(force) > 5e-3  # N/mm: the finger presses on the cylinder
    # both converge to a relative residual of 1e-8: they agree to 1e-8 (6.6e-9 mm in 13.3 mm, the force to 5.8e-9)
    assert np.abs(u - u_felupe).max() < 1e-6 * np.abs(u).max()
    assert np.linalg.norm(force - force_felupe) < 1e-6 * np.linalg.norm(force)

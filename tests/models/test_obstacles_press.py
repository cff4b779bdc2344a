"""A hard press in 2D: the 15-unit default design's tip against a cylinder in its way and against a wall at its
first level's tip, without and with friction. The design lengthens more than it bends, so its tip pushes on the
obstacle; the contact-aware Newton rules (:mod:`pneumorph.fem.fast.newton`: the stride of a step, the refresh on a
change of contact state) and the penalty (:data:`pneumorph.fem.fast.contact.PENALTY`) take these ramps through."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.models import make_model
from pneumorph.models.fe import Reduced2D
from pneumorph.models.fe.obstacles import blocked_obstacle

DESIGN = "001111010001001"
#: 5 mm beyond the free tip at 22.5 kPa, (163.74, 7.33) mm, along its chord to the tip at 45 kPa, (171.80, 9.51) mm:
#: the cylinder's surface is 1 mm beyond the tip at 22.5 kPa
CENTRE = [168.565, 8.638]


def _balanced(levels: list[dict]) -> None:
    """The clamp's reaction equals the obstacle's force at every level in contact, within 1 %."""
    for level in levels:
        force = np.asarray(level["obstacles"][0]["force_n"])
        assert np.allclose(level["base_reaction_n"], force, rtol=0.0, atol=1e-2 * np.linalg.norm(force) + 1e-9)


@pytest.mark.parametrize("friction", [0.0, 0.5])
def test_a_finger_pressed_on_a_cylinder_in_its_way(friction: float) -> None:
    """Untouched to 22.5 kPa, then pressed; with the penalty at 100 times the shear modulus and unbounded steps
    the frictionless ramp stopped at 25.1 kPa (its residual stalled at the tolerance) and the frictional one at
    27 kPa."""
    cylinder = {"kind": "cylinder", "centre": CENTRE, "radius": 4.0, "friction": friction}
    response = Reduced2D(15, obstacles=[cylinder]).solve(DESIGN).response
    assert response.converged
    levels = response.metadata["contact"]["levels"]
    forces = np.array([level["obstacles"][0]["force_magnitude_n"] for level in levels])
    assert np.all(forces[:5] == 0.0) and np.all(forces[5:] > 1e-3)  # N, from 27 kPa on
    _balanced(levels)
    if friction:  # friction holds the tip, which slides round the cylinder without it
        assert forces.max() > 0.1
    else:
        assert forces.max() < 0.05


def test_a_blocked_finger_with_friction_cuts_back_little() -> None:
    """The wall at the first level's tip with friction 0.5: the blocked force rises to 0.7 N at 18-22.5 kPa and falls as
    the finger curls away; 127 Newton iterations and 3 cut-backs, against 297 and 11 with the penalty at 100 times the
    shear modulus and unbounded steps."""
    model = Reduced2D(15)
    wall = {**blocked_obstacle(model, DESIGN), "friction": 0.5}
    response = model.variant(obstacles=[wall]).solve(DESIGN).response
    assert response.converged and response.metadata["cutbacks"] <= 4
    levels = response.metadata["contact"]["levels"]
    _balanced(levels)
    forces = [level["obstacles"][0]["force_magnitude_n"] for level in levels]
    assert int(np.argmax(forces)) in (3, 4) and 0.6 < max(forces) < 0.8


@pytest.mark.slow
def test_a_3d_finger_pressed_on_a_rough_cylinder_in_its_way() -> None:
    """The 3D half model against a cylinder across the width, placed as in 2D from its own free tip at 22.5 and
    45 kPa, (163.62, 7.05) and (171.52, 8.48) mm, with friction 0.5: through the ramp with no cut-back (6 with the
    penalty at 100 times the shear modulus, unbounded steps and a tangent kept across changes of contact state),
    the clamp balancing the cylinder."""
    cylinder = {"kind": "cylinder", "centre": [168.536, 7.944, 7.5], "radius": 4.0, "axis": [0.0, 0.0, 1.0],
                "friction": 0.5}
    response = make_model(15, {"fidelity": "3d"}).variant(obstacles=[cylinder]).solve(DESIGN).response
    assert response.converged and response.metadata["cutbacks"] == 0
    levels = response.metadata["contact"]["levels"]
    _balanced(levels)
    forces = np.array([level["obstacles"][0]["force_magnitude_n"] for level in levels])
    assert np.all(forces[:5] == 0.0) and 0.1 < forces[-1] < 0.3  # N

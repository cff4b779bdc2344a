"""Chords of a space polyline as twist-free turns: the inverse of their composition, the planar chain's turns
in the plane, and turns that turn with the actuator about its long axis."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import serve_table
from pneumorph.models.chain.space import frame_elements, frame_polyline, space_elements, space_polyline
from pneumorph.models.factory import make_model
from pneumorph.models.response import response_elements


def _curves(seed: int, shape: tuple[int, ...], m: int) -> np.ndarray:
    """Random polylines of ``m`` chords of 8-12 mm turning by up to 40 degrees, from the origin along x."""
    rng = np.random.default_rng(seed)
    turns = rng.uniform(-0.7, 0.7, size=(*shape, m, 2))
    turns[..., 0, :] *= 0.3
    return space_polyline(turns, rng.uniform(8, 12, size=(*shape, m)), np.zeros((*shape, 3)))


def test_composing_the_elements_gives_the_polyline_back() -> None:
    points = _curves(0, (4, 6), 16)  # levels x designs x points
    turns, lengths = space_elements(points)
    assert turns.shape == (4, 6, 16, 2) and lengths.shape == (4, 6, 16)
    assert np.abs(space_polyline(turns, lengths, points[..., 0, :]) - points).max() < 1e-10


def test_a_planar_response_has_the_planar_chains_turns() -> None:
    """The shipped 2D table's response of the default design, put in space at z = 0."""
    model = make_model(15, {"fidelity": "2d", "pressure_kpa": 36})
    served = serve_table(model)
    assert served is not None
    response = ChainModel(served.table, 15).evaluate("001111010001001")
    turn, length, _ = response_elements(response)
    plane = np.stack([response.centreline(k) for k in range(response.n_levels)])
    turns, lengths = space_elements(plane)  # (x, y): in the plane z = 0
    assert np.all(turns[..., 0] == 0.0)
    assert np.abs(turns[..., 1] - turn).max() < 1e-12 and np.abs(lengths - length).max() < 1e-12


@pytest.mark.parametrize("degrees", [90.0, 180.0, -30.0])
def test_turning_the_actuator_about_its_axis_turns_its_turns(degrees: float) -> None:
    """About x (the base's chord direction), a turn (about y, about z) is a vector in the y-z plane: a bend towards
    +y turned 90 degrees bends towards +z, about y negatively; turned over (180), both turns change sign."""
    points = _curves(1, (3,), 12)
    turns, lengths = space_elements(points)
    turned = points @ Rotation.from_rotvec([np.radians(degrees), 0, 0]).as_matrix().T
    again, same = space_elements(turned)
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    expected = np.stack([c * turns[..., 0] - s * turns[..., 1], s * turns[..., 0] + c * turns[..., 1]], axis=-1)
    assert np.abs(again - expected).max() < 1e-10 and np.abs(same - lengths).max() < 1e-10


def test_the_frame_elements_compose_back_and_keep_the_roll() -> None:
    """Chords in their units' frames and each frame in the one before: composing them gives the polyline back,
    whatever the frames (rolled too)."""
    rng = np.random.default_rng(2)
    points = _curves(3, (2, 5), 9)  # 8 units: base, 8 centres, tip
    frames = rng.normal(scale=0.3, size=(2, 5, 8, 3))
    chords, turns = frame_elements(points, frames)
    assert chords.shape == (2, 5, 9, 3) and turns.shape == (2, 5, 8, 3)
    assert np.abs(frame_polyline(chords, turns, points[..., 0, :]) - points).max() < 1e-10
    # the first unit's frame in the base's is its own rotation
    assert np.abs(turns[..., 0, :] - frames[..., 0, :]).max() < 1e-12

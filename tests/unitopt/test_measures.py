"""Omega, h_b and the strain of the unit optimisation on fields whose answers are known."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.errors import SettingsError
from pneumorph.geometry.assembly import assemble
from pneumorph.geometry.unit import UnitSpec
from pneumorph.unitopt.measures import balloon_heights, chord_turns, measure, principal_strains


@pytest.fixture(scope="module")
def mesh():
    """Three coarse aligned units, half width (as the probe meshes them)."""
    return assemble(UnitSpec(element_size=3.0), "000", dim=3, half=True)


def _rigid(points: np.ndarray, angle: float, shift: tuple[float, float]) -> np.ndarray:
    """The displacement of a rigid rotation about z by ``angle`` (rad) and a shift in x-y."""
    c, s = np.cos(angle), np.sin(angle)
    x, y = points[:, 0], points[:, 1]
    moved = np.stack([c * x - s * y + shift[0], s * x + c * y + shift[1], points[:, 2]], axis=1)
    return moved - points


def test_a_rigid_motion_turns_nothing_balloons_nothing_and_strains_nothing(mesh) -> None:
    u = _rigid(mesh.points, 0.7, (3.0, -2.0))
    m = measure(mesh, u[None], curl_deg=np.degrees(0.7))
    assert abs(m.omega_deg) < 1e-9
    assert m.balloon_mm < 1e-9 and m.strain < 1e-9 and m.layer_strain < 1e-9
    assert m.curl_per_unit_deg == pytest.approx(np.degrees(0.7) / 3)


def test_a_uniform_stretch_is_its_own_principal_strain(mesh) -> None:
    u = mesh.points * [0.0, 0.0, 0.0]
    u[:, 1] = 0.35 * mesh.points[:, 1]  # a stretch of 1.35 across the height
    assert principal_strains(mesh, u, "body") == pytest.approx(0.35, abs=1e-9)
    assert principal_strains(mesh, u, "layer") == pytest.approx(0.35, abs=1e-9)


def test_chord_turns_of_points_on_a_circle_are_the_angle_between_them() -> None:
    t = np.radians([0.0, 20.0, 40.0, 60.0])
    points = np.stack([np.sin(t), 1 - np.cos(t)], axis=1) * 30.0
    assert chord_turns(points) == pytest.approx([20.0, 20.0])
    assert chord_turns(points * [1, -1]) == pytest.approx([-20.0, -20.0])  # turned over: the opposite sign
    with pytest.raises(SettingsError, match="at least 3"):
        chord_turns(points[:2])


def test_a_bulge_of_the_soft_wall_is_its_height(mesh) -> None:
    """Push the bottom face's middle of the middle unit down by a known bump on top of a rigid motion."""
    p = mesh.points
    bump = np.where((np.abs(p[:, 1]) < 1e-9) & (p[:, 0] > 10.5) & (p[:, 0] < 21.0),
                    0.8 * np.sin(np.pi * (p[:, 0] - 10.5) / 10.5), 0.0)
    u = np.zeros_like(p)
    u[:, 1] = -bump
    rotation = np.array([[np.cos(0.3), -np.sin(0.3)], [np.sin(0.3), np.cos(0.3)]])
    turned = (p[:, :2] + u[:, :2]) @ rotation.T - p[:, :2]
    u[:, :2] = turned
    bottom, end, side = balloon_heights(mesh, u)
    assert bottom == pytest.approx(bump.max(), abs=1e-9) and bump.max() > 0.7
    assert end < 1e-9 and side < 1e-9
    u[:, 2] = np.where(np.abs(p[:, 2]) < 1e-9, -0.4, 0.0)  # the outer side face pushed out by 0.4 mm
    assert balloon_heights(mesh, u)[2] == pytest.approx(0.4)


def test_a_turned_over_unit_is_refused() -> None:
    mesh = assemble(UnitSpec(element_size=3.0), "010", dim=3, half=True)
    with pytest.raises(SettingsError, match="aligned"):
        balloon_heights(mesh, np.zeros_like(mesh.points))


def test_the_built_in_units_omega_is_the_15_unit_actuators_curl_per_unit() -> None:
    """The probe (3 units, the package's 3D model and mesh) against the 15-unit curl of docs/unit-geometry.md.

    302.78 degrees over 15 units is 20.19 per unit; the middle of 3 units sits next to the clamped first
    unit and the tip unit and turns 3.5 % more (docs/unit-library.md): within 5 %.
    """
    from pneumorph.unitopt.probe import UnitProbe, measures_of

    m = measures_of(UnitProbe(UnitSpec()).evaluate("000"))
    assert m.omega_deg == pytest.approx(302.78 / 15, rel=0.05)
    assert 0 < m.balloon_mm < UnitSpec().pitch and 0 < m.strain < 4.4

"""Rigid obstacles in the FE models (:mod:`pneumorph.models.fe.obstacles`): out of reach they change nothing, a wall
at the free tip's position takes force only above that pressure, the clamp's reaction balances the obstacles'
forces, and bad obstacles are refused before any solve."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pneumorph.errors import SearchConfigError, SettingsError
from pneumorph.models import make_model
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D
from pneumorph.models.fe.obstacles import blocked_obstacle, parse_obstacle

DESIGN = "000"


@pytest.fixture(scope="module")
def free() -> object:
    return Reduced2D(len(DESIGN)).solve(DESIGN)


def _levels(solution: object) -> list[dict]:
    return solution.response.metadata["contact"]["levels"]


def test_an_obstacle_out_of_reach_changes_nothing(free: object) -> None:
    far = [{"kind": "plane", "point": [0.0, 100.0], "normal": [0.0, -1.0]},
           {"kind": "cylinder", "centre": [80.0, 0.0], "radius": 10.0}]
    model = Reduced2D(len(DESIGN), obstacles=far)
    solution = model.solve(DESIGN)
    assert np.abs(solution.displacements - free.displacements).max() < 1e-6
    for level in _levels(solution):
        assert all(o["force_magnitude_n"] == 0.0 and not o["nodes_in_contact"] for o in level["obstacles"])
    # the shape figure draws them (a plane as a line, the cylinder as a circle) with their forces
    from matplotlib.patches import Circle

    from pneumorph.plot.shape import plot_shape

    ax = plot_shape(solution).axes[0]
    assert [type(p) for p in ax.patches if isinstance(p, Circle)] == [Circle]
    assert any(line.get_label() == f"obstacle 1: 0 N at {solution.response.pressures[-1] * 1e3:.4g} kPa"
               for line in ax.lines)
    # the free model's fingerprint is that of a model without the option; obstacles change it
    assert "obstacles" not in Reduced2D(3).describe()
    assert model.fingerprint() != Reduced2D(3).fingerprint()


def test_a_wall_at_the_free_tip_takes_force_only_above_its_pressure(free: object) -> None:
    """A wall touching the free end where it is at level k, normal to its motion there."""
    k = 5
    mesh, u = free.mesh, free.displacements
    tip = free.response.tip
    d = (tip[k] - tip[k - 1]) / np.linalg.norm(tip[k] - tip[k - 1])
    end = np.isclose(mesh.points[:, 0], mesh.points[mesh.end_points[0], 0])
    x = (mesh.points + u[k])[end]
    wall = {"kind": "plane", "point": x[np.argmax(x @ d)].tolist(), "normal": (-d).tolist(), "on": "end"}
    solution = Reduced2D(len(DESIGN), obstacles=[wall]).solve(DESIGN)
    forces = np.array([level["obstacles"][0]["force_magnitude_n"] for level in _levels(solution)])
    assert np.all(forces[:k] == 0.0)
    assert forces[-1] > 0.05  # N: the end pressed against the wall
    # just touching at its pressure: the penalty's blend (over 2 % of an element) pushes a touching node with
    # a quarter of the penalty times that gap
    assert forces[k] < 1e-2 * forces[-1]
    assert np.all(np.diff(forces[k:]) > 0.0)
    # the shape figure's legend gives the wall's force at the last level drawn, and that level's pressure
    from pneumorph.plot.shape import plot_shape

    pressures = solution.response.pressures * 1e3
    for levels in ([k - 1, len(forces) - 1], [len(forces) - 1], [k - 1, k + 2]):
        (legend,) = plot_shape(solution, levels=levels).legends
        walls = [t.get_text() for t in legend.get_texts() if t.get_text().startswith("obstacle")]
        assert walls == [f"obstacle 1: {forces[levels[-1]]:.3g} N at {pressures[levels[-1]]:.4g} kPa"]
    assert walls != [f"obstacle 1: 0 N at {pressures[k - 1]:.4g} kPa"]  # not the first section's


def test_the_clamp_balances_the_obstacles(tmp_path: object) -> None:
    """The pressure is internal: the clamp's reaction on the actuator is the sum of the obstacles' forces."""
    obstacles = [{"kind": "cylinder", "centre": [38.0, 22.0], "radius": 4.0},
                 {"kind": "plane", "point": [36.0, 0.0], "normal": [-1.0, 0.0]}]
    solution = Reduced2D(len(DESIGN), obstacles=obstacles).solve(DESIGN)
    levels = _levels(solution)
    last = levels[-1]
    total = np.sum([o["force_n"] for o in last["obstacles"]], axis=0)
    assert all(o["force_magnitude_n"] > 0.01 for o in last["obstacles"])  # both pressed
    assert last["obstacles"][0]["contact_length_mm"] > 0.0
    for level in levels:
        total = np.sum([o["force_n"] for o in level["obstacles"]], axis=0)
        assert np.allclose(level["base_reaction_n"], total, rtol=0.0, atol=1e-2 * max(np.linalg.norm(total), 1e-9))
    assert solution.response.converged
    # the VTK series holds each node's share: the obstacles' forces summed
    import meshio

    from pneumorph.io import write_vtk_series

    write_vtk_series(solution, tmp_path)
    data = meshio.read(tmp_path / f"actuator_{len(levels) - 1:02d}.vtu").point_data
    field = data["contact_force"]
    assert np.allclose(field.sum(axis=0)[:2], np.sum([o["force_n"] for o in last["obstacles"]], axis=0), atol=1e-12)
    # and its contact pressure (kPa), where it touches only
    touching = np.zeros(len(field), dtype=bool)
    for o in last["obstacles"]:
        touching[o["nodes_in_contact"]] = True
    assert np.all(data["contact_pressure"][touching] > 0.0) and np.all(data["contact_pressure"][~touching] == 0.0)


def test_blocked_force_rises_along_the_ramp() -> None:
    model = Reduced2D(len(DESIGN), ramp_spec=RampSpec(pressure=0.03, steps=replace(Reduced2D.default_steps,
                                                                                     increments=4)))
    wall = blocked_obstacle(model, DESIGN)
    assert wall["on"] == "end" and wall["normal"][1] < -0.9  # against the curl (+y)
    solution = model.variant(obstacles=[wall]).solve(DESIGN)
    forces = [level["obstacles"][0]["force_magnitude_n"] for level in _levels(solution)]
    assert forces[0] > 0.0 and np.all(np.diff(forces) > 0.0)


def test_model_settings_carry_obstacles() -> None:
    table = parse_obstacle("cylinder:centre=38,22;radius=4")
    model = make_model(3, {"obstacle": [table]})
    assert model.describe()["obstacles"] == [{"kind": "cylinder", "centre": [38.0, 22.0], "radius": 4.0}]
    assert model.variant().obstacles == model.obstacles
    with pytest.raises(SearchConfigError, match="radius"):
        make_model(3, {"obstacle": [{"kind": "cylinder", "centre": [38, 22], "radius": 0}]})
    with pytest.raises(SearchConfigError, match="list"):
        make_model(3, {"obstacle": {"kind": "sphere"}})
    with pytest.raises(SettingsError, match="fast backend"):
        Reduced2D(3, backend="felupe", obstacles=[table])


def test_an_obstacle_inside_the_actuator_is_refused_before_the_solve() -> None:
    for obstacle in ({"kind": "sphere", "centre": [10.0, 6.0], "radius": 2.0},  # in a cavity: its filler's points
                     {"kind": "plane", "point": [0.0, 11.0], "normal": [0.0, -1.0]}):
        model = Reduced2D(3, obstacles=[obstacle])
        with pytest.raises(SettingsError, match="starts inside"):
            model.build(DESIGN)


def test_a_half_model_needs_symmetric_obstacles() -> None:
    model = Full3D(1, obstacles=[{"kind": "sphere", "centre": [20.0, 20.0, 0.0], "radius": 2.0}])
    with pytest.raises(SettingsError, match="mid-plane"):
        model.build("0")


def test_a_calculix_deck_of_a_model_with_obstacles_is_refused() -> None:
    from pneumorph.export.calculix import calculix_deck

    model = Full3D(1, obstacles=[{"kind": "plane", "point": [0, 80, 0], "normal": [0, -1, 0]}])
    with pytest.raises(SettingsError, match="obstacles"):
        calculix_deck(model, "0")


@pytest.mark.slow
def test_3d_an_obstacle_out_of_reach_changes_nothing_and_the_clamp_balances_a_wall() -> None:
    ramp = RampSpec(pressure=0.03, steps=replace(Full3D.default_steps, increments=3))
    free = Full3D(2, ramp_spec=ramp).solve("00")
    far = Full3D(2, ramp_spec=ramp, obstacles=[{"kind": "plane", "point": [0, 80, 0], "normal": [0, -1, 0]}])
    assert np.abs(far.solve("00").displacements - free.displacements).max() < 1e-6
    model = Full3D(2, ramp_spec=ramp)
    wall = blocked_obstacle(model, "00")
    solution = model.variant(obstacles=[wall]).solve("00")
    levels = _levels(solution)
    for level in levels:
        force = np.asarray(level["obstacles"][0]["force_n"])
        assert np.allclose(level["base_reaction_n"], force, rtol=0.0, atol=1e-2 * np.linalg.norm(force))
    assert levels[-1]["obstacles"][0]["force_magnitude_n"] > levels[0]["obstacles"][0]["force_magnitude_n"] > 0.0
    assert levels[-1]["obstacles"][0]["contact_area_mm2"] > 0.0
    # the 3D shape figure draws the wall beside the actuator's surface, with its force
    from pneumorph.plot.shape import plot_shape

    labels = [c.get_label() for c in plot_shape(solution).axes[0].collections]
    assert labels[1:] == [f"obstacle 1: {levels[-1]['obstacles'][0]['force_magnitude_n']:.3g} N at 30 kPa"]
    # with friction on the wall: the end sticks to it, the clamp still balances it
    rough = model.variant(obstacles=[{**wall, "friction": 0.5}]).solve("00")
    last = _levels(rough)[-1]
    force = np.asarray(last["obstacles"][0]["force_n"])
    assert rough.response.converged and np.allclose(last["base_reaction_n"], force, atol=1e-2 * np.linalg.norm(force))
    assert np.linalg.norm(force - levels[-1]["obstacles"][0]["force_n"]) > 1e-3 * np.linalg.norm(force)


@pytest.mark.slow
def test_3d_a_finger_with_friction_on_a_cylinder() -> None:
    """A 3-unit 3D finger pressed on a cylinder: friction 0 and 0.5 both run to the full pressure with at most one
    cut-back, balance the clamp within 1 % and differ. The frictional Newton steps solve the whole tangent (the
    symmetric factorisation and the friction's rest by GMRES); with the symmetric part alone this ramp took 290
    iterations and 7 cut-backs."""
    cylinder = {"kind": "cylinder", "centre": [34.0, 24.0, 7.5], "radius": 4.0, "axis": [0.0, 0.0, 1.0]}
    forces = {}
    for friction in (0.0, 0.5):
        solution = Full3D(3, obstacles=[{**cylinder, "friction": friction}]).solve(DESIGN)
        metadata = solution.response.metadata
        assert solution.response.converged and metadata["cutbacks"] <= 1
        last = _levels(solution)[-1]
        forces[friction] = force = np.asarray(last["obstacles"][0]["force_n"])
        assert np.linalg.norm(force) > 0.1  # N
        assert np.allclose(last["base_reaction_n"], force, rtol=0.0, atol=1e-2 * np.linalg.norm(force))
    assert np.linalg.norm(forces[0.5] - forces[0.0]) > 1e-2 * np.linalg.norm(forces[0.0])


def test_a_certified_search_over_obstacles_falls_back_to_the_ga() -> None:
    """The chain model knows no contact: the certified search is not claimed over obstacles."""
    from pneumorph.design.config import DesignConfig

    wall = {"kind": "plane", "point": [0, 100, 0], "normal": [0, -1, 0]}
    config, why = DesignConfig(model={"obstacle": [wall]}).searchable()
    assert config.search == "ga" and "contact with [[model.obstacle]]" in (why or "")
    assert DesignConfig().searchable() == (DesignConfig(), None)


def test_a_finger_with_friction_on_a_cylinder() -> None:
    """Friction 0 and 0.5 both run to the full pressure and balance the clamp; friction changes the grip."""
    cylinder = {"kind": "cylinder", "centre": [35.0, 25.0], "radius": 5.0}
    forces = {}
    for friction in (0.0, 0.5):
        model = Reduced2D(4, obstacles=[{**cylinder, "friction": friction}])
        assert ("friction" in model.describe()["obstacles"][0]) == (friction > 0)
        solution = model.solve("0000")
        assert solution.response.converged
        # Newton steps that keep the nodes out of the cylinder (pneumorph.fem.fast.newton) take the ramp with at
        # most one cut-back; steps blind to it threw the curling finger into it and were cut back 8 times
        assert solution.response.metadata["cutbacks"] <= 1
        last = _levels(solution)[-1]
        forces[friction] = force = np.asarray(last["obstacles"][0]["force_n"])
        assert np.allclose(last["base_reaction_n"], force, rtol=0.0, atol=1e-6 * np.linalg.norm(force))
    assert np.linalg.norm(forces[0.5] - forces[0.0]) > 1e-2 * np.linalg.norm(forces[0.0])


@pytest.mark.slow
def test_a_long_finger_grazing_a_cylinder_solves_through_the_ramp() -> None:
    """A 15-unit finger whose free tip ends (152.2, -5.55) mm at 45 kPa, against a cylinder of 4 mm radius
    centred there: the tip slides round it. Newton steps blind to the cylinder failed this ramp at 40 kPa."""
    cylinder = {"kind": "cylinder", "centre": [152.2, -5.55], "radius": 4.0}
    solution = Reduced2D(15, obstacles=[cylinder]).solve("111000000111111")
    response = solution.response
    assert response.converged  # (with 2 cut-backs; its tip's sliding makes their count sensitive to the centre)
    last = _levels(solution)[-1]
    force = np.asarray(last["obstacles"][0]["force_n"])
    assert 1e-4 < np.linalg.norm(force) < 1e-2  # N: it grazes the cylinder
    assert np.allclose(last["base_reaction_n"], force, rtol=0.0, atol=1e-2 * np.linalg.norm(force))


def test_a_volume_ramp_presses_a_finger_on_a_rough_cylinder(capsys: pytest.CaptureFixture[str]) -> None:
    """``simulate --volume-change`` with an obstacle: below contact every level is the pressure ramp's state at its
    pressure; then the cylinder takes force (with friction along it) and the clamp balances it."""
    import json

    from pneumorph.cli import main
    from pneumorph.fem import StepSettings

    cylinder = {"kind": "cylinder", "centre": [36.0, 14.0], "radius": 3.0, "friction": 0.5}
    assert main(["simulate", "-o", DESIGN, "--volume-change", "0.6", "--increments", "5", "--json",
                 "--obstacle", "cylinder:centre=36,14;radius=3;friction=0.5"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["converged"] and data["metadata"]["volume0"] > 0.0
    contact = data["metadata"]["contact"]
    assert contact["obstacles"] == [cylinder]
    forces = [level["obstacles"][0]["force_magnitude_n"] for level in contact["levels"]]
    assert forces[-1] > 0.01 and forces[-2] == 0.0  # N: the finger reaches the cylinder in the last increment
    last = contact["levels"][-1]
    force = np.asarray(last["obstacles"][0]["force_n"])
    assert np.allclose(last["base_reaction_n"], force, rtol=0.0, atol=1e-6 * np.linalg.norm(force))
    free = data["levels"][-2]  # not touching: the pressure ramp's state at that pressure
    pressure = free["pressure_kpa"]
    assert 25.0 < pressure < data["levels"][-1]["pressure_kpa"]
    ramped = Reduced2D(len(DESIGN), obstacles=[cylinder],
                       ramp_spec=RampSpec(pressure=pressure / 1e3, steps=StepSettings(increments=2, substeps=2)))
    assert np.abs(ramped.solve(DESIGN).response.tip[-1] - free["tip_mm"]).max() < 1e-6  # mm

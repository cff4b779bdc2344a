"""The volume-controlled ramp: the pressure ramp's states below the limit, past the pressure's maximum beyond it."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.errors import SettingsError, SimulationFailed
from pneumorph.fem import StepSettings, ramp
from pneumorph.fem.fast.volume import VolumeControl, example_plate, volume_control
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D

THIN = {"wall": 0.25, "cells_per_mm": 4, "pressure": 0.02}  # 0.25 mm walls round a 2.5 mm hole


def _pressure_ramp(increments: int, **plate) -> tuple[list[float], list[float], np.ndarray]:
    body, apply, step = example_plate(**plate)
    pressures, volumes = [], []

    def record(k: int, t: float) -> None:
        pressures.append(t * plate.get("pressure", 0.02))
        volumes.append(step.system.cavity_volume(body.displacement.ravel()))

    ramp(body.items, body.field, apply, body.dof1, body.dof0, StepSettings(increments=increments, substeps=1),
         on_level=record, substep=step)
    return pressures, volumes, body.displacement.copy()


def _volume_ramp(change: float, increments: int, reuse: float | None = None, depth: int = 0, **plate):
    body, apply, step = example_plate(reuse=reuse, **plate)
    step.depth = depth  # Anderson acceleration of the kept tangent's steps, the load factor's among them
    control = VolumeControl(step, apply, change, body.displacement.ravel())
    pressures, volumes = [], []

    def record(k: int, t: float) -> None:
        pressures.append(control.factor * plate.get("pressure", 0.02))
        volumes.append(step.system.cavity_volume(body.displacement.ravel()))

    ramp(body.items, body.field, control.apply, body.dof1, body.dof0,
         StepSettings(increments=increments, substeps=1), on_level=record, substep=control)
    return control, pressures, volumes, body.displacement.copy()


@pytest.mark.parametrize(("reuse", "depth"), [(None, 0), (0.5, 0), (0.5, 4)])
def test_the_volume_ramp_ends_on_the_pressure_ramps_state(reuse: float | None, depth: int) -> None:
    # thin walls below their limit (4.41 kPa): the pressure ramp to 4 kPa, then its volume driven
    _, volumes, u = _pressure_ramp(4, **{**THIN, "pressure": 0.004})
    control, p, v, u2 = _volume_ramp(volumes[-1] / 6.25 - 1.0, 4, reuse=reuse, depth=depth,
                                     **{**THIN, "pressure": 0.004})
    assert control.volume0 == pytest.approx(6.25, rel=1e-12)  # the 2.5 x 2.5 mm hole
    assert v[-1] == pytest.approx(volumes[-1], rel=1e-9)
    assert p[-1] == pytest.approx(0.004, rel=1e-6)
    assert np.max(np.abs(u2 - u)) < 1e-6 * np.max(np.abs(u))
    assert np.all(np.diff(p) > 0)  # below the limit the pressure rises with the volume


def test_the_volume_ramp_passes_the_pressure_maximum_where_the_pressure_ramp_stops() -> None:
    with pytest.raises(SimulationFailed) as failed:
        _pressure_ramp(5, **{**THIN, "pressure": 0.005})
    reached = failed.value.reached * 0.005
    _, p, v, _ = _volume_ramp(12.0, 12, **THIN)
    top = int(np.argmax(p))
    assert 0 < top < len(p) - 1  # a maximum inside the ramp, the pressure falling after it
    assert p[-1] < p[top] - 1e-4  # 0.1 kPa below it at 13 times the initial volume
    assert v[-1] == pytest.approx(13 * 6.25, rel=1e-9)
    # the pressure ramp stops just below the maximum the volume ramp passes (sampled every 6.25 mm^2)
    assert reached < p[top] * 1.002
    assert reached > p[top] * 0.98


def test_volume_control_needs_the_fast_backend() -> None:
    body, apply, _ = example_plate()
    substep, _ = body.stepper("felupe")
    with pytest.raises(SettingsError, match="fast backend"):
        volume_control(0.5, substep, apply, body.displacement)


def _volume_of(model, design: str, displacement: np.ndarray) -> float:
    _, body, _ = model.build(design)
    _, monitor = body.stepper("fast")
    body.field[0].values[:] = displacement[:, : body.field[0].values.shape[1]]
    return monitor()


def test_a_volume_controlled_2d_actuator_has_the_pressure_ramps_shape_at_its_pressure() -> None:
    steps = StepSettings(increments=3, substeps=1)
    model = Reduced2D(2, ramp_spec=RampSpec(pressure=0.03, steps=steps))
    pressure = model.solve("01")
    end = _volume_of(model, "01", pressure.displacements[-1])
    volume = Reduced2D(2, ramp_spec=RampSpec(pressure=0.03, steps=steps, volume=end / 54.0 - 1.0)).solve("01")
    assert volume.response.metadata["volume0"] == pytest.approx(54.0, rel=1e-9)  # 2 cavities, 2D areas
    assert volume.response.pressures[-1] == pytest.approx(0.03, rel=1e-6)
    assert np.max(np.abs(volume.displacements[-1] - pressure.displacements[-1])) < 1e-5
    assert np.max(np.abs(volume.response.tip[-1] - pressure.response.tip[-1])) < 1e-5


@pytest.mark.slow
def test_a_volume_controlled_3d_actuator_has_the_pressure_ramps_shape_at_its_pressure() -> None:
    steps = StepSettings(increments=2, substeps=1)
    model = Full3D(1, ramp_spec=RampSpec(pressure=0.02, steps=steps))
    pressure = model.solve("0")
    end = _volume_of(model, "0", pressure.displacements[-1])
    _, body, _ = model.build("0")
    _, monitor = body.stepper("fast")
    v0 = monitor()
    volume = Full3D(1, ramp_spec=RampSpec(pressure=0.02, steps=steps, volume=end / v0 - 1.0)).solve("0")
    assert volume.response.pressures[-1] == pytest.approx(0.02, rel=1e-5)
    assert np.max(np.abs(volume.response.tip[-1] - pressure.response.tip[-1])) < 1e-4

"""The bimodal actuator under volume control: the pressure ramp's shapes, and on where the pressure ramp stops."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.bimodal.geometry import BimodalSpec
from pneumorph.bimodal.model import BimodalModel
from pneumorph.cli import main

ONE = BimodalSpec(voids=1, element_size=5.0)


@pytest.mark.slow
def test_the_volume_ramp_has_the_pressure_ramps_tip_at_its_pressure() -> None:
    volume = BimodalModel(ONE, crimp_ratio=0.3, pmax=0.01, step=0.005, volume=0.5).solve()
    assert volume.completed and volume.metadata["volume0_mm3"] > 0
    p_end = float(volume.pressures[-1])
    assert 0.0 < volume.pressures[0] < p_end  # the pressure rises with the volume below the limit
    pressure = BimodalModel(ONE, crimp_ratio=0.3, pmax=p_end, step=p_end / 2).solve()
    assert pressure.completed
    assert np.max(np.abs(pressure.tip[-1] - volume.tip[-1])) < 1e-5 * np.max(np.abs(pressure.tip[-1]))


@pytest.mark.slow
def test_the_volume_ramp_goes_on_where_the_pressure_ramp_stops() -> None:
    spec = BimodalSpec(voids=2, element_size=2.5, end_cap=0.0)
    pressure = BimodalModel(spec, crimp_ratio=0.2, pmax=0.06).solve()
    assert not pressure.completed  # the free 1.5 mm end wall balloons
    stop = float(pressure.pressures[-1])
    volume = BimodalModel(spec, crimp_ratio=0.2, pmax=0.06, volume=8.0).solve()
    assert volume.completed and len(volume.pressures) == 12
    assert volume.metadata["volumes_mm3"][-1] == pytest.approx(9 * volume.metadata["volume0_mm3"])
    assert volume.pressures.max() > stop  # past the pressure ramp's last converged level


@pytest.mark.slow
def test_the_default_command_is_volume_controlled_and_ends_normally(capsys) -> None:
    code = main(["bimodal", "-c", "0.2", "--voids", "2", "-q"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "volume control: pressure maximum" in out and "ramp ended early" not in out

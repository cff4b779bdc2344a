"""A nearby model's solve from a solved state (models.fe.warmstart.solve_near): the ramp's answer at the top
pressure in a few Newton iterations, for every parameter the identification moves; a start that does not fit
falls back to the ramp."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.geometry.unit import UnitSpec
from pneumorph.identify import ParameterSet
from pneumorph.identify.parameters import NAMES, STEPS
from pneumorph.models.factory import make_model
from pneumorph.models.fe.warmstart import solve_near

BASE = {"fidelity": "3d", "pressure_kpa": 36}
DESIGN = "010"


@pytest.fixture(scope="module")
def params() -> ParameterSet:
    return ParameterSet(UnitSpec(element_size=3.0))


@pytest.fixture(scope="module")
def start(params: ParameterSet):  # type: ignore[no-untyped-def]
    return make_model(3, params.settings(params.nominal, BASE)).solve(DESIGN)


@pytest.mark.parametrize("name", NAMES)
def test_each_step_of_the_jacobian_is_the_ramps_answer(params: ParameterSet, start, name: str) -> None:  # type: ignore[no-untyped-def]
    values = params.nominal.copy()
    values[NAMES.index(name)] += STEPS[name]
    model = make_model(3, params.settings(values, BASE))
    warm, cold = solve_near(model, DESIGN, start), model.solve(DESIGN)
    moved = np.abs(cold.displacements[-1] - start.displacements[-1]).max()
    assert moved > 0.02  # the step moves the actuator (the layer least: 0.023 mm) ...
    assert np.abs(warm.displacements[-1] - cold.displacements[-1]).max() < 1e-6  # ... and both reach one state
    for got, want in ((warm.response.centres[-1], cold.response.centres[-1]), (warm.response.tip[-1],
                                                                               cold.response.tip[-1])):
        assert np.abs(got - want).max() < 1e-6
    assert warm.response.curl[-1] == pytest.approx(cold.response.curl[-1], abs=1e-6)
    assert warm.response.converged and np.isnan(warm.response.centres[:-1]).all()  # the last level only
    assert warm.response.metadata["warm_start"] < cold.response.metadata["newton_iterations"] / 3


@pytest.mark.slow
def test_a_start_that_does_not_fit_falls_back_to_the_ramp(start) -> None:  # type: ignore[no-untyped-def]
    other = make_model(3, {**BASE, "unit": {"element_size": 2.5}})  # another grid: no node is the start's
    warm = solve_near(other, DESIGN, start)
    assert "warm_start" not in warm.response.metadata and not np.isnan(warm.response.centres).any()
    assert np.array_equal(warm.displacements, other.solve(DESIGN).displacements)

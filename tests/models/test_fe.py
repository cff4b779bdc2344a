"""Finite-element actuator models: symmetry, path independence, errors, provenance.

Small actuators and low pressures keep these fast; the physics checked does not depend on
the unit's cavity design.
"""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.errors import OrientationError, PressureRangeError, SettingsError, SimulationFailed
from pneumorph.fem import StepSettings
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials import get_filler
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D

LOW = RampSpec(pressure=0.01, steps=StepSettings(increments=2, substeps=2))


@pytest.fixture(scope="module")
def pair_2d():
    model = Reduced2D(2, ramp_spec=LOW)
    return model.evaluate("01"), model.evaluate("10")


def test_2d_inverting_every_unit_mirrors_the_shape(pair_2d) -> None:
    a, b = pair_2d
    H = UnitSpec().height
    assert a.converged and b.converged
    np.testing.assert_allclose(a.centres[..., 0], b.centres[..., 0], atol=1e-7)
    np.testing.assert_allclose(a.centres[..., 1], H - b.centres[..., 1], atol=1e-7)
    np.testing.assert_allclose(a.curl, -b.curl, atol=1e-6)
    np.testing.assert_allclose(a.tip[:, 1], H - b.tip[:, 1], atol=1e-7)


def test_2d_aligned_units_bend_towards_the_stiff_layer() -> None:
    r = Reduced2D(2, ramp_spec=LOW).evaluate("00")
    assert np.all(np.diff(r.curl) > 0) and r.curl[0] > 0
    assert np.all(r.tip[:, 1] > r.reference_tip[1])


def test_filler_path_independence() -> None:
    """Hyperelastic equilibrium depends only on the current load and moduli (Fig 5.7).

    A filler that follows E(P) and one held at E(p_max) reach the same shape at p_max
    but not at the intermediate levels, where the constant filler is softer.
    """
    eq52 = get_filler()
    e_end = float(eq52.modulus(LOW.pressure))
    constant = FillerLaw(
        name="constant", display_name="E(p_max)", coefficients=(e_end,),
        pressure_range=eq52.pressure_range, poisson_ratio=eq52.poisson_ratio,
    )
    varying = Reduced2D(2, ramp_spec=LOW, filler=eq52).evaluate("00")
    fixed = Reduced2D(2, ramp_spec=LOW, filler=constant).evaluate("00")
    np.testing.assert_allclose(fixed.centres[-1], varying.centres[-1], atol=1e-6)
    assert abs(fixed.curl[0]) > abs(varying.curl[0]) * 1.01


def test_pressure_outside_the_filler_range_is_refused() -> None:
    with pytest.raises(PressureRangeError, match="60 kPa is outside the calibrated range 0-45 kPa"):
        Reduced2D(3, ramp_spec=RampSpec(pressure=0.06))
    with pytest.raises(SettingsError, match="pressure must be a finite number > 0"):
        RampSpec(pressure=-0.01)


def test_orientation_of_the_wrong_length_is_refused() -> None:
    with pytest.raises(OrientationError, match="has 3 units, expected 2"):
        Reduced2D(2, ramp_spec=LOW).evaluate("010")
    with pytest.raises(SettingsError, match="n_units must be a whole number >= 1"):
        Reduced2D(0)


def test_failed_solve_names_the_design_and_the_pressure_reached() -> None:
    starved = RampSpec(pressure=0.01, steps=StepSettings(increments=2, substeps=1, max_iterations=1, max_cutbacks=1))
    failed = r"design 01: simulation failed, converged up to 0 kPa of 10 kPa"
    with pytest.raises(SimulationFailed, match=failed) as info:
        Reduced2D(2, ramp_spec=starved).evaluate("01")
    assert info.value.design == "01" and info.value.reached == 0.0


def test_fingerprint_follows_everything_that_changes_results(pair_2d) -> None:
    base = Reduced2D(2, ramp_spec=LOW)
    assert base.fingerprint() == Reduced2D(2, ramp_spec=LOW).fingerprint()
    assert base.fingerprint() != Reduced2D(3, ramp_spec=LOW).fingerprint()
    assert base.fingerprint() != Reduced2D(2, unit=UnitSpec(wall=1.4), ramp_spec=LOW).fingerprint()
    assert base.fingerprint() != Reduced2D(2, ramp_spec=RampSpec(pressure=0.02)).fingerprint()
    assert pair_2d[0].metadata["fingerprint"] == base.fingerprint()
    assert pair_2d[0].metadata["newton_iterations"] > 0


def test_3d_single_unit_mirror() -> None:
    ramp = RampSpec(pressure=0.005, steps=StepSettings(increments=1, substeps=1))
    model = Full3D(1, ramp_spec=ramp)
    a, b = model.evaluate("0"), model.evaluate("1")
    H = UnitSpec().height
    assert a.curl[-1] > 0
    np.testing.assert_allclose(a.centres[..., 1], H - b.centres[..., 1], atol=1e-7)
    np.testing.assert_allclose(a.curl, -b.curl, atol=1e-6)


def test_3d_half_model_equals_the_full_model() -> None:
    """The actuator is symmetric across its width: u_z = 0 on the mid-plane is exact."""
    ramp = RampSpec(pressure=0.005, steps=StepSettings(increments=1, substeps=1))
    half = Full3D(1, ramp_spec=ramp).evaluate("1")
    full = Full3D(1, ramp_spec=ramp, half=False).evaluate("1")
    assert half.metadata["dofs"] < 0.6 * full.metadata["dofs"]
    assert (half.axes, full.axes) == (2, 3)  # the full model keeps z: on the mid-plane here
    np.testing.assert_allclose(half.centres, full.centres[..., :2], atol=1e-7)
    np.testing.assert_allclose(full.centres[..., 2], UnitSpec().width / 2, atol=1e-9)
    np.testing.assert_allclose(half.curl, full.curl, atol=1e-6)


def test_2d_tip_displacement_converges_with_the_mesh() -> None:
    """Element sizes 1.5, 0.75, 0.375 mm on a 2-unit actuator at 15 kPa.

    The tip displacement changes less with each halving (measured: 0.0146 then 0.0073 mm
    of 2.13 mm) and the default 1.5 mm mesh lies within 3 % of the finest.
    """
    ramp = RampSpec(pressure=0.015, steps=StepSettings(increments=3, substeps=1))
    tips = []
    for h in (1.5, 0.75, 0.375):
        r = Reduced2D(2, unit=UnitSpec(element_size=h), ramp_spec=ramp).evaluate("00")
        tips.append(float(np.hypot(*(r.tip[-1] - r.reference_tip))))
    d1, d2 = abs(tips[1] - tips[0]), abs(tips[2] - tips[1])
    assert d2 < 0.7 * d1
    assert abs(tips[0] - tips[2]) < 0.03 * tips[2]


@pytest.mark.parametrize("pressure", [0.01, 0.045])
def test_2d_fast_backend_gives_felupes_results(pressure: float) -> None:
    """The vectorised assembly and its Newton method against FElupe's, 3 units.

    Both stop at FElupe's criterion ||r1|| / (1e-3 + ||r0||) < 1e-8; the equilibrium
    error this leaves is a relative force imbalance of 1e-8, so shapes may differ by
    about 1e-8 of the displacements (tens of mm): 1e-6 mm and 1e-5 degrees allow that
    with margin and would catch any difference in the equations.
    """
    design = "".join(map(str, np.random.default_rng(7).integers(0, 2, 3)))
    ramp = RampSpec(pressure=pressure)
    fast = Reduced2D(3, ramp_spec=ramp).evaluate(design)
    slow = Reduced2D(3, ramp_spec=ramp, backend="felupe").evaluate(design)
    assert fast.metadata["backend"] == "fast" and slow.metadata["backend"] == "felupe"
    assert fast.metadata["fingerprint"] == slow.metadata["fingerprint"]
    assert abs(fast.curl[-1]) > 1.0  # a real bending
    np.testing.assert_allclose(fast.centres, slow.centres, rtol=0, atol=1e-6)
    np.testing.assert_allclose(fast.tip, slow.tip, rtol=0, atol=1e-6)
    np.testing.assert_allclose(fast.curl, slow.curl, rtol=0, atol=1e-5)


def test_unknown_backend_is_refused() -> None:
    with pytest.raises(ValueError, match="backend must be one of fast, felupe, got 'jax'"):
        Reduced2D(2, backend="jax")
    with pytest.raises(ValueError, match="backend must be one of fast, felupe, got 'jax'"):
        Full3D(1, backend="jax")


@pytest.mark.parametrize("pressure", [0.015, 0.045])
def test_3d_fast_backend_gives_felupes_results(pressure: float) -> None:
    """The fast 3D path (symmetric assembly, kept tangents) against FElupe's Newton method.

    One unit, hex20 at 3 mm, the default ramp. Both stop at ||r1|| / (1e-3 + ||r0||) <
    1e-8, which leaves shapes free to differ by about 1e-8 of the displacements (mm):
    1e-6 mm and 1e-5 degrees allow that with margin and would catch any difference in
    the equations.
    """
    unit = UnitSpec(element_size=3.0)
    ramp = RampSpec(pressure=pressure, steps=Full3D.default_steps)
    fast = Full3D(1, unit=unit, ramp_spec=ramp).evaluate("0")
    slow = Full3D(1, unit=unit, ramp_spec=ramp, backend="felupe").evaluate("0")
    assert fast.metadata["backend"] == "fast" and slow.metadata["backend"] == "felupe"
    assert fast.metadata["fingerprint"] == slow.metadata["fingerprint"]
    assert fast.metadata["factorisations"] < slow.metadata["factorisations"]
    assert abs(fast.curl[-1]) > 2.0  # a real bending
    np.testing.assert_allclose(fast.centres, slow.centres, rtol=0, atol=1e-6)
    np.testing.assert_allclose(fast.tip, slow.tip, rtol=0, atol=1e-6)
    np.testing.assert_allclose(fast.curl, slow.curl, rtol=0, atol=1e-5)


def test_3d_fingerprint_holds_the_result_determining_ramp_settings_only() -> None:
    base = Full3D(2)
    solved_otherwise = RampSpec(steps=StepSettings(increments=10, substeps=3, max_cutbacks=2, max_iterations=9))
    assert Full3D(2, ramp_spec=solved_otherwise, backend="felupe").fingerprint() == base.fingerprint()
    assert base.describe()["steps"] == {"increments": 10, "tolerance": 1e-8}
    assert Full3D(2, ramp_spec=RampSpec(steps=StepSettings(increments=5))).fingerprint() != base.fingerprint()
    assert Full3D(2, ramp_spec=RampSpec(steps=StepSettings(tolerance=1e-6))).fingerprint() != base.fingerprint()
    assert Full3D(2, ramp_spec=RampSpec(pressure=0.03)).fingerprint() != base.fingerprint()


def test_a_failed_ramp_keeps_the_levels_it_converged(monkeypatch: pytest.MonkeyPatch) -> None:
    import pneumorph.models.fe.solving as fesolving
    from pneumorph.execution.outcome import solve

    ramp = RampSpec(pressure=0.01)  # 10 levels
    full = Reduced2D(2, ramp_spec=ramp).evaluate("01")
    real = fesolving.ramp  # FEModel.solve's ramp

    def failing(*args, on_level=None, **kwargs):  # the real ramp, stopped after its third level
        def level(k, t):
            on_level(k, t)
            if k == 2:
                raise SimulationFailed(reached=0.3, cause="stopped by the test")

        return real(*args, on_level=level, **kwargs)

    monkeypatch.setattr(fesolving, "ramp", failing)
    outcome = solve(Reduced2D(2, ramp_spec=ramp), "01")
    partial = outcome.response
    assert not outcome.ok and outcome.failure == "stopped by the test" and outcome.reached == pytest.approx(0.003)
    assert partial is not None and not partial.converged and partial.failure == "stopped by the test"
    assert np.array_equal(partial.curl[:3], full.curl[:3]) and np.isnan(partial.curl[3:]).all()

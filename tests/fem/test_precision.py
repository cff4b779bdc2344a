"""The fast 3D Newton method's factorisation precision, and why a first load step fails."""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from pneumorph.errors import SimulationFailed
from pneumorph.fem.fast.newton import FastSubstep
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, RampSpec

pytest.importorskip("pypardiso")


def _model(n: int = 1, tolerance: float = 1e-8, increments: int = 2, **unit: float) -> Full3D:
    steps = replace(Full3D.default_steps, tolerance=tolerance, increments=increments)
    return Full3D(n, UnitSpec(**unit), RampSpec(pressure=0.045, steps=steps))


class LinearisedScan:
    """A linear "system" K u = f with a chosen condition number (the fast systems' interface)."""

    symmetric, ordering, single_precision, tangent_dtype = True, 0, True, np.float64

    def __init__(self, cond: float, n: int = 60, seed: int = 0) -> None:
        import scipy.sparse as sp

        rng = np.random.default_rng(seed)
        q, _ = np.linalg.qr(rng.standard_normal((n, n)))
        self.K = (q * np.geomspace(1.0, cond, n)) @ q.T
        self.K = (self.K + self.K.T) / 2
        upper = sp.triu(sp.csr_matrix(self.K)).tocsr()
        upper.sort_indices()
        self.indptr, self.indices, self._data = upper.indptr, upper.indices, upper.data
        self.f = rng.standard_normal(n) * 1e-3 / np.sqrt(n)
        self.dof1, self.dof0 = np.arange(n), np.arange(0)

    def tangent_data(self) -> np.ndarray:
        return self._data.astype(self.tangent_dtype)

    def residual(self, u: np.ndarray) -> tuple[np.ndarray, float]:
        return self.K @ u - self.f, 1.0


def _solve_linear(cond: float) -> tuple[FastSubstep, str | None, np.ndarray, LinearisedScan]:
    system = LinearisedScan(cond)
    step = FastSubstep(system, reuse=Full3D.tangent_reuse, depth=Full3D.anderson_depth)
    fields = [SimpleNamespace(values=np.zeros(len(system.f)))]
    _, cause = step(fields, SimpleNamespace(max_iterations=25, tolerance=1e-5))
    return step, cause, fields[0].values, system


def test_a_stalling_single_precision_factorisation_is_replaced_by_double() -> None:
    """Single precision (eps 6e-8) cannot solve a system of condition 1e10: after STALLED_FRESH fresh tangents
    that gain too little, the method factorises in double precision and converges to the exact solution."""
    step, cause, u, system = _solve_linear(1e10)
    assert cause is None and step.precision == "double"
    np.testing.assert_allclose(u, np.linalg.solve(system.K, system.f), rtol=1e-3)


def test_without_the_switch_single_precision_stalls(monkeypatch: pytest.MonkeyPatch) -> None:
    import pneumorph.fem.fast.newton as newton

    monkeypatch.setattr(newton, "STALLED_FRESH", 10**6)
    step, cause, _, _ = _solve_linear(1e10)
    assert step.precision == "single" and cause is not None


def test_a_well_conditioned_solve_stays_in_single_precision() -> None:
    step, cause, _, _ = _solve_linear(1e5)
    assert cause is None and step.precision == "single"
    assert _model().evaluate("0").metadata["precision"] == "single"


@pytest.mark.slow
def test_first_step_failure_says_why() -> None:
    """A tolerance below the residual's round-off cannot be met even in double precision: the failure names
    the first load step, the residual reached, the tolerance and the precision."""
    with pytest.raises(SimulationFailed) as info:
        _model(tolerance=1e-16).evaluate("0")
    text = str(info.value)
    assert info.value.reached == 0.0
    assert "first load step" in text
    assert "not the tolerance 1e-16" in text
    assert "double-precision factorisation" in text


@pytest.mark.slow
def test_refined_three_unit_design_converges() -> None:
    """A 3-unit design on the 1.0 mm mesh (4.8 times the default cells) solves the whole ramp and curls
    more than on the default mesh (the coarse mesh is stiffer), by less than 5 %."""
    fine = Full3D(3, UnitSpec(element_size=1.0)).evaluate("001")
    coarse = Full3D(3).evaluate("001")
    assert fine.converged and fine.metadata["dofs"] > 3 * coarse.metadata["dofs"]
    assert 1.0 < fine.curl[-1] / coarse.curl[-1] < 1.05


def test_precision_attribute_follows_the_solver() -> None:
    class Pattern:
        indptr = np.array([0, 1])
        indices = np.array([0])
        symmetric = True
        ordering = 0
        single_precision = True
        tangent_dtype = np.float64

    system = Pattern()
    step = FastSubstep(system, reuse=0.7)
    assert step.precision == "single" and system.tangent_dtype == np.float32
    step.to_double()
    assert step.precision == "double" and system.tangent_dtype == np.float64


def test_large_systems_start_in_double_precision(monkeypatch: pytest.MonkeyPatch) -> None:
    import pneumorph.fem.fast.newton as newton

    monkeypatch.setattr(newton, "SINGLE_PRECISION_MAX_DOFS", 1000)
    assert _model(increments=1).evaluate("0").metadata["precision"] == "double"


class ShortSteps:
    """An obstacle's step limit that lets every Newton step go only ``fraction`` of its way, touched by no node
    (the interface :func:`~pneumorph.fem.fast.contact.contact_fraction` and the contact checks read)."""

    friction = 0.0

    def __init__(self, fraction: float) -> None:
        self.fraction = fraction

    def step_fraction(self, x: np.ndarray, dx: np.ndarray, motion: float = 0.0) -> float:
        return self.fraction

    def states(self, x: np.ndarray) -> np.ndarray:
        return np.zeros(len(x), dtype=np.int8)


def test_steps_cut_short_say_nothing_of_the_precision() -> None:
    """Fresh steps cut to a quarter by an obstacle's step limit lower the residual of a linear system by 0.75,
    less than the reuse factor 0.7 asks: cut short, they do not judge the single-precision factorisation, which
    stays (a well-conditioned system, condition 1e5) and converges to the exact solution."""
    system = LinearisedScan(1e5)
    system.points = np.zeros((len(system.f), 1))
    system.contacts = (ShortSteps(0.25),)
    step = FastSubstep(system, reuse=Full3D.tangent_reuse, depth=Full3D.anderson_depth)
    fields = [SimpleNamespace(values=np.zeros(len(system.f)))]
    iterations, cause = step(fields, SimpleNamespace(max_iterations=80, tolerance=1e-5))
    assert cause is None and step.precision == "single"
    assert step.factorisations == iterations  # every short step gained less than the reuse factor: refreshed
    np.testing.assert_allclose(fields[0].values, np.linalg.solve(system.K, system.f), rtol=1e-3)


@pytest.mark.parametrize(("reach", "taken"), [(8.0, 0.5), (14.0, 0.125)])
def test_a_landing_step_is_kept_up_to_the_landing_growth(reach: float, taken: float) -> None:
    """A fresh step cut to half by an obstacle's step limit (a landing: the nodes it would carry deep into an obstacle
    end at the reach) from ``u = 0`` along ``reach K^-1 f`` lands at ``u = reach / 2 K^-1 f``, whose residual is
    ``reach / 2 - 1`` times the start's: 3 times (within :data:`LANDING`, 3) is kept whole; 6 times is halved, to 2.5
    times (above :data:`GROWTH`, 2), then to 0.75 times, and a quarter of the cut step is taken."""
    from pneumorph.fem.fast.newton import GROWTH, LANDING, _FixedLoad
    from pneumorph.fem.stepping import relative_residual

    assert GROWTH < 2.5 and 3.0 <= LANDING < 6.0  # (the cases above straddle both)
    system = LinearisedScan(10.0)
    system.points = np.zeros((len(system.f), 1))
    system.contacts = (ShortSteps(0.5),)
    substep = FastSubstep(system, reuse=Full3D.tangent_reuse)
    u = np.zeros(len(system.f))
    previous = relative_residual(system.residual(u)[0], system.dof1, system.dof0)
    step = reach * np.linalg.solve(system.K, system.f)
    out = substep._trial(u, np.zeros(0), step, True, previous, _FixedLoad())
    np.testing.assert_allclose(out[0], taken * step, rtol=1e-12)
    assert out[6]  # cut short

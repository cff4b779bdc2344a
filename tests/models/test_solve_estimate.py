"""The estimate of one FE solve's time against the solve times measured (BENCHMARKS.md, "The 2D estimate's growth
with the units"): a 2D solve grows faster than its units, as the measured CPU times do; a run's estimate of its
solves is their CPU time, slowed only by the processes of other runs that share the cores (the load given, or the
load average less the run's own processes).

The measurements are numbers written here from that table (not timed by the test): one design pattern cut to
5-30 units, the median CPU time of 3 solves each.
"""

from __future__ import annotations

import pytest

from pneumorph.models.chain.plan import solve_seconds

#: units -> median CPU seconds of a 2D solve of ``111000000111111...`` cut to the units (BENCHMARKS.md)
MEASURED_2D = {5: 0.201, 10: 0.395, 15: 0.903, 20: 1.406, 30: 1.949}
#: the fit's largest deviation from a median, as BENCHMARKS.md states it (-18 to +15 %)
FIT_ERROR = 0.18


@pytest.mark.parametrize("units", sorted(MEASURED_2D))
def test_the_2d_estimate_is_within_the_fit_error_of_each_measured_median(units: int) -> None:
    estimate = solve_seconds("2d", units)
    assert estimate is not None
    assert MEASURED_2D[units] == pytest.approx(estimate, rel=FIT_ERROR)  # median / fit - 1, as the table says it


def test_the_2d_estimate_grows_faster_than_the_units_as_the_measurements_do() -> None:
    """30 units measured 9.7 times 5 units' time (6 for linear growth); the estimate's ratio within the fit's
    error of both ends."""
    measured = MEASURED_2D[30] / MEASURED_2D[5]
    estimated = solve_seconds("2d", 30) / solve_seconds("2d", 5)  # type: ignore[operator]
    assert measured == pytest.approx(9.70, abs=0.01)
    assert estimated == pytest.approx(measured, rel=2 * FIT_ERROR) and estimated > 6 * (1 + FIT_ERROR)


def test_the_3d_estimate_stays_linear_in_the_units() -> None:
    """No 3D growth was measured here: its 15-unit figure scaled by the units, as before."""
    assert solve_seconds("3d", 15) == 15.0 and solve_seconds("3d", 30) == 30.0 and solve_seconds("3d", 5) == 5.0


def test_the_verification_estimate_is_the_cpu_time_scaled_only_by_other_runs() -> None:
    """A 17-unit 3D solve is 17 s of CPU (15 s for 15 units, linear); on 2 cores two verifications at once run at
    that speed on a machine without other work, at half of it beside two busy processes of another run, and one
    at a time beside one such process still has a core of its own."""
    from pneumorph.models.chain.plan import solve_estimate
    from pneumorph.models.fe import Full3D

    model = Full3D(17)
    assert solve_estimate(model, 2, workers=2, load=0.0, cores=2) == " (3d, about 17 s each)"
    assert solve_estimate(model, 2, workers=2, load=2.0, cores=2) == " (3d, about 34 s each)"
    assert solve_estimate(model, 2, workers=1, load=1.0, cores=2) == " (3d, about 17 s each)"
    assert solve_estimate(model, 1, load=1.0, cores=2) == " (3d, about 17 s)"


def test_the_runs_own_processes_do_not_slow_its_estimate(monkeypatch: pytest.MonkeyPatch) -> None:
    """The load average counts the run's own process (it has been scoring designs): that is no competitor. The
    machine's measured load of 1.0 on 2 cores leaves the two verifications at their CPU time (not 1.5 times it);
    a load of 3.0 is two processes of other runs besides this one."""
    from pneumorph.io.progress import other_load
    from pneumorph.models.chain.plan import solve_estimate
    from pneumorph.models.fe import Full3D

    assert (other_load(1.0, own=1), other_load(3.0, own=1), other_load(0.5, own=2)) == (0.0, 2.0, 0.0)
    monkeypatch.setattr("pneumorph.io.progress.os.getloadavg", lambda: (1.0, 1.0, 1.0))
    assert solve_estimate(Full3D(17), 2, workers=2, cores=2) == " (3d, about 17 s each)"
    monkeypatch.setattr("pneumorph.io.progress.os.getloadavg", lambda: (3.0, 3.0, 3.0))
    assert solve_estimate(Full3D(17), 2, workers=2, cores=2) == " (3d, about 34 s each)"

"""The 3D references of a calibration, solved through the evaluation cache.

The calibration's 3D model reports every calibration pressure from one ramp
(:func:`reference_model`); the held-out designs of the validation are solved to the
highest of them. Every 3D solve goes through a
:class:`~pneumorph.execution.CachedEvaluator` (:func:`cached_3d_solver`), so recalibrating
repeats no 3D solve, and :func:`solve_references` can fill the cache beforehand.

Examples
--------
>>> from pneumorph.execution import EvaluationCache
>>> with open_cache(EvaluationCache(":memory:")) as store:
...     solve_3d = cached_3d_solver(store)
>>> callable(solve_3d)
True
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TypeAlias

import numpy as np

from pneumorph.calibration.designs import calibration_designs, holdout_designs
from pneumorph.errors import SimulationFailed
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator, default_cache_path
from pneumorph.execution.evaluators import Evaluator
from pneumorph.fem import StepSettings
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, RampSpec
from pneumorph.models.response import Response

#: ``solve_3d(model, design) -> Response``: how a calibration gets its 3D responses.
Solve3D: TypeAlias = Callable[[Full3D, str], Response]


def reference_model(unit: UnitSpec, n_units: int, pressures_kpa: Sequence[float],
                    steps: StepSettings | None = None) -> Full3D:
    """The 3D model of a calibration: its ramp reports every calibration pressure.

    Examples
    --------
    >>> m = reference_model(UnitSpec(), 15, (5, 10, 15, 20, 25, 30, 35, 40, 45))
    >>> m.ramp.steps.increments, round(m.ramp.pressure * 1e3, 6)
    (9, 45.0)
    """
    levels = np.asarray(pressures_kpa, dtype=float) / 1e3
    p_max = float(levels.max())
    increments = round(p_max / np.gcd.reduce(np.round(levels * 1e4).astype(int)) * 1e4)
    steps = steps or StepSettings(increments=increments, substeps=2)
    if steps.increments != increments:
        steps = replace(steps, increments=increments)
    return Full3D(n_units, unit, RampSpec(pressure=p_max, steps=steps))


def cached_3d_solver(cache: EvaluationCache) -> Solve3D:
    """A ``solve_3d`` that answers from an evaluation cache and stores what it solves.

    A :class:`~pneumorph.execution.CachedEvaluator` over the serial evaluator; a failed
    3D solve raises :class:`~pneumorph.errors.SimulationFailed`.
    """
    cached = CachedEvaluator(SerialEvaluator(), cache)

    def solve_3d(model: Full3D, design: str) -> Response:
        (outcome,) = cached.evaluate_many(model, [design])
        if not outcome.ok or outcome.response is None:
            raise SimulationFailed(reached=0.0, cause=f"3D reference failed: {outcome.failure}", design=design)
        return outcome.response

    return solve_3d


@contextlib.contextmanager
def open_cache(cache: EvaluationCache | str | Path | None = None) -> Iterator[EvaluationCache]:
    """The evaluation cache of a calibration, closed at the end if opened here.

    Parameters
    ----------
    cache : EvaluationCache, str or Path, optional
        An open cache (left open), or the file of one (opened and closed); by default
        :func:`~pneumorph.execution.default_cache_path`.

    Raises
    ------
    CacheError
        If the file cannot serve as a cache.
    """
    if isinstance(cache, EvaluationCache):
        yield cache
        return
    store = EvaluationCache(default_cache_path() if cache is None else cache)
    try:
        yield store
    finally:
        store.close()


@dataclass(frozen=True)
class ReferenceSolve:
    """One 3D reference solved (or answered by the cache) by :func:`solve_references`.

    Attributes
    ----------
    index, total : int
        Its place among the references (1-based) and their number.
    kind : str
        ``"calibration"`` or ``"validation"`` (a held-out design).
    design : str
    seconds : float
        Wall time of the solve (near 0 for a cached one).
    curl : float or None
        The curl at the highest pressure, degrees (None if the solve failed).
    failure : str or None
        Why the solve failed.
    """

    index: int
    total: int
    kind: str
    design: str
    seconds: float
    curl: float | None = None
    failure: str | None = None


def reference_jobs(unit: UnitSpec, n_units: int, pressures_kpa: Sequence[float], runs: int = 3, seed: int = 0,
                   n_validate: int = 10) -> list[tuple[Full3D, str]]:
    """The ``(3D model, design)`` references a calibration and its validation ask for, in order.

    The calibration designs (:func:`~pneumorph.calibration.calibration_designs`) on the
    reference ramp, then ``n_validate`` held-out designs ramped to the highest pressure.

    Examples
    --------
    >>> jobs = reference_jobs(UnitSpec(), 5, (10, 20), runs=2, n_validate=1)
    >>> len(jobs), [m.ramp.steps.increments for m, _ in jobs][:2]
    (3, [2, 2])
    """
    jobs = [(reference_model(unit, n_units, pressures_kpa), d) for d in calibration_designs(n_units, runs, seed)]
    holdout = Full3D(n_units, unit, RampSpec(pressure=max(pressures_kpa) / 1e3))
    held = holdout_designs(n_units, n_validate, seed, [d for _, d in jobs])
    return jobs + [(holdout, d) for d in held]


def solve_references(
    unit: UnitSpec,
    n_units: int,
    pressures_kpa: Sequence[float],
    runs: int = 3,
    seed: int = 0,
    n_validate: int = 10,
    cache: EvaluationCache | str | Path | None = None,
    on_reference: Callable[[ReferenceSolve], None] | None = None,
    evaluator: Evaluator | None = None,
) -> list[ReferenceSolve]:
    """Solve the 3D references of a calibration and its validation into the cache.

    The references of :func:`reference_jobs`, exactly as
    :func:`~pneumorph.calibration.run_calibration` with the same settings asks for them.
    A reference that fails is reported and the others go on.

    Parameters
    ----------
    unit, n_units, pressures_kpa, runs, seed, n_validate
        As for :func:`~pneumorph.calibration.run_calibration`.
    cache : EvaluationCache, str or Path, optional
        Where the responses go (:func:`open_cache`).
    on_reference : callable, optional
        Progress: called with each :class:`ReferenceSolve` as it ends (in the order they end).
    evaluator : Evaluator, optional
        Solves them (:mod:`pneumorph.execution`: a process pool or a Dask cluster solve
        several at once); by default one after another in this process.

    Returns
    -------
    list of ReferenceSolve
        In the order of :func:`reference_jobs`.
    """
    jobs = reference_jobs(unit, n_units, pressures_kpa, runs, seed, n_validate)
    done: dict[int, ReferenceSolve] = {}
    with open_cache(cache) as store:
        cached = CachedEvaluator(evaluator or SerialEvaluator(), store)
        for j, outcome in cached.iter_cases(jobs):
            i = j + 1
            kind = "calibration" if i <= runs else "validation"
            ok = outcome.ok and outcome.response is not None
            curl = float(outcome.response.curl[-1]) if ok and outcome.response is not None else None
            failure = None if ok else f"3D reference failed: {outcome.failure}"
            seconds = 0.0 if outcome.cached else outcome.wall_time
            report = ReferenceSolve(i, len(jobs), kind, jobs[j][1], seconds, curl, failure)
            done[j] = report
            if on_reference is not None:
                on_reference(report)
    return [done[j] for j in sorted(done)]

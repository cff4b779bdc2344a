"""Evaluators: one interface, three ways to solve a batch of designs, and the choice by name.

- :class:`SerialEvaluator` - one after the other in this process.
- :class:`ProcessPoolEvaluator` - a pool of local processes (all cores by default); each
  worker receives the model once and keeps it; BLAS/OpenMP threads are set to 1 in the
  workers so that processes, not threads, share the cores.
- :class:`DaskEvaluator` - a Dask ``distributed`` cluster: a scheduler address (many
  machines) or a ``LocalCluster`` on this machine; the model is sent to every worker once.

Every evaluator has ``iter_evaluate(model, designs)``, yielding ``(index, Outcome)`` as
solves finish (so a cache can store each at once), and ``evaluate_many(model, designs)``,
the outcomes in the order of the designs. ``iter_cases(cases)`` does the same for
``(model, design)`` pairs of different models (the variants of a sensitivity study); each
case carries its model to the worker. A :class:`~pneumorph.errors.SimulationFailed`
becomes a failed :class:`~pneumorph.execution.outcome.Outcome`; any other exception from
the model stops the batch as :class:`~pneumorph.errors.EvaluationError`.

A worker process that dies while solving a design (a crash, the out-of-memory killer)
does not stop the run: the design gets a failed outcome whose ``failure`` starts with
``"worker died"`` and which is marked ``transient`` (not a property of the design; a cache
must not keep it), and the other designs are solved on.

The interface and the serial evaluator live in :mod:`pneumorph.execution.serial`, the pool in
:mod:`pneumorph.execution.pool`, the Dask evaluator in :mod:`pneumorph.execution.cluster`;
this module names them all and chooses one by name (:func:`make_evaluator`).
"""

from __future__ import annotations

import os
from typing import Any

from pneumorph.checks import EXECUTORS
from pneumorph.errors import SearchConfigError
from pneumorph.execution.cluster import (
    MMAP_THRESHOLD,
    TRIM_THRESHOLD,
    DaskEvaluator,
    SolverSettings,
    solver_plugin,
    tune_allocator,
)
from pneumorph.execution.pool import ProcessPoolEvaluator, prepare_worker
from pneumorph.execution.serial import THREAD_VARIABLES, Evaluator, SerialEvaluator

#: Most worker processes per core of this machine (a pool or a local Dask cluster): each solves one design at a
#: time on one core, so more share the cores and multiply the memory.
MAX_WORKERS_PER_CORE = 2


def check_execution(kind: str, workers: int | None = None, scheduler: str | None = None,
                    names: tuple[str, str, str] = ("--executor", "--workers", "--scheduler")) -> None:
    """Refuse execution settings that would be ignored, before anything is solved.

    ``workers`` counts the processes of the pool or the workers of a local Dask cluster;
    ``scheduler`` is the address of a Dask cluster (whose workers are started there, so
    ``workers`` does not apply). ``names`` are the settings' names in the message.

    Raises
    ------
    SearchConfigError
        An unknown executor; a scheduler without ``dask``; workers with ``serial`` or with
        a scheduler.

    Examples
    --------
    >>> check_execution("dask", scheduler="tcp://10.0.0.5:8786")
    >>> check_execution("processes", scheduler="tcp://10.0.0.5:8786")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: --scheduler only applies to --executor dask, not to processes
    >>> check_execution("processes", workers=100_000)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: --workers 100000: more than 2 worker processes per core of this machine ...
    >>> check_execution("serial", workers=2)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: --workers does not apply to --executor serial (one design at a time in
    this process); leave it out or use --executor processes
    """
    executor, n, address = names
    if kind not in EXECUTORS:
        raise SearchConfigError(f"unknown executor {kind!r}; choose one of {', '.join(EXECUTORS)}")
    if scheduler is not None and kind != "dask":
        raise SearchConfigError(f"{address} only applies to {executor} dask, not to {kind}")
    if workers is not None and kind == "serial":
        raise SearchConfigError(f"{n} does not apply to {executor} serial (one design at a time in this process); "
                                f"leave it out or use {executor} processes")
    if workers is not None and scheduler is not None:
        raise SearchConfigError(f"{n} does not apply with {address}: the cluster's workers are started on their "
                                f"machines (dask worker ADDR --nworkers 1 --nthreads 1); leave {n} out")
    cores = os.cpu_count() or 1
    if workers is not None and workers > MAX_WORKERS_PER_CORE * cores:
        raise SearchConfigError(f"{n} {workers}: more than {MAX_WORKERS_PER_CORE} worker processes per core of this "
                                f"machine ({cores} cores: at most {MAX_WORKERS_PER_CORE * cores}; "
                                "MAX_WORKERS_PER_CORE); each solves one design on one core, so more would only "
                                "share the cores and multiply the memory")


def make_evaluator(
    kind: str = "serial", workers: int | None = None, scheduler: str | None = None, timeout: float = 5.0,
    on_message: Any = None,
) -> SerialEvaluator | ProcessPoolEvaluator | DaskEvaluator:
    """An evaluator by name: ``serial``, ``processes`` or ``dask`` (settings checked by :func:`check_execution`).

    ``on_message`` receives the evaluators' lines: the Dask cluster's (a lost worker), a pool's or a local
    cluster's that starts fewer processes than ``workers`` because the batch has fewer designs.

    Examples
    --------
    >>> type(make_evaluator("serial")).__name__
    'SerialEvaluator'
    >>> make_evaluator("gpu")
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: unknown executor 'gpu'; choose one of serial, processes, dask
    """
    check_execution(kind, workers, scheduler, ("executor", "workers", "scheduler"))
    if kind == "serial":
        return SerialEvaluator()
    if kind == "processes":
        return ProcessPoolEvaluator(workers, on_message=on_message)
    return DaskEvaluator(scheduler, workers=workers, timeout=timeout, on_message=on_message)


__all__ = ["MMAP_THRESHOLD", "THREAD_VARIABLES", "TRIM_THRESHOLD", "DaskEvaluator", "Evaluator",
           "ProcessPoolEvaluator", "SerialEvaluator", "SolverSettings", "check_execution", "make_evaluator",
           "prepare_worker", "solver_plugin", "tune_allocator"]

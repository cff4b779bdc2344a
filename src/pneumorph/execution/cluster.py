"""The Dask evaluator: designs solved on a ``distributed`` cluster (a scheduler address or a
``LocalCluster``), its workers set up by a plugin, a lost worker's designs retried and a lost
scheduler turned into :class:`~pneumorph.errors.ClusterLostError` (``docs/cluster.md``;
see :mod:`pneumorph.execution.evaluators`).
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterable, Iterator
from typing import Any

from pneumorph.errors import (
    ClusterLostError,
    EvaluationError,
    SchedulerUnreachableError,
    SearchConfigError,
    WorkerVersionError,
)
from pneumorph.execution.outcome import Outcome, solve
from pneumorph.execution.serial import THREAD_VARIABLES, EvaluatorBase
from pneumorph.models.response import ActuatorModel

#: glibc's mallopt parameters (malloc.h) and the values a Dask worker is given (see :class:`SolverSettings`)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
MMAP_THRESHOLD = 32 * 2**20  # glibc's largest dynamic mmap threshold on 64-bit systems
TRIM_THRESHOLD = 2 * MMAP_THRESHOLD  # what glibc's dynamic rule sets beside it

#: the models a Dask worker keeps, by fingerprint (the last few: their meshes and set-up are reused)
_DASK_MODELS: dict[str, ActuatorModel] = {}
_DASK_MODELS_KEPT = 4


def tune_allocator() -> bool:
    """Give this process glibc's large-allocation behaviour back; True if it could be set.

    A Dask nanny starts its worker with ``MALLOC_TRIM_THRESHOLD_=65536``. Setting that
    threshold switches glibc's dynamic mmap threshold off, so every large array of a
    finite-element solve is mapped and unmapped afresh (page faults, system time): 3D
    solves ran about twice as slowly. This sets what the dynamic rule would reach, an
    mmap threshold of 32 MiB and a trim threshold of 64 MiB, through ``mallopt``. Does
    nothing (False) where the C library is not glibc.

    Examples
    --------
    >>> tune_allocator() in (True, False)
    True
    """
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc (macOS, Windows, musl without mallopt)
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and bool(mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))


#: seconds a local Dask cluster's workers may take to start (each imports pneumorph: about 2 s)
WORKER_START_SECONDS = 120.0


def _worker_settings() -> dict[str, Any]:
    """Set up a Dask worker process for solving (:func:`tune_allocator`, one BLAS/OpenMP thread); what it set."""
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    return {"allocator": tune_allocator(), "threads": {name: os.environ[name] for name in THREAD_VARIABLES}}


class SolverSettings:
    """What a Dask worker plugin does to every worker, present or joining later, so it solves at full speed.

    :class:`DaskEvaluator` registers it (as a ``distributed`` ``WorkerPlugin``, see
    :func:`solver_plugin`) when it connects: it runs :func:`tune_allocator` and sets the
    BLAS/OpenMP thread counts to one in the worker process, so that a worker started the
    standard way (``dask worker ADDR --nworkers 1 --nthreads 1``, with its nanny) solves as
    fast as a process of the pool. A worker the nanny restarts gets it again.

    Examples
    --------
    >>> SolverSettings.name
    'pneumorph-solver-settings'
    """

    name = "pneumorph-solver-settings"
    idempotent = True

    def setup(self, worker: Any = None) -> None:
        _worker_settings()


def solver_plugin() -> Any:
    """:class:`SolverSettings` as a ``distributed`` worker plugin (distributed is imported here, not before)."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class SolverSettingsPlugin(SolverSettings, WorkerPlugin):
        pass

    return SolverSettingsPlugin()


def _solve_on_dask_worker(model: ActuatorModel, design: str) -> Outcome:
    for name in THREAD_VARIABLES:
        os.environ.setdefault(name, "1")
    fp = model.fingerprint()
    kept = _DASK_MODELS.get(fp)
    if kept is None:  # the first design of this model on this worker: keep its instance
        while len(_DASK_MODELS) >= _DASK_MODELS_KEPT:
            _DASK_MODELS.pop(next(iter(_DASK_MODELS)))
        kept = _DASK_MODELS[fp] = model
    return solve(kept, design)


def _quiet_distributed() -> dict[str, int]:
    """Keep distributed's client-side logging to CRITICAL (a lost connection is reported by the run itself)."""
    import logging

    saved = {}
    for name in ("distributed", "distributed.client", "distributed.core", "distributed.batched", "distributed.comm"):
        logger = logging.getLogger(name)
        saved[name] = logger.level
        logger.setLevel(logging.CRITICAL)
    return saved


class DaskEvaluator(EvaluatorBase):
    """Solve designs on a Dask ``distributed`` cluster.

    Parameters
    ----------
    address : str, optional
        A scheduler address (``"tcp://host:8786"``); None starts a ``LocalCluster``.
    workers : int, optional
        LocalCluster only: number of workers (all cores by default).
    processes : bool
        LocalCluster only: workers in processes (True) or threads of this process.
    timeout : float
        Seconds to wait for the scheduler before giving up (and to reconnect to it once lost).
    on_message : callable, optional
        Called with a line of text when something happens on the cluster (a worker lost and
        the designs it was solving retried, no worker left).

    On connect and at the start of every batch, every worker must run the same pneumorph
    version as this process (else :class:`~pneumorph.errors.WorkerVersionError` naming
    both), and each worker, present or joining later, gets :class:`SolverSettings`
    (allocator and thread counts for solving).

    Each task carries its model (a few kB); a worker keeps the instance of each model it
    has seen (by fingerprint), so no data lives on the cluster only: losing any worker
    loses no model. A worker that dies while solving has its designs retried on the others
    by Dask (``retried`` counts them; a design whose workers keep dying, 3 by default,
    becomes a failed transient outcome, as in the process pool). Results are fetched as
    each finishes and released on the cluster at once. A lost scheduler, or no worker at
    all for ``no_worker_timeout`` seconds, ends the batch with
    :class:`~pneumorph.errors.ClusterLostError`.

    Raises
    ------
    SearchConfigError
        If ``distributed`` is not installed.
    SchedulerUnreachableError
        If the scheduler does not answer within ``timeout`` seconds.
    WorkerVersionError
        If a worker runs another pneumorph version, or none.

    Examples
    --------
    >>> with DaskEvaluator(workers=1, processes=False) as ev:  # doctest: +SKIP
    ...     outcomes = ev.evaluate_many(model, ["0101", "1100"])
    """

    #: seconds between looks at the cluster (workers lost, designs in flight) while waiting for results
    poll = 1.0
    #: seconds a batch waits with no worker at all before it ends with ClusterLostError
    no_worker_timeout = 300.0

    def __init__(
        self, address: str | None = None, workers: int | None = None, processes: bool = True, timeout: float = 5.0,
        on_message: Any = None,
    ) -> None:
        try:
            from distributed import Client, LocalCluster
        except ImportError:  # pragma: no cover - depends on the installation
            raise SearchConfigError(
                "the dask executor needs the 'distributed' package: pip install 'pneumorph[dask]'"
            ) from None
        self.address = address
        self.on_message = on_message
        self.retried = 0
        self.lost_workers = 0
        self._cluster = None
        self._logging = _quiet_distributed()
        self.requested = workers
        self._local = 0  # a local cluster's most workers (started as batches need them)
        if address is None:
            self._local = workers or os.cpu_count() or 1
            self._cluster = LocalCluster(
                n_workers=0, threads_per_worker=1, processes=processes, dashboard_address=None
            )
            self.client = Client(self._cluster, timeout=timeout)
        else:
            start = time.perf_counter()
            try:
                self.client = Client(address, timeout=timeout)
            except (OSError, TimeoutError) as exc:
                waited = time.perf_counter() - start
                self._restore_logging()
                raise SchedulerUnreachableError(
                    f"no Dask scheduler answered at {address!r} within {waited:.1f} s ({exc}); "
                    "check the address and that 'dask scheduler' runs there, or use --executor processes"
                ) from None
        try:
            self._check_versions()
            self.client.register_plugin(solver_plugin(), name=SolverSettings.name)
        except BaseException:
            self.close()
            raise

    @property
    def where(self) -> str:
        """The scheduler's address (or ``"a local cluster"``)."""
        return self.address or "a local cluster"

    @property
    def workers(self) -> int:
        """Designs the cluster solves at once now: the threads of its workers (at least 1); a local cluster's
        most workers (it starts them as batches need them)."""
        if self._local:
            return self._local
        try:
            info = self.client.scheduler_info()
        except Exception:  # a lost scheduler: the run itself reports it
            return 1
        return max(1, sum(int(w.get("nthreads", 1)) for w in info.get("workers", {}).values()))

    def _say(self, text: str) -> None:
        if self.on_message is not None:
            self.on_message(text)

    def _check_versions(self) -> None:
        """Refuse workers that run another pneumorph than this process (or none)."""
        import importlib.metadata

        from pneumorph import __version__

        found = self.client.run(importlib.metadata.version, "pneumorph", on_error="return")
        # a string: the version; PackageNotFoundError: none; another error (a worker going away) is not the version's
        wrong = {addr: v for addr, v in found.items()
                 if (isinstance(v, str) and v != __version__) or isinstance(v, importlib.metadata.PackageNotFoundError)}
        if wrong:
            addr, v = sorted(wrong.items())[0]
            theirs = f"pneumorph {v}" if isinstance(v, str) else f"no pneumorph ({type(v).__name__})"
            more = f" (and {len(wrong) - 1} more)" if len(wrong) > 1 else ""
            raise WorkerVersionError(
                f"the Dask worker {addr}{more} at {self.where} runs {theirs}, this client pneumorph {__version__}; "
                f"install pneumorph {__version__} (pip install 'pneumorph[dask]=={__version__}') on every worker "
                "machine and restart its workers")

    def iter_evaluate(self, model: ActuatorModel, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]:
        designs = list(designs)
        yield from self._collect([(model, d) for d in designs])

    def iter_cases(self, cases: Iterable[tuple[ActuatorModel, str]]) -> Iterator[tuple[int, Outcome]]:
        """Solve ``(model, design)`` pairs of different models, each sent with its case."""
        yield from self._collect(list(cases))

    def _grow(self, tasks: int) -> None:
        """Start a local cluster's workers up to what ``tasks`` designs can use (at most ``workers``), saying so once
        when that is fewer than asked for."""
        if self._cluster is None:
            return
        size = max(1, min(self._local, tasks))
        have = len(self._cluster.workers)
        if have >= size:
            return
        if self.requested is not None and size < self.requested and not have:
            self._say(f"starting {size} Dask worker{'s' if size > 1 else ''}, not {self.requested}: the batch has "
                      f"{tasks} design{'s' if tasks > 1 else ''} to solve")
        self._cluster.scale(size)
        try:
            self.client.wait_for_workers(size, timeout=WORKER_START_SECONDS)
        except TimeoutError:
            raise EvaluationError(f"the local Dask cluster's {size} worker(s) did not start within "
                                  f"{WORKER_START_SECONDS:g} s; check the memory and the processes' limits, or use "
                                  "--executor processes") from None

    def _lost(self, why: str) -> ClusterLostError:
        return ClusterLostError(f"lost the Dask scheduler at {self.where} ({why}); every design finished before "
                                "is in the evaluation cache")

    def _collect(self, cases: list[tuple[ActuatorModel, str]]) -> Iterator[tuple[int, Outcome]]:
        """Submit ``(model, design)`` pairs and yield ``(index, Outcome)`` as they finish."""
        from concurrent.futures import CancelledError

        from distributed import KilledWorker
        from distributed import wait as dask_wait

        if not cases:
            return
        self._grow(len(cases))
        try:
            self._check_versions()  # workers that joined since the last batch, too
            futures = [self.client.submit(_solve_on_dask_worker, m, d, pure=False) for m, d in cases]
        except (OSError, CancelledError):
            raise self._lost("its connection closed") from None
        index = {f.key: i for i, f in enumerate(futures)}
        pending = set(futures)
        seen: dict[str, set[Any]] = self._processing(index) or {}
        alone: float | None = None  # since when no worker is left (said once)
        try:
            while pending:
                try:
                    done, _ = dask_wait(list(pending), timeout=self.poll, return_when="FIRST_COMPLETED")
                except TimeoutError:
                    done = set()
                except (OSError, CancelledError):
                    raise self._lost("its connection closed") from None
                for f in sorted(done, key=lambda f: index[f.key]):
                    pending.discard(f)
                    i = index[f.key]
                    try:
                        outcome = f.result()
                    except KilledWorker:  # every worker that tried it died (distributed's allowed-failures)
                        outcome = Outcome(cases[i][1], None, transient=True,
                                          failure="worker died: every Dask worker that solved it died (KilledWorker)")
                    except CancelledError:
                        raise self._lost("its connection closed") from None
                    f.release()  # nothing kept on the cluster: a worker lost later costs no solve again
                    yield i, outcome
                now = self._processing(index)
                if now is None:
                    if self.client.status != "running":
                        raise self._lost(f"client {self.client.status}")
                    continue
                open_keys = {f.key for f in pending}
                for addr in sorted(set(seen) - set(now)):
                    again = seen[addr] & open_keys
                    self.lost_workers += 1
                    self.retried += len(again)
                    self._say(f"Dask worker {addr} lost; the {len(again)} design(s) it was solving or held queued "
                              f"are retried on the other workers ({self.retried} retried in this run)")
                if now or not pending:
                    alone = None
                elif alone is None:
                    alone = time.monotonic()
                    self._say(f"no Dask worker at {self.where}: waiting up to {self.no_worker_timeout:.0f} s for "
                              f"one to join (dask worker {self.where} --nworkers 1 --nthreads 1)")
                elif time.monotonic() - alone > self.no_worker_timeout:
                    raise ClusterLostError(f"no Dask worker at {self.where} for {self.no_worker_timeout:.0f} s; "
                                           "every design finished before is in the evaluation cache")
                seen = now
        finally:
            live = [f for f in pending if not f.done()]
            if live and self.client.status == "running":
                with contextlib.suppress(Exception):  # best effort: the scheduler may be gone
                    self.client.cancel(live)

    def _processing(self, index: dict[Any, int]) -> dict[str, set[Any]] | None:
        """The keys of this batch each worker is solving now (None if the scheduler does not answer)."""
        try:
            processing = self.client.processing()
        except Exception:  # any failure to ask means the scheduler is gone or going
            return None
        return {addr: {k for k in keys if k in index} for addr, keys in processing.items()}

    def _restore_logging(self) -> None:
        import logging

        for name, level in self._logging.items():
            logging.getLogger(name).setLevel(level)

    def close(self) -> None:
        """Close the client (and the LocalCluster this evaluator started)."""
        try:
            with contextlib.suppress(Exception):  # a lost scheduler: nothing to close there
                self.client.close(timeout=2)
            if self._cluster is not None:
                self._cluster.close()
                self._cluster = None
        finally:
            self._restore_logging()

"""Evaluators: one interface, three ways to solve a batch of designs.

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
"""

from __future__ import annotations

import atexit
import contextlib
import multiprocessing
import os
import signal
import threading
import time
import weakref
from collections import deque
from collections.abc import Generator, Iterable, Iterator
from concurrent.futures import (
    ALL_COMPLETED,
    FIRST_COMPLETED,
    Future,
    ProcessPoolExecutor,
    wait,
)
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Protocol, runtime_checkable

from pneumorph.errors import (
    ClusterLostError,
    EvaluationError,
    SchedulerUnreachableError,
    SearchConfigError,
    WorkerVersionError,
)
from pneumorph.execution.outcome import Outcome, solve
from pneumorph.models.response import ActuatorModel

THREAD_VARIABLES = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMEXPR_NUM_THREADS")


@runtime_checkable
class Evaluator(Protocol):
    """Solves designs of a model; see the module docstring."""

    def iter_evaluate(self, model: ActuatorModel, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]: ...

    def evaluate_many(self, model: ActuatorModel, designs: Iterable[str]) -> list[Outcome]: ...

    def iter_cases(self, cases: Iterable[tuple[ActuatorModel, str]]) -> Iterator[tuple[int, Outcome]]: ...

    def close(self) -> None: ...


class _Base:
    def evaluate_many(self, model: ActuatorModel, designs: Iterable[str]) -> list[Outcome]:
        """Outcomes of ``designs``, in their order."""
        designs = list(designs)
        out: list[Outcome | None] = [None] * len(designs)
        for i, outcome in self.iter_evaluate(model, designs):  # type: ignore[attr-defined]
            out[i] = outcome
        return out  # type: ignore[return-value]

    def close(self) -> None:
        """Release workers (nothing to do for the serial evaluator)."""

    def __enter__(self) -> Any:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class SerialEvaluator(_Base):
    """Solve the designs one after another in this process.

    Examples
    --------
    >>> SerialEvaluator().evaluate_many(object(), [])
    []
    """

    def iter_evaluate(self, model: ActuatorModel, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]:
        for i, design in enumerate(designs):
            yield i, solve(model, design)

    def iter_cases(self, cases: Iterable[tuple[ActuatorModel, str]]) -> Iterator[tuple[int, Outcome]]:
        for i, (model, design) in enumerate(cases):
            yield i, solve(model, design)


# -- process pool ------------------------------------------------------------------------
_WORKER_MODEL: Any = None


def prepare_worker() -> None:
    """Set up a worker process of a pool: one thread for the linear algebra, Ctrl-C left to the
    parent (it reaches the whole process group; the parent stops the workers, which print no
    tracebacks), and an exit of its own when the parent dies (:func:`_watch_parent`)."""
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except (ValueError, OSError):  # pragma: no cover - not the main thread of the worker
        pass
    _watch_parent(os.getppid())


def _init_worker(model: ActuatorModel | None) -> None:
    global _WORKER_MODEL
    prepare_worker()
    _WORKER_MODEL = model


def _watch_parent(parent: int, every: float = 0.5) -> None:
    """End this worker when its parent is gone (a SIGKILL of the run leaves no orphan solving on).

    A killed parent cannot stop its workers, so each worker checks every ``every`` s that
    its parent process is still the one that started it, and exits at once otherwise.
    """

    def watch() -> None:
        while True:
            time.sleep(every)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, name="pneumorph-parent-watch", daemon=True).start()


def _solve_in_worker(design: str) -> Outcome:
    return solve(_WORKER_MODEL, design)


def _solve_case_in_worker(case: tuple[ActuatorModel, str]) -> Outcome:
    return solve(*case)


#: the pool of :meth:`ProcessPoolEvaluator.iter_cases` holds no model (each case brings its own)
_CASES = "cases"


_LIVE_POOLS: weakref.WeakSet[ProcessPoolEvaluator] = weakref.WeakSet()


def _close_all_pools() -> None:
    """At interpreter exit: stop the workers of every pool still open (no process outlives the run)."""
    for evaluator in list(_LIVE_POOLS):
        with contextlib.suppress(Exception):  # best effort at exit
            evaluator.close(grace=0.2)


# before concurrent.futures' own exit hook (those run last-registered first), which would wait for every
# running solve to finish
_register_atexit = getattr(threading, "_register_atexit", atexit.register)
_register_atexit(_close_all_pools)


def _describe_exit(code: int | None) -> str:
    if code is None:
        return "ended abruptly"
    if code < 0:
        try:
            return f"was killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"was killed by signal {-code}"
    return f"exited with code {code}"


def _stop_pool(pool: ProcessPoolExecutor, grace: float) -> dict[int, int | None]:
    """Shut ``pool`` down: cancel what is queued, give the workers ``grace`` seconds to end, then
    terminate (and at last kill) those still running. Returns their exit codes by pid.

    The pool's own manager thread joins (reaps) the workers; this function only signals them
    and waits for that thread. Joining them here as well would race it for the same exit
    status, and the loser would report a reaped worker as still running.
    """
    processes = dict(getattr(pool, "_processes", None) or {})
    manager = getattr(pool, "_executor_manager_thread", None)
    pool.shutdown(wait=False, cancel_futures=True)
    if manager is not None:
        manager.join(grace)
        for stop in ("terminate", "kill"):  # busy workers: a signal only, no reaping
            if not manager.is_alive():
                break
            for p in processes.values():
                getattr(p, stop)()
            manager.join(2.0)
    pool.shutdown(wait=True)
    return {pid: p.exitcode for pid, p in processes.items()}


class ProcessPoolEvaluator(_Base):
    """Solve designs in a pool of local processes.

    Parameters
    ----------
    workers : int, optional
        Number of processes; all cores by default.

    The pool starts on first use (processes are spawned, so they import fresh with one
    BLAS/OpenMP thread each) and is kept while the model's fingerprint stays the same.
    At most ``workers`` designs are handed to the pool at a time, so the designs being
    solved are known at every moment.

    A worker process that dies (a crash of the solver, ``os._exit``, the out-of-memory
    killer, ``kill -9``) breaks the pool: it is restarted and the run goes on. The designs
    that were in flight are solved again one at a time; a design whose worker dies while
    it is the only one in flight gets a failed :class:`Outcome` with ``failure`` starting
    ``"worker died"`` and ``transient=True`` (not a property of the design: not to be
    cached). Designs not yet started are simply handed to the new pool.

    No worker outlives its evaluator: :meth:`close`, a ``KeyboardInterrupt`` (or its
    subclasses) while solving, and the end of the interpreter stop them, terminating
    those still busy. Workers ignore SIGINT (Ctrl-C reaches the whole process group; this
    process stops them).
    """

    def __init__(self, workers: int | None = None) -> None:
        if workers is not None and workers < 1:
            raise SearchConfigError(f"the number of worker processes must be at least 1, got {workers}")
        self.workers = workers or os.cpu_count() or 1
        self._pool: ProcessPoolExecutor | None = None
        self._fingerprint: str | None = None
        self.restarts = 0
        _LIVE_POOLS.add(self)

    def _ensure_pool(self, model: ActuatorModel | None) -> ProcessPoolExecutor:
        fp = _CASES if model is None else model.fingerprint()
        if self._pool is not None and fp == self._fingerprint:
            return self._pool
        self.close()
        saved = {name: os.environ.get(name) for name in THREAD_VARIABLES}
        os.environ.update({name: "1" for name in THREAD_VARIABLES})  # inherited by spawned workers
        try:
            self._pool = ProcessPoolExecutor(
                max_workers=self.workers,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_init_worker,
                initargs=(model,),
            )
            # start the workers now, while the environment says one thread
            for f in [self._pool.submit(os.getpid) for _ in range(self.workers)]:
                f.result()
        except BrokenProcessPool as exc:
            self.close(grace=0.0)
            raise EvaluationError(f"the worker processes died while starting (the model {type(model).__name__} "
                                  "could not be sent to them, or they could not import pneumorph); "
                                  "try --executor serial") from exc
        except BaseException:
            self.close(grace=0.0)
            raise
        finally:
            for name, value in saved.items():
                if value is None:
                    os.environ.pop(name, None)
                else:
                    os.environ[name] = value
        self._fingerprint = fp
        return self._pool

    def iter_evaluate(self, model: ActuatorModel, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]:
        designs = list(designs)
        yield from self._iterate(model, designs, [(_solve_in_worker, d) for d in designs])

    def iter_cases(self, cases: Iterable[tuple[ActuatorModel, str]]) -> Iterator[tuple[int, Outcome]]:
        """Solve ``(model, design)`` pairs of different models in one pool, yielding ``(index, Outcome)``."""
        cases = list(cases)
        yield from self._iterate(None, [d for _, d in cases], [(_solve_case_in_worker, c) for c in cases])

    def _iterate(self, model: ActuatorModel | None, designs: list[str],
                 tasks: list[tuple[Any, Any]]) -> Iterator[tuple[int, Outcome]]:
        """Run ``tasks`` (function, argument) of ``designs``; see :meth:`iter_evaluate`."""
        if not designs:
            return
        queue = deque(range(len(designs)))  # handed to the pool, ``workers`` at a time
        alone: deque[int] = deque()  # in flight when a worker died: solved one at a time
        idle_deaths = 0
        try:
            while queue or alone:
                source, window = (alone, 1) if alone else (queue, self.workers)
                broken, lost = yield from self._stream(model, tasks, source, window)
                if not broken:
                    continue
                codes = self._restart()
                if len(lost) == 1:
                    (i,) = lost
                    dead = [c for c in codes.values() if c not in (None, 0, -signal.SIGTERM)]
                    how = _describe_exit(dead[0]) if len(dead) == 1 else "ended abruptly"
                    yield i, Outcome(designs[i], None, failure=f"worker died: the process solving it {how}",
                                     transient=True)
                else:
                    alone.extend(sorted(lost))
                idle_deaths = 0 if lost else idle_deaths + 1
                if idle_deaths >= 3:
                    raise EvaluationError("the worker processes keep dying while idle (3 pools in a row); "
                                          "check the memory and the processes' limits, or use --executor serial")
        except KeyboardInterrupt:  # the solves in flight are abandoned: stop them now
            self.close(grace=0.0)
            raise

    def _stream(self, model: ActuatorModel | None, tasks: list[tuple[Any, Any]], source: deque[int],
                window: int) -> Generator[tuple[int, Outcome], None, tuple[bool, set[int]]]:
        """Run the tasks of ``source`` with at most ``window`` in flight, yielding them as they
        finish. Returns ``(broken, lost)``: whether a worker died, and the designs it took along
        (those in flight then; the others stay in ``source``)."""
        pool = self._ensure_pool(model)
        flight: dict[Future[Outcome], int] = {}
        lost: set[int] = set()
        broken = False
        try:
            while source or flight:
                while source and len(flight) < window and not broken:
                    i = source.popleft()
                    try:
                        fn, arg = tasks[i]
                        flight[pool.submit(fn, arg)] = i
                    except BrokenProcessPool:
                        source.appendleft(i)
                        broken = True
                if not flight:
                    break
                done, _ = wait(flight, return_when=ALL_COMPLETED if broken else FIRST_COMPLETED)
                for f in sorted(done, key=flight.__getitem__):
                    i = flight.pop(f)
                    try:
                        outcome = f.result()
                    except BrokenProcessPool:
                        broken = True
                        lost.add(i)
                        continue
                    yield i, outcome
                if broken and not flight:
                    break
            return broken, lost
        finally:
            for f in flight:
                f.cancel()

    def _restart(self) -> dict[int, int | None]:
        """Discard a broken pool (the next solve starts a new one); the exit codes of its workers."""
        pool, self._pool, self._fingerprint = self._pool, None, None
        self.restarts += 1
        return {} if pool is None else _stop_pool(pool, grace=0.0)

    def close(self, grace: float = 1.0) -> None:
        """Shut the pool down: cancel queued solves, let idle workers end, terminate busy ones
        after ``grace`` seconds."""
        pool, self._pool, self._fingerprint = self._pool, None, None
        if pool is not None:
            _stop_pool(pool, grace)


# -- dask --------------------------------------------------------------------------------
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


class DaskEvaluator(_Base):
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
        if address is None:
            n = workers or os.cpu_count() or 1
            self._cluster = LocalCluster(
                n_workers=n, threads_per_worker=1, processes=processes, dashboard_address=None
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
        """Designs the cluster solves at once now: the threads of its workers (at least 1)."""
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


#: The names :func:`make_evaluator` knows: in this process, a process pool, a Dask cluster.
EXECUTORS = ("serial", "processes", "dask")


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


def make_evaluator(
    kind: str = "serial", workers: int | None = None, scheduler: str | None = None, timeout: float = 5.0,
    on_message: Any = None,
) -> SerialEvaluator | ProcessPoolEvaluator | DaskEvaluator:
    """An evaluator by name: ``serial``, ``processes`` or ``dask`` (settings checked by :func:`check_execution`).

    ``on_message`` receives the Dask evaluator's lines about the cluster (a lost worker).

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
        return ProcessPoolEvaluator(workers)
    return DaskEvaluator(scheduler, workers=workers, timeout=timeout, on_message=on_message)

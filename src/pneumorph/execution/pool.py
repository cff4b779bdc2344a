"""The process-pool evaluator: a pool of local processes, each receiving the model once and
keeping it, one BLAS/OpenMP thread each; a worker that dies fails its design (``transient``)
and the others are solved on (see :mod:`pneumorph.execution.evaluators`).
"""

from __future__ import annotations

import atexit
import contextlib
import multiprocessing
import os
import signal
import sys
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
from typing import Any

from pneumorph.errors import (
    EvaluationError,
    SearchConfigError,
)
from pneumorph.execution.outcome import Outcome, solve
from pneumorph.execution.serial import THREAD_VARIABLES, EvaluatorBase
from pneumorph.models.response import ActuatorModel

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



def _start_advice() -> str:
    """What to do when the workers died while starting: the command line's option, or in a script of the API the
    ``__main__`` guard, without which each spawned worker runs the script's own run again and dies."""
    if "pneumorph.cli" in sys.modules:
        return "try --executor serial"
    return ('a script that solves in worker processes must start its run under `if __name__ == "__main__":` (each '
            'worker imports the script; documentation page api), or solve in this process with executor "serial"')

class ProcessPoolEvaluator(EvaluatorBase):
    """Solve designs in a pool of local processes.

    Parameters
    ----------
    workers : int, optional
        Most processes; all cores by default.
    on_message : callable, optional
        Receives one line when fewer processes start than ``workers`` asked for.

    The pool starts on first use (processes are spawned, so they import fresh with one
    BLAS/OpenMP thread each) with no more processes than the batch has designs (``started``), and is kept while
    the model's fingerprint stays the same (started again, larger, for a larger batch).
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

    def __init__(self, workers: int | None = None, on_message: Any = None) -> None:
        if workers is not None and workers < 1:
            raise SearchConfigError(f"the number of worker processes must be at least 1, got {workers}")
        self.workers = workers or os.cpu_count() or 1
        self.requested = workers
        self.on_message = on_message
        self.started = 0  # processes of the pool now (0: none started)
        self._said = False
        self._pool: ProcessPoolExecutor | None = None
        self._fingerprint: str | None = None
        self.restarts = 0
        _LIVE_POOLS.add(self)

    def _ensure_pool(self, model: ActuatorModel | None, tasks: int) -> ProcessPoolExecutor:
        """The pool for ``model``, of as many processes as ``tasks`` designs can use (at most ``workers``)."""
        fp = _CASES if model is None else model.fingerprint()
        size = max(1, min(self.workers, tasks))
        if self._pool is not None and fp == self._fingerprint and self.started >= size:
            return self._pool
        self.close()
        if self.requested is not None and size < self.requested and self.on_message is not None and not self._said:
            self._said = True  # once: a later, smaller pool says nothing new
            self.on_message(f"starting {size} worker process{'es' if size > 1 else ''}, not {self.requested}: the "
                            f"batch has {tasks} design{'s' if tasks > 1 else ''} to solve")
        saved = {name: os.environ.get(name) for name in THREAD_VARIABLES}
        os.environ.update({name: "1" for name in THREAD_VARIABLES})  # inherited by spawned workers
        try:
            self._pool = ProcessPoolExecutor(
                max_workers=size,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_init_worker,
                initargs=(model,),
            )
            # start the workers now, while the environment says one thread
            for f in [self._pool.submit(os.getpid) for _ in range(size)]:
                f.result()
            self.started = size
        except BrokenProcessPool as exc:
            self.close(grace=0.0)
            raise EvaluationError(f"the worker processes died while starting (the model {type(model).__name__} "
                                  "could not be sent to them, or they could not import pneumorph); "
                                  f"{_start_advice()}") from exc
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
        pool = self._ensure_pool(model, len(source))
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
        pool, self._pool, self._fingerprint, self.started = self._pool, None, None, 0
        self.restarts += 1
        return {} if pool is None else _stop_pool(pool, grace=0.0)

    def close(self, grace: float = 1.0) -> None:
        """Shut the pool down: cancel queued solves, let idle workers end, terminate busy ones
        after ``grace`` seconds."""
        pool, self._pool, self._fingerprint, self.started = self._pool, None, None, 0
        if pool is not None:
            _stop_pool(pool, grace)

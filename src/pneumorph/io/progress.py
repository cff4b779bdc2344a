"""Lines about long work: what it plans, how far it is, and that it is still going.

Every command that can run for more than a few seconds says, on standard error and one line
at a time (a terminal and a log file read alike; no carriage returns):

- its plan first: what, how many items (FE solves), an estimate and where the results go;
- counted progress, at most every :data:`THROTTLE` seconds and always at the last item:
  ``done/total``, the time so far, the measured time per item and the time left at that
  measured rate (not at the nominal one the plan estimated with);
- a heartbeat: after :data:`HEARTBEAT` seconds without a line (one FE solve of a minute, a
  table build, a figure) a line that says what is still running and for how long.

The layers below the command line only call back (a ``say(text)`` or a counter); a command
renders them through one :class:`Progress`, which is such a ``say`` callable too.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import threading
import time
from collections.abc import Callable
from types import TracebackType

#: seconds without a line after which the heartbeat says what is still running (the contract: no
#: silence longer than 10 s; the margin covers a busy interpreter)
HEARTBEAT = 7.0
#: fewest seconds between two counted lines (the last item is always said)
THROTTLE = 2.0


def duration_text(seconds: float) -> str:
    """A duration for people: ``45 s``, ``3.5 min``, ``1.2 h``.

    >>> duration_text(0.37), duration_text(44.6), duration_text(210), duration_text(9000)
    ('0.4 s', '45 s', '3.5 min', '2.5 h')
    """
    if seconds < 9.95:
        return f"{seconds:.1f} s"
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.2g} min"
    return f"{seconds / 3600:.2g} h"


def own_processes() -> int:
    """The processes of this run that the machine's load average counts while they compute: this one and its
    live child processes (a process pool's workers).

    >>> own_processes() >= 1
    True
    """
    return 1 + len(multiprocessing.active_children())


def other_load(load: float | None = None, own: int | None = None) -> float:
    """The processes of other runs that compete for the cores now: the one-minute load average ``load`` (default:
    this machine's) less this run's own processes in it (``own``, default :func:`own_processes`), never below 0.

    A run's own work is in the load average (its scoring, its workers' last solves): counted as a competitor it
    would slow the run's estimate of itself (two busy processes of one run on 2 cores estimated each solve 1.5
    times its time alone).

    >>> other_load(1.0, own=1), other_load(3.0, own=1), other_load(0.2, own=3)
    (0.0, 2.0, 0.0)
    """
    if load is None:
        try:
            load = os.getloadavg()[0]
        except (AttributeError, OSError):  # no load average on this system
            load = 0.0
    return max(0.0, float(load) - (own_processes() if own is None else int(own)))


def load_factor(workers: int = 1, load: float | None = None, cores: int | None = None) -> float:
    """How much slower than on a quiet machine ``workers`` processes of a run compute here now: they and the
    processes of other runs (``load``, default :func:`other_load`: the load average without this run's own) share
    the cores, never faster than alone.

    >>> load_factor(2, load=0.0, cores=2), load_factor(2, load=2.0, cores=2), load_factor(1, load=0.5, cores=4)
    (1.0, 2.0, 1.0)
    """
    others = other_load() if load is None else max(0.0, float(load))
    cores = cores or os.cpu_count() or 1
    return max(1.0, (others + max(1, int(workers))) / cores)


def estimate_seconds(count: int, each: float, workers: int = 1, load: float | None = None,
                     cores: int | None = None) -> float:
    """Wall time of ``count`` items of ``each`` seconds (on one core of a quiet machine) among ``workers``
    processes, slowed by what other runs on this machine compute now (``load``, :func:`load_factor`).

    >>> estimate_seconds(65, 0.3, workers=2, load=0.0, cores=2)
    9.9
    >>> estimate_seconds(65, 0.3, workers=2, load=2.0, cores=2)
    19.8
    """
    if count <= 0:
        return 0.0
    workers = max(1, min(int(workers), count))
    return round(each * math.ceil(count / workers) * load_factor(workers, load, cores), 6)


class Progress:
    """One command's lines about its work, written by ``write`` (e.g. to standard error).

    Call it (or :meth:`say`) with a line; :meth:`plan` starts a count, :meth:`count` advances it,
    :meth:`note` sets what the heartbeat names as running. As a context manager it runs the
    heartbeat in a thread and stops it on leaving.

    Parameters
    ----------
    write : callable
        Writes one line (no newline in it).
    heartbeat : float
        Seconds of silence after which the heartbeat writes a line (0: no heartbeat).
    throttle : float
        Fewest seconds between two counted lines.
    clock : callable
        Seconds, monotonic (a test passes its own).

    Examples
    --------
    >>> now = [0.0]
    >>> progress = Progress(print, clock=lambda: now[0])
    >>> progress.plan("exhaustive search", 4, each=3.0, load=0.0, where="runs/a")
    exhaustive search: 4 solves, estimated 12 s (3.0 s each, 1 worker) -> runs/a
    >>> now[0] = 5.0; progress.count(1)
      exhaustive search: 1/4 after 5.0 s, 5.0 s each, about 15 s left
    >>> now[0] = 6.0; progress.count(2)  # within the throttle: nothing said
    >>> now[0] = 14.0; progress.count(4)
      exhaustive search: 4/4 after 14 s, 3.5 s each
    >>> now[0] = 30.0; progress.beat()
      still running, 16 s since: exhaustive search: 4/4 after 14 s, 3.5 s each
    >>> progress.plan("verification", 1, each=40.0, load=0.0, cores=2)
    verification: 1 solve, estimated 40 s (40 s each, 1 worker)
    >>> progress.note("design 0110"); now[0] = 38.0; progress.beat()
      still running: verification: 0/1 after 8.0 s, about 32 s left by the estimate (design 0110)
    """

    def __init__(self, write: Callable[[str], None], heartbeat: float = HEARTBEAT, throttle: float = THROTTLE,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.write, self.heartbeat, self.throttle, self.clock = write, float(heartbeat), float(throttle), clock
        self.lock = threading.RLock()
        self.last = self.clock()  # when the last line was written
        self.said, self.said_at = "", self.last  # the last line not the heartbeat's, and when
        self.what, self.noun, self.total, self.done, self.first, self.started = "", "solves", 0, 0, 0, self.last
        self.estimate: float | None = None
        self.detail = ""
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def __call__(self, text: str) -> None:
        self.say(text)

    def say(self, text: str) -> None:
        """Write one line now."""
        with self.lock:
            self.write(str(text))
            self.last = self.said_at = self.clock()
            self.said = str(text).strip()

    def plan(self, what: str, total: int, each: float | None = None, workers: int = 1, where: str | None = None,
             noun: str = "solves", load: float | None = None, cores: int | None = None, done: int = 0,
             title: str | None = None) -> None:
        """Start counting ``total`` items of ``what`` and say the plan: how many, the estimated wall time
        (from ``each`` seconds an item on one core of a quiet machine, :func:`estimate_seconds`) and where the
        results go. ``done`` items are finished already (the rate counts the others); ``title`` names the work
        in the plan's line instead of ``what`` (which names it in the counted lines)."""
        with self.lock:
            self.what, self.noun, self.total, self.done, self.first = what, noun, int(total), int(done), int(done)
            self.started, self.detail = self.clock(), ""
            left = int(total) - int(done)
            self.estimate = None if each is None else estimate_seconds(left, float(each), workers, load, cores)
            workers = max(1, int(workers))
            cost = "" if self.estimate is None else (
                f", estimated {duration_text(self.estimate)} ({duration_text(float(each or 0.0))} each, "
                f"{workers} worker{'s' if workers > 1 else ''})")
            noun = noun[:-1] if int(total) == 1 and noun.endswith("s") else noun
            self.say(f"{title or what}: {total} {noun}{cost}" + (f" -> {where}" if where else ""))

    def count(self, done: int, detail: str = "", always: bool = False) -> None:
        """``done`` items of the plan are finished: a line if :data:`THROTTLE` seconds passed since the last
        line (the heartbeat's aside), at the last item, or ``always`` (a failure)."""
        with self.lock:
            if not self.what:
                return  # no count running (or it was said to its end)
            self.done = int(done)
            if always or self.done >= self.total or self.clock() - self.said_at >= self.throttle:
                self.say(f"  {self.status()}" + (f"; {detail}" if detail else ""))
            if self.done >= self.total:
                self.what, self.detail = "", ""  # counted to the end: the heartbeat names the last line

    def note(self, text: str) -> None:
        """What is running now (``design 0110, level 7/16``), named by the next heartbeat."""
        with self.lock:
            self.detail = str(text)

    def status(self) -> str:
        """``what: done/total after T, S each, about R left``: S and R at the rate measured since the plan
        (before the first item, R from the plan's estimate)."""
        with self.lock:
            elapsed = self.clock() - self.started
            text = f"{self.what}: {self.done}/{self.total} after {duration_text(elapsed)}"
            if self.done > self.first:
                each = elapsed / (self.done - self.first)
                text += f", {duration_text(each)} each"
                if self.done < self.total:
                    text += f", about {duration_text(each * (self.total - self.done))} left"
            elif self.estimate is not None:
                left = self.estimate - elapsed
                text += f", about {duration_text(left)} left by the estimate" if left > 0 else \
                    ", longer than estimated"
            return text

    def beat(self) -> None:
        """The heartbeat's line, if ``heartbeat`` seconds passed without one."""
        with self.lock:
            now = self.clock()
            if now - self.last < self.heartbeat:
                return
            detail = f" ({self.detail})" if self.detail else ""
            if self.what:
                text = f"  still running: {self.status()}{detail}"
            elif self.said:
                text = f"  still running, {duration_text(now - self.said_at)} since: {self.said}{detail}"
            else:
                text = f"  still starting after {duration_text(now - self.said_at)}{detail}"
            self.write(text)
            self.last = now

    def __enter__(self) -> Progress:
        if self.heartbeat > 0 and self._thread is None:
            self._stop.clear()
            self._thread = threading.Thread(target=self._run, name="pneumorph-progress", daemon=True)
            self._thread.start()
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        """Stop the heartbeat."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def _run(self) -> None:
        while not self._stop.wait(min(1.0, self.heartbeat / 4)):
            self.beat()


__all__ = ["HEARTBEAT", "THROTTLE", "Progress", "duration_text", "estimate_seconds", "load_factor", "other_load",
           "own_processes"]

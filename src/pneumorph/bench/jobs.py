"""Work that takes longer than a query: FE verification, export and chain tables, each in a process of its own.

A :class:`JobBoard` runs one job at a time (the machine's other core stays with the live
answers), each in a new process of :mod:`pneumorph.bench.worker` in a process group of its
own: the server never solves, meshes or writes a part itself, so it answers queries while a
job runs, and a cancelled job (``DELETE``) or a stopping server ends the job's whole process
group at once, its FE workers with it. The FE solves go through the package's evaluators and
the shared evaluation cache, so a verified design is never solved twice and a design run
from the CLI answers the bench from the cache. Every job lives in its own folder under the
state directory, with a ``job.json`` written atomically at each change: a page reload finds
it, and a server restart lists finished jobs again (a job that was running when the server
stopped is marked interrupted).

Jobs belong to a browser session; one session cannot see, fetch or cancel another's jobs.
A session has at most :attr:`JobLimits.per_session` jobs queued or running, the board at most
:attr:`JobLimits.queued`; finished jobs expire after :attr:`JobLimits.expiry_days`, and the
oldest finished jobs make room when the state folder passes :attr:`JobLimits.quota_mb`.
"""

from __future__ import annotations

import json
import os
import queue
import secrets
import shutil
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pneumorph.bench.answer import LIBRARIES, Bench
from pneumorph.bench.query import Query
from pneumorph.errors import JobLimitError, StateQuotaError
from pneumorph.io.files import atomic_write_text, json_safe

STATES = ("queued", "running", "done", "failed", "cancelled", "interrupted")
ACTIVE = ("queued", "running")
MAX_LOG = 500  # lines a job keeps
STOP_GRACE = 2.0  # seconds a job's processes get between SIGTERM and SIGKILL
SWEEP_EVERY = 3600.0  # seconds between sweeps of expired jobs while the bench is idle


@dataclass(frozen=True)
class JobLimits:
    """What the bench's jobs may take.

    Attributes
    ----------
    per_session : int
        Jobs one session may have queued or running at once.
    queued : int
        Jobs all sessions together may have queued or running.
    expiry_days : float
        Finished jobs (and their files) are deleted this long after they were started.
    quota_mb : float
        Disk space the state folder may take (jobs, FE shapes, units); past it the oldest
        finished jobs are deleted, and a new job is refused while the rest exceeds it.

    Examples
    --------
    >>> JobLimits().per_session, JobLimits(quota_mb=100).quota_mb
    (2, 100)
    """

    per_session: int = 2
    queued: int = 8
    expiry_days: float = 7.0
    quota_mb: float = 2000.0


@dataclass
class Job:
    """One background job and what it has said so far."""

    id: str
    session: str
    kind: str
    folder: Path
    params: dict[str, Any]
    state: str = "queued"
    progress: float = 0.0
    message: str = "queued"
    log: list[str] = field(default_factory=list)
    result: dict[str, Any] | None = None
    files: list[str] = field(default_factory=list)
    created: float = field(default_factory=time.time)
    process: subprocess.Popen[bytes] | None = field(default=None, repr=False)
    stop: str | None = None  # why the job is being stopped: "cancelled" or "interrupted"

    def to_dict(self) -> dict[str, Any]:
        """The job as the page sees it (file links relative to the server)."""
        return {"id": self.id, "kind": self.kind, "state": self.state, "progress": self.progress,
                "message": self.message, "log": self.log[-200:], "result": self.result, "created": self.created,
                "params": self.params,
                "files": [{"name": f, "url": f"/api/jobs/{self.id}/files/{f}"} for f in self.files]}

    def save(self) -> None:
        record = {**self.to_dict(), "log": self.log, "session": self.session}
        atomic_write_text(self.folder / "job.json", json.dumps(json_safe(record), indent=1))


def folder_size(path: Path) -> int:
    """Bytes of the files under ``path`` (0 for a missing folder).

    Examples
    --------
    >>> folder_size(Path("no-such-folder"))
    0
    """
    total = 0
    for root, _, files in os.walk(path):
        for name in files:
            try:
                total += os.lstat(os.path.join(root, name)).st_size
            except OSError:
                continue
    return total


class JobBoard:
    """The background jobs of every session, each run in a worker process.

    Parameters
    ----------
    bench : Bench
    state_dir : path
        Jobs' folders go in ``state_dir/jobs``.
    cache : path
        The evaluation cache (SQLite) the FE solves go through.
    workers : int
        FE worker processes of a job.
    limits : JobLimits, optional
    """

    def __init__(self, bench: Bench, state_dir: str | Path, cache: str | Path, workers: int = 1,
                 limits: JobLimits | None = None) -> None:
        self.bench = bench
        self.state_dir = Path(state_dir)
        self.root = self.state_dir / "jobs"
        self.root.mkdir(parents=True, exist_ok=True)
        self.cache = Path(cache)
        self.workers = int(workers)
        self.limits = limits or JobLimits()
        self._jobs: dict[str, Job] = {}
        self._lock = threading.RLock()
        self._queue: queue.Queue[Job | None] = queue.Queue()
        self._closing = False
        self._load()
        self.sweep()
        self._runner = threading.Thread(target=self._serve, name="pneumorph-jobs", daemon=True)
        self._runner.start()

    def _load(self) -> None:
        for record in sorted(self.root.glob("*/job.json")):
            try:
                data = json.loads(record.read_text(encoding="utf-8"))
                job = Job(data["id"], data["session"], data["kind"], record.parent, data.get("params", {}),
                          data["state"], float(data.get("progress", 0.0)), data.get("message", ""),
                          list(data.get("log", [])), data.get("result"), [f["name"] for f in data.get("files", [])],
                          float(data.get("created", 0.0)))
            except (OSError, ValueError, KeyError, TypeError, RecursionError):
                continue  # not a job this version wrote
            if job.state in ACTIVE:
                job.state, job.message = "interrupted", "the server stopped before the job finished; start it again"
                job.save()
            self._jobs[job.id] = job

    # -- the page's view ----------------------------------------------------------------
    def get(self, session: str, job_id: str) -> Job | None:
        """A job of ``session`` (None for another session's or an unknown id)."""
        job = self._jobs.get(job_id)
        return job if job is not None and job.session == session else None

    def of(self, session: str) -> list[Job]:
        """The session's jobs, newest first."""
        with self._lock:
            mine = [j for j in self._jobs.values() if j.session == session]
        return sorted(mine, key=lambda j: -j.created)

    def file(self, session: str, job_id: str, name: str) -> Path | None:
        """A file a job of ``session`` offers for download (None otherwise)."""
        job = self.get(session, job_id)
        if job is None or name not in job.files:
            return None
        path = job.folder / "files" / name
        return path if path.is_file() else None

    # -- limits ---------------------------------------------------------------------------
    def sweep(self) -> int:
        """Delete expired finished jobs and FE shapes, then the oldest finished jobs while the state folder
        is past its quota. Runs at start, before each new job and every :data:`SWEEP_EVERY` s.

        Returns
        -------
        int
            Bytes the state folder takes afterwards.
        """
        now = time.time()
        expiry = self.limits.expiry_days * 86400
        with self._lock:
            finished = sorted((j for j in self._jobs.values() if j.state not in ACTIVE), key=lambda j: j.created)
            for job in finished:
                if now - job.created > expiry:
                    self._delete(job)
            for shape in (self.state_dir / "shapes").glob("*.json"):  # a verified design's 3D view, kept as long
                try:
                    if now - shape.stat().st_mtime > expiry:
                        shape.unlink()
                except OSError:
                    continue
            used = folder_size(self.state_dir)
            quota = self.limits.quota_mb * 1e6
            for job in finished:
                if used <= quota:
                    break
                if job.id in self._jobs:
                    used -= folder_size(job.folder)
                    self._delete(job)
        return used

    def _delete(self, job: Job) -> None:
        self._jobs.pop(job.id, None)
        shutil.rmtree(job.folder, ignore_errors=True)

    # -- starting and stopping jobs ---------------------------------------------------
    def submit(self, session: str, kind: str, params: dict[str, Any]) -> Job:
        """Queue a job of ``kind`` (a job of :mod:`pneumorph.bench.worker`) for ``session``.

        Raises
        ------
        JobLimitError
            The session, or the board, has as many jobs queued or running as it may.
        StateQuotaError
            The state folder is full even without the finished jobs.
        """
        with self._lock:
            if self._closing:
                raise JobLimitError("the bench is stopping; no new jobs")
            active = [j for j in self._jobs.values() if j.state in ACTIVE]
            if sum(j.session == session for j in active) >= self.limits.per_session:
                raise JobLimitError(f"this session has {self.limits.per_session} jobs queued or running, the limit "
                                    "(serve --jobs-per-session); wait for one or cancel it")
            if len(active) >= self.limits.queued:
                raise JobLimitError(f"the bench has {self.limits.queued} jobs queued or running, its limit "
                                    "(serve --max-jobs); try again when one has finished")
            used = self.sweep()
            if used > self.limits.quota_mb * 1e6:
                raise StateQuotaError(f"the bench's state folder takes {used / 1e6:.0f} MB, above its quota of "
                                      f"{self.limits.quota_mb:g} MB (serve --state-quota); wait for a job to end")
            job = Job(secrets.token_hex(16), session, kind, self.root / secrets.token_hex(16), params)
            job.folder.mkdir(parents=True)
            job.save()
            self._jobs[job.id] = job
        self._queue.put(job)
        return job

    def verify(self, session: str, query: Query) -> Job:
        """Certify a query's optimum by FE: ``pneumorph design --certify`` for its target and model."""
        return self.submit(session, "verify", {"query": json.loads(query.key())})

    def export(self, session: str, design: str, unit: str = "builtin") -> Job:
        """STL parts, casting mould and CalculiX deck of a design, zipped."""
        return self.submit(session, "export", {"design": design, "unit": unit})

    def table(self, session: str, spec: Any, fidelity: str) -> Job:
        """The chain table of an uploaded unit (built on first use through the evaluation cache).

        The unit gets a random id, offered to ``session`` alone once the job is done (the
        built-in unit's parameters are the built-in unit).
        """
        from pneumorph.geometry.unit import UnitSpec

        unit_id = "builtin" if spec == UnitSpec() else "u" + secrets.token_hex(8)
        return self.submit(session, "table", {"model": fidelity, "unit": spec.to_dict(), "unit_id": unit_id})

    def units_of(self, session: str) -> list[dict[str, Any]]:
        """The units this session's finished table jobs made available."""
        return [{"id": j.result["unit_id"], "name": j.result["name"], "model": j.result["model"]}
                for j in self.of(session) if j.kind == "table" and j.state == "done" and j.result]

    def unit_ids_of(self, session: str) -> tuple[str, ...]:
        """The unit ids ``session`` may name: the built-in unit, the built-in libraries and its own uploaded units."""
        return ("builtin", *LIBRARIES, *(u["id"] for u in self.units_of(session) if u["id"] != "builtin"))

    def cancel(self, session: str, job_id: str) -> Job | None:
        """Cancel a queued or running job of ``session`` (its processes end at once); delete a finished one.

        Returns the job (state ``cancelled``, or as it was when deleted), None if ``session``
        has no such job.
        """
        with self._lock:
            job = self.get(session, job_id)
            if job is None:
                return None
            if job.state == "queued":
                job.state, job.message = "cancelled", "cancelled before it started"
                job.save()
            elif job.state == "running":
                job.stop = "cancelled"
                self._terminate(job)
            else:
                self._delete(job)
        if job.state == "running" and job.process is not None:
            self._reap(job)
        return job

    def close(self, timeout: float = 5.0) -> None:
        """Stop: the running job's processes end (it is marked interrupted), queued jobs are marked interrupted."""
        with self._lock:
            if self._closing:
                return
            self._closing = True
            for job in self._jobs.values():
                if job.state == "queued":
                    job.state, job.message = "interrupted", "the server stopped before the job started"
                    job.save()
                elif job.state == "running":
                    job.stop = "interrupted"
                    self._terminate(job)
        self._queue.put(None)
        self._runner.join(timeout)

    def _terminate(self, job: Job) -> None:
        """SIGTERM to the job's process group; SIGKILL after :data:`STOP_GRACE` s if it lives on."""
        proc = job.process
        if proc is None or proc.poll() is not None:
            return
        try:
            os.killpg(proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            return

        def kill() -> None:
            try:
                proc.wait(STOP_GRACE)
            except subprocess.TimeoutExpired:
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass

        threading.Thread(target=kill, daemon=True).start()

    def _reap(self, job: Job, timeout: float = 2 * STOP_GRACE + 1) -> None:
        """Wait until the runner has recorded a stopped job's end (or ``timeout`` s)."""
        end = time.monotonic() + timeout
        while job.state == "running" and time.monotonic() < end:
            time.sleep(0.02)

    # -- running ------------------------------------------------------------------------
    def _serve(self) -> None:
        while True:
            try:
                job = self._queue.get(timeout=SWEEP_EVERY)
            except queue.Empty:
                self.sweep()
                continue
            if job is None or self._closing:
                return
            if job.state != "queued":
                continue  # cancelled while it waited
            try:
                self._run(job)
            except Exception as exc:  # the worker could not be started (or read): this job fails, the board goes on
                with self._lock:
                    job.state, job.message, job.process = "failed", f"the job could not run: {exc}"[:500], None
                    job.log.append(job.message)
                    job.save()

    def _run(self, job: Job) -> None:
        from pneumorph.execution.evaluators import THREAD_VARIABLES

        spec = {"kind": job.kind, "params": job.params, "folder": str(job.folder), "cache": str(self.cache),
                "workers": self.workers, "table_dir": str(self.bench.table_dir) if self.bench.table_dir else None,
                "unit_dir": str(self.bench.unit_dir) if self.bench.unit_dir else None,
                "model_settings": self.bench.settings,
                "shape_dir": str(self.bench.shape_dir or self.state_dir / "shapes")}
        env = {**os.environ, **dict.fromkeys(THREAD_VARIABLES, "1"), "PYTHONUNBUFFERED": "1"}
        with self._lock:
            if self._closing or job.state != "queued":
                return
            job.state, job.message = "running", "started"
            job.save()
            with open(job.folder / "worker.log", "wb") as log:
                job.process = subprocess.Popen([sys.executable, "-m", "pneumorph.bench.worker"], stdin=subprocess.PIPE,
                                               stdout=subprocess.PIPE, stderr=log, env=env, start_new_session=True)
        proc = job.process
        assert proc.stdin is not None and proc.stdout is not None
        error = None
        done = False
        try:
            proc.stdin.write(json.dumps(spec).encode())
            proc.stdin.close()
        except OSError:
            pass  # it ended already: said below
        for line in proc.stdout:
            try:
                event = json.loads(line)
            except ValueError:
                continue
            if "say" in event:
                self._say(job, str(event["say"]), event.get("progress"))
            elif "file" in event:
                if event["file"] not in job.files:
                    job.files.append(str(event["file"]))
            elif "result" in event:
                job.result, done = event["result"], True
            elif "error" in event:
                error = str(event["error"])
        code = proc.wait()
        with self._lock:
            if job.stop == "cancelled":
                job.state, job.message = "cancelled", "cancelled"
            elif job.stop == "interrupted" or self._closing:
                job.state, job.message = "interrupted", "the server stopped while the job ran; start it again"
            elif done and code == 0:
                job.state, job.progress, job.message = "done", 1.0, "done"
            else:
                job.state = "failed"
                job.message = error or (f"the job's process ended with code {code}"
                                        + (" (killed: out of memory?)" if code == -signal.SIGKILL else ""))
            job.log.append(job.message)
            job.process = None
            job.save()

    def _say(self, job: Job, text: str, progress: float | None = None) -> None:
        job.log.append(text)
        del job.log[:-MAX_LOG]
        job.message = text
        if isinstance(progress, (int, float)):
            job.progress = max(job.progress, min(float(progress), 0.99))
        job.save()


def fe_solve_shape(model: Any, design: str) -> tuple[Any, dict[str, Any] | None, float]:
    """Solve a design with a 3D model (in a worker process): its response, its surface at every level, seconds.

    A failed solve gives ``(None, None, seconds)``; so does a ramp that did not converge.
    """
    from pneumorph.bench.shapes import surface
    from pneumorph.errors import SimulationFailed

    start = time.perf_counter()
    try:
        solution = model.solve(design)
    except SimulationFailed:
        return None, None, time.perf_counter() - start
    wall = time.perf_counter() - start
    if not solution.response.converged:
        return None, None, wall
    mesh = solution.mesh
    levels = [surface(mesh, mesh.points + u) for u in solution.displacements]
    shape = {"source": "fe", "indices": levels[0]["indices"],
             "levels": [{"positions": s["positions"], "bounds": s["bounds"]} for s in levels]}
    return solution.response, shape, wall


__all__ = ["ACTIVE", "STATES", "Job", "JobBoard", "JobLimits", "fe_solve_shape", "folder_size"]

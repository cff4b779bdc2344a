"""Work that takes longer than a query: FE verification and export, run in the background.

A :class:`JobBoard` runs one job at a time on a thread of the server (the machine's other
core stays with the live answers); the FE solves themselves run in a worker process through
the package's evaluators and the shared evaluation cache, so a verified design is never
solved twice and a design run from the CLI answers the bench from the cache. Every job lives
in its own folder under the state directory, with a ``job.json`` written atomically at each
change: a page reload finds it, and a server restart lists finished jobs again (a job that
was running when the server stopped is marked failed).

Jobs belong to a browser session; one session cannot see or fetch another's jobs.
"""

from __future__ import annotations

import json
import multiprocessing
import shutil
import threading
import time
import uuid
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pneumorph.bench.answer import Bench
from pneumorph.bench.query import Query
from pneumorph.execution.evaluators import prepare_worker
from pneumorph.io.files import atomic_write_text, json_safe

STATES = ("queued", "running", "done", "failed")
SHOWN = ("report.md", "certificate.json", "top.csv", "profile.png", "chain-vs-fe.png", "mould.png")


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

    def to_dict(self) -> dict[str, Any]:
        """The job as the page sees it (file links relative to the server)."""
        return {"id": self.id, "kind": self.kind, "state": self.state, "progress": self.progress,
                "message": self.message, "log": self.log[-200:], "result": self.result, "created": self.created,
                "params": self.params,
                "files": [{"name": f, "url": f"/api/jobs/{self.id}/files/{f}"} for f in self.files]}

    def save(self) -> None:
        record = {**self.to_dict(), "session": self.session}
        atomic_write_text(self.folder / "job.json", json.dumps(json_safe(record), indent=1))


class JobBoard:
    """The background jobs of every session.

    Parameters
    ----------
    bench : Bench
    state_dir : path
        Jobs' folders go in ``state_dir/jobs``.
    cache : path
        The evaluation cache (SQLite) the FE solves go through.
    workers : int
        FE worker processes.
    """

    def __init__(self, bench: Bench, state_dir: str | Path, cache: str | Path, workers: int = 1) -> None:
        self.bench = bench
        self.root = Path(state_dir) / "jobs"
        self.root.mkdir(parents=True, exist_ok=True)
        self.cache = Path(cache)
        self.workers = int(workers)
        self._jobs: dict[str, Job] = {}
        self._lock = threading.Lock()
        self._runner = ThreadPoolExecutor(max_workers=1, thread_name_prefix="pneumorph-job")
        self._load()

    def _load(self) -> None:
        for record in sorted(self.root.glob("*/job.json")):
            try:
                data = json.loads(record.read_text(encoding="utf-8"))
                job = Job(data["id"], data["session"], data["kind"], record.parent, data.get("params", {}),
                          data["state"], float(data.get("progress", 0.0)), data.get("message", ""),
                          list(data.get("log", [])), data.get("result"), [f["name"] for f in data.get("files", [])],
                          float(data.get("created", 0.0)))
            except (OSError, ValueError, KeyError, TypeError):
                continue  # not a job this version wrote
            if job.state in ("queued", "running"):
                job.state, job.message = "failed", "the server stopped before the job finished; start it again"
                job.save()
            self._jobs[job.id] = job

    # -- the page's view ----------------------------------------------------------------
    def get(self, session: str, job_id: str) -> Job | None:
        """A job of ``session`` (None for another session's or an unknown id)."""
        job = self._jobs.get(job_id)
        return job if job is not None and job.session == session else None

    def of(self, session: str) -> list[Job]:
        """The session's jobs, newest first."""
        return sorted((j for j in self._jobs.values() if j.session == session), key=lambda j: -j.created)

    def file(self, session: str, job_id: str, name: str) -> Path | None:
        """A file a job of ``session`` offers for download (None otherwise)."""
        job = self.get(session, job_id)
        if job is None or name not in job.files:
            return None
        path = job.folder / "files" / name
        return path if path.is_file() else None

    # -- starting jobs ------------------------------------------------------------------
    def submit(self, session: str, kind: str, params: dict[str, Any], work: Callable[[Job], None]) -> Job:
        job = Job(uuid.uuid4().hex, session, kind, self.root / uuid.uuid4().hex, params)
        job.folder.mkdir(parents=True)
        job.save()
        with self._lock:
            self._jobs[job.id] = job
        self._runner.submit(self._run, job, work)
        return job

    def verify(self, session: str, query: Query) -> Job:
        """Certify a query's optimum by FE: ``pneumorph design --certify`` for its target and model.

        In 3D the chain's best design is solved first in a worker process, keeping its fields
        for the 3D view; its response goes into the cache, where the design run finds it.
        """
        return self.submit(session, "verify", {"query": json.loads(query.key())}, lambda job: self._verify(job, query))

    def export(self, session: str, design: str, unit: str = "builtin") -> Job:
        """STL parts, casting mould and CalculiX deck of a design, zipped."""
        return self.submit(session, "export", {"design": design, "unit": unit},
                           lambda job: self._export(job, design, unit))

    def table(self, session: str, spec: Any, fidelity: str) -> Job:
        """The chain table of an uploaded unit (built on first use through the evaluation cache)."""
        return self.submit(session, "table", {"model": fidelity, "unit": spec.to_dict()},
                           lambda job: self._table(job, spec, fidelity))

    def units_of(self, session: str) -> list[dict[str, Any]]:
        """The units this session's finished table jobs made available."""
        return [{"id": j.result["unit_id"], "name": j.result["name"], "model": j.result["model"]}
                for j in self.of(session) if j.kind == "table" and j.state == "done" and j.result]

    def close(self) -> None:
        self._runner.shutdown(wait=False, cancel_futures=True)

    # -- running ------------------------------------------------------------------------
    def _run(self, job: Job, work: Callable[[Job], None]) -> None:
        job.state, job.message = "running", "started"
        job.save()
        try:
            work(job)
        except Exception as exc:  # the job fails, the server goes on; the message says why
            job.state, job.message = "failed", f"{type(exc).__name__}: {exc}"
            job.log.append(job.message)
        else:
            job.state, job.progress, job.message = "done", 1.0, "done"
        job.save()

    def _say(self, job: Job, text: str, progress: float | None = None) -> None:
        job.log.append(text)
        job.message = text
        if progress is not None:
            job.progress = max(job.progress, min(float(progress), 0.99))
        job.save()

    def _offer(self, job: Job, path: Path, name: str | None = None) -> None:
        out = job.folder / "files"
        out.mkdir(exist_ok=True)
        target = out / (name or path.name)
        if path.resolve() != target.resolve():
            shutil.copyfile(path, target)
        if target.name not in job.files:
            job.files.append(target.name)

    def _verify(self, job: Job, query: Query) -> None:
        from pneumorph.design.run import run_design

        unit = None if query.unit == "builtin" else self.bench.unit_spec(query.unit).to_dict()
        config = query.config(self.bench.units, unit, certify=True, executor="processes", workers=self.workers,
                              cache=str(self.cache))
        model = self.bench.model(query.model, query.unit)
        if query.model == "3d":  # solve the chain's best once, keeping its fields for the 3D view
            design = self.bench.answer(query)["winner"]["design"]
            self._say(job, f"solving {design} by 3D FE (its shape and its verification)", 0.05)
            self._presolve(model, design, query.unit)
        run = job.folder / "run"
        self._say(job, f"design run: certified search on the {query.model.upper()} model", 0.5)
        result = run_design(config, model, run, on_message=lambda text: self._say(job, str(text)))
        cert = result.certified
        if result.status != "finished" or cert is None:
            raise RuntimeError(f"the design run ended {result.status}")
        winner = cert.winner
        self._say(job, f"verified {winner.design}: {winner.value:.4g} {result.objective.unit} by FE", 0.9)
        for path in result.files:
            if path.name in SHOWN:
                self._offer(job, path)
        archive = shutil.make_archive(str(job.folder / "run"), "zip", root_dir=run)
        self._offer(job, Path(archive))
        job.result = {"design": winner.design, "fe_value": winner.value, "chain_value": cert.winner_chain.value,
                      "level": winner.level, "pressure_kpa": None if winner.pressure is None else winner.pressure * 1e3,
                      "certified": bool(cert.certificate["certified"]), "gap": cert.certificate["gap"],
                      "could_beat": cert.certificate["could_beat"], "verified": cert.certificate["verified"],
                      "solves": result.solves, "unit": result.objective.unit, "model": query.model,
                      "shape": self.bench.fe_shape_file(winner.design, query.unit) is not None}

    def _presolve(self, model: Any, design: str, unit: str) -> None:
        """Solve ``design`` in a worker process: its surface for the viewer, its response into the cache."""
        from pneumorph.execution.cache import EvaluationCache
        from pneumorph.execution.outcome import Outcome

        with EvaluationCache(self.cache) as cache:
            fe_known = self.bench.fe_shape_file(design, unit) is not None
            if cache.get(model.fingerprint(), design) is not None and fe_known:
                return  # verified and drawn before
        # spawned, as the evaluators' workers: a fork of the threaded server could inherit a held lock
        with ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn"),
                                 initializer=prepare_worker) as pool:
            response, shape, wall = pool.submit(fe_solve_shape, model, design).result()
        if response is None or shape is None:
            return  # the design run solves it again and reports the failure
        self.bench.add_fe_shape(design, shape, unit)
        with EvaluationCache(self.cache) as cache:
            if cache.get(model.fingerprint(), design) is None:
                cache.put(model.fingerprint(), Outcome(design, response, wall_time=wall))

    def _table(self, job: Job, spec: Any, fidelity: str) -> None:
        from pneumorph.execution import CachedEvaluator, EvaluationCache, make_evaluator
        from pneumorph.models.chaintables import table_for

        unit_id = self.bench.add_unit(spec)
        model = self.bench.model(fidelity, unit_id)
        self._say(job, f"chain table of unit {spec.name!r} for the {fidelity.upper()} model", 0.02)
        with EvaluationCache(self.cache) as cache, make_evaluator("processes", self.workers) as inner:
            table = table_for(model, model.with_units, folder=self.bench.table_dir,
                              evaluator=CachedEvaluator(inner, cache), on_progress=lambda t: self._say(
                                  job, str(t), _fraction(str(t))))
        val = table.validation
        job.result = {"unit_id": unit_id, "name": spec.name, "model": fidelity, "window": table.window,
                      "centre_worst_mm": max(val.get("centre_worst_mm", [float("nan")]))}
        self._say(job, f"unit {spec.name!r} ready: window {table.window}, held-out centre error at most "
                       f"{job.result['centre_worst_mm']:.3g} mm", 0.99)

    def _export(self, job: Job, design: str, unit_id: str = "builtin") -> None:
        from pneumorph.export import BaseBlock, MouldSpec, actuator_parts, casting_mould, plot_mould, write_stl
        from pneumorph.export.calculix import write_calculix_deck

        model = self.bench.model("3d", unit_id)
        unit = model.unit
        out = job.folder / "export"
        self._say(job, f"parts of {design}", 0.1)
        write_stl(actuator_parts(unit, design, BaseBlock()), out / "parts")
        self._say(job, "casting mould", 0.3)
        mould = casting_mould(unit, design, MouldSpec())
        write_stl(mould.parts, out / "mould")
        plot_mould(mould, out / "mould" / "mould.png")
        self._offer(job, out / "mould" / "mould.png")
        self._say(job, "CalculiX deck", 0.8)
        write_calculix_deck(model, design, out / f"{design}.inp")
        archive = shutil.make_archive(str(job.folder / f"export-{design}"), "zip", root_dir=out)
        self._offer(job, Path(archive))
        job.result = {"design": design, "parts": sorted(p.name for p in (out / "parts").glob("*.stl")),
                      "mould_parts": len(mould.parts)}


def _fraction(text: str) -> float | None:
    """The share done in a table build's progress line ("covering: 12/30 solved ..."), if it says."""
    import re

    found = re.search(r"(\d+)/(\d+) solved", text)
    return None if found is None else 0.05 + 0.9 * int(found.group(1)) / max(int(found.group(2)), 1)


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


__all__ = ["STATES", "Job", "JobBoard", "fe_solve_shape"]

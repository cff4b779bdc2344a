"""The bench's web application: the page, its JSON API and the background jobs (FastAPI).

Every route is a thin shell over :class:`~pneumorph.bench.answer.Bench` (answers, shapes)
and :class:`~pneumorph.bench.jobs.JobBoard` (verification, export); the page holds no
logic of its own. A browser session is a random cookie; a session sees only its own jobs.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import multiprocessing
import os
from collections.abc import AsyncIterator
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from importlib import resources
from pathlib import Path
from typing import Any

from fastapi import APIRouter, FastAPI, Request
from fastapi.concurrency import run_in_threadpool
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, JSONResponse, Response
from fastapi.staticfiles import StaticFiles
from starlette.exceptions import HTTPException as StarletteHTTPException

from pneumorph.bench.answer import LIBRARIES, Bench
from pneumorph.bench.guard import (
    LOCAL_HOSTS,
    MAX_UNIT_FILE,
    Guard,
    Signing,
    error,
    error_body,
)
from pneumorph.bench.jobs import JobBoard, JobLimits
from pneumorph.bench.query import MODELS, Query, QueryError, choice, load_json
from pneumorph.bench.schema import describe
from pneumorph.design.objectives.paths import PATH_PRESETS
from pneumorph.design.objectives.targets import PRESETS, TIP_GOALS
from pneumorph.errors import BodyTooLargeError, JobLimitError, PneumorphError, SettingsError, StateQuotaError
from pneumorph.geometry.limits import MeshLimitError, check_manufacturable
from pneumorph.geometry.meshsize import check_mesh
from pneumorph.geometry.unit import UnitSpec
from pneumorph.io.files import json_safe
from pneumorph.io.reading import decode_text, parse_toml


def read_unit(raw: bytes) -> UnitSpec:
    """An uploaded unit TOML file, checked: size, UTF-8 text, TOML, a valid ``[unit]`` table, a unit a mould can
    cast (:func:`~pneumorph.geometry.limits.check_manufacturable`).

    Raises
    ------
    QueryError
        Field ``unit``, saying what is wrong.
    """
    if len(raw) > MAX_UNIT_FILE:
        raise QueryError("unit", f"a unit file is at most {MAX_UNIT_FILE // 1024} kB")
    try:  # the one reader of a user's text: a byte-order mark read as the file's encoding, TOML's depth bounded
        data = parse_toml(decode_text(raw, "the unit file"), "the unit file")
    except SettingsError as exc:
        raise QueryError("unit", str(exc)) from None
    table = data.get("unit")
    if not isinstance(table, dict):
        raise QueryError("unit", "the unit file needs a [unit] table (lengths in mm)")
    try:
        spec = UnitSpec.from_dict(table, "uploaded unit")
        check_manufacturable(spec, "uploaded unit:")
        return spec
    except PneumorphError as exc:
        raise QueryError("unit", str(exc)) from None


_POOL_BENCH: Bench | None = None


def _start_answer_worker(table_dir: Path | None, unit_dir: Path | None, settings: dict[str, Any]) -> None:
    global _POOL_BENCH
    from pneumorph.execution.evaluators import prepare_worker

    prepare_worker()
    _POOL_BENCH = Bench(table_dir=table_dir, unit_dir=unit_dir, memo=0, settings=settings)


def _answer_in_worker(query: Query) -> dict[str, Any]:
    assert _POOL_BENCH is not None
    if not _POOL_BENCH.knows(query.unit):
        raise QueryError("unit", f"unknown unit {query.unit!r}")
    return _POOL_BENCH.compute(query)


def _warm_worker(fidelity: str) -> int:
    assert _POOL_BENCH is not None
    _POOL_BENCH.compute(Query("preset", "sin", model=fidelity))
    return os.getpid()


#: slow queries (:meth:`~pneumorph.bench.answer.Bench.slow`) the bench holds at once: one answered, one waiting
#: for it; more are refused (429) with the reason, to be asked again
SLOW_QUEUE = 2


class SlowQueriesBusy(JobLimitError):
    """A slow query refused: :data:`SLOW_QUEUE` of them are being answered or waiting."""


class AnswerPool:
    """Answers computed in worker processes, so that concurrent queries use every core.

    Each worker holds its own :class:`Bench` (models and chain tables loaded once); a query
    travels as a :class:`Query` and its answer comes back as plain data. Slow queries (the
    branch-and-bound of a chain in space, seconds to a minute within the query's memory
    budget, :data:`~pneumorph.bench.answer.QUERY_MEMORY`) go to a worker of their own, at
    most :data:`SLOW_QUEUE` at a time, so that they never hold up the plain ones: ``workers``
    is the plain queries' workers plus that one (at least one each). With no workers, answers
    are computed on the server's threads (slow ones counted the same).
    """

    def __init__(self, bench: Bench, workers: int | None = None) -> None:
        self.bench = bench
        self.workers = min(os.cpu_count() or 1, 4) if workers is None else int(workers)
        self._pool: ProcessPoolExecutor | None = None
        self._slow_pool: ProcessPoolExecutor | None = None
        self._slow = 0  # slow queries answered or waiting

    def _make(self, workers: int) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                                   initializer=_start_answer_worker,
                                   initargs=(self.bench.table_dir, self.bench.unit_dir, self.bench.settings))

    async def start(self) -> None:
        """Start the workers and load their tables (before the first query is taken)."""
        if self.workers < 1:
            return
        plain = max(1, self.workers - 1)
        self._pool, self._slow_pool = self._make(plain), self._make(1)
        loop = asyncio.get_running_loop()
        for fidelity in ("3d", "2d"):
            await asyncio.gather(*(loop.run_in_executor(self._pool, _warm_worker, fidelity) for _ in range(plain)),
                                 loop.run_in_executor(self._slow_pool, _warm_worker, fidelity))

    async def compute(self, query: Query) -> dict[str, Any]:
        """The answer to ``query``: on the plain queries' workers, or a slow one's (refused when too many wait).

        Raises
        ------
        SlowQueriesBusy
            :data:`SLOW_QUEUE` slow queries are being answered or waiting.
        """
        if not self.bench.slow(query):
            return await self._run(query, slow=False)
        if self._slow >= SLOW_QUEUE:
            raise SlowQueriesBusy(f"{self._slow} slow queries (a chain in space searched by branch-and-bound, or an "
                                  "answer solved against an object by FE, up to a minute each) are being answered or "
                                  "waiting; ask again when they are done")
        self._slow += 1
        try:
            return await self._run(query, slow=True)
        finally:
            self._slow -= 1

    async def _run(self, query: Query, slow: bool) -> dict[str, Any]:
        pool = self._slow_pool if slow else self._pool
        if pool is None:
            return await run_in_threadpool(self.bench.compute, query)
        loop = asyncio.get_running_loop()
        try:
            return await loop.run_in_executor(pool, _answer_in_worker, query)
        except BrokenProcessPool:  # a worker died (killed, out of memory): start afresh once
            pool.shutdown(wait=False, cancel_futures=True)
            pool = self._make(1 if slow else max(1, self.workers - 1))
            if slow:
                self._slow_pool = pool
            else:
                self._pool = pool
            return await loop.run_in_executor(pool, _answer_in_worker, query)

    def close(self) -> None:
        for pool in (self._pool, self._slow_pool):
            if pool is not None:
                pool.shutdown(wait=False, cancel_futures=True)
        self._pool = self._slow_pool = None


def static_dir() -> Path:
    """The page's files, installed with the package."""
    return Path(str(resources.files("pneumorph.bench") / "static"))


def default_state_dir() -> Path:
    """Where the bench keeps its jobs and shapes: beside the evaluation cache."""
    from pneumorph.execution.cache import default_cache_path

    return default_cache_path().parent / "bench"


def create_app(state_dir: str | Path | None = None, cache: str | Path | None = None, workers: int = 1,
               answer_workers: int | None = None, allowed_hosts: tuple[str, ...] | list[str] = LOCAL_HOSTS,
               limits: JobLimits | None = None, model_settings: dict[str, Any] | None = None) -> FastAPI:
    """The bench as an ASGI application.

    Parameters
    ----------
    state_dir : path, optional
        Jobs, FE shapes, uploaded units and the session key (default: ``bench/`` beside the evaluation cache).
    cache : path, optional
        The evaluation cache (default: the design command's, so both share solves).
    workers : int
        FE worker processes of a background job.
    answer_workers : int, optional
        Processes that compute answers (default: one per core, at most 4): one of them answers the slow
        queries (a chain in space), the others the plain ones (at least one); 0: on the server's threads.
    allowed_hosts : sequence of str
        The host names (``Host`` header) served; any other is refused (DNS rebinding).
        Default: this machine's loopback names.
    limits : JobLimits, optional
        Jobs per session and in all, their expiry and the state folder's quota.
    model_settings : dict, optional
        Settings under every model of the bench (``serve --model-file``: an identified model; :class:`Bench`).

    Examples
    --------
    >>> import tempfile
    >>> from fastapi.testclient import TestClient
    >>> root = Path(tempfile.mkdtemp())
    >>> client = TestClient(create_app(root / "state", root / "cache.sqlite", answer_workers=0),
    ...                     base_url="http://127.0.0.1:8000")
    >>> client.get("/api/jobs").json()
    {'jobs': []}
    >>> client.post("/api/jobs", content=b'{"kind": "export"}', headers={"content-type": "text/plain"}).json()
    {'error': {'field': 'content-type', 'message': 'this route takes application/json, not text/plain'}}
    """
    from pneumorph import __version__
    from pneumorph.execution.cache import chain_table_dir, default_cache_path

    cache_path = Path(cache) if cache is not None else default_cache_path()
    state = Path(state_dir) if state_dir is not None else default_state_dir()
    state.mkdir(parents=True, exist_ok=True)
    bench = Bench(table_dir=chain_table_dir(cache_path), unit_dir=state / "units", settings=model_settings)
    bench.shape_dir = state / "shapes"
    board = JobBoard(bench, state, cache_path, workers, limits)
    answers = AnswerPool(bench, answer_workers)

    @contextlib.asynccontextmanager
    async def lifespan(app: FastAPI) -> AsyncIterator[None]:
        await answers.start()
        try:
            yield
        finally:  # Ctrl-C, SIGTERM: the running job's processes end now, the job is marked interrupted
            board.close()
            answers.close()

    app = FastAPI(title="pneumorph bench", version=__version__, docs_url=None, redoc_url=None, openapi_url=None,
                  lifespan=lifespan)
    app.state.bench, app.state.board = bench, board
    _add_error_handlers(app)
    app.add_middleware(Guard, signing=Signing(state), allowed_hosts=tuple(allowed_hosts))

    @app.get("/", include_in_schema=False)
    async def index() -> FileResponse:
        return FileResponse(static_dir() / "index.html", headers={"Cache-Control": "no-cache"})

    app.mount("/static", StaticFiles(directory=static_dir()), name="static")
    app.include_router(_answers_router(bench, board, answers))
    app.include_router(_units_router(bench, board))
    app.include_router(_jobs_router(bench, board))
    describe(app)  # the bodies and answers in app.openapi(): docs/bench-api.md renders it
    return app


def _add_error_handlers(app: FastAPI) -> None:
    """Every refusal as the bench's one error format (:func:`~pneumorph.bench.guard.error`)."""

    @app.exception_handler(QueryError)
    async def _query_error(request: Request, exc: QueryError) -> JSONResponse:
        return error(422, exc.field, exc.message)

    @app.exception_handler(StarletteHTTPException)
    async def _http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        field = {404: "path", 405: "method"}.get(exc.status_code, "request")
        message = {404: f"no such route: {request.url.path[:100]}",
                   405: f"{request.method} is not allowed on {request.url.path[:100]}"}.get(exc.status_code,
                                                                                            str(exc.detail))
        return error(exc.status_code, field, message, getattr(exc, "headers", None))

    @app.exception_handler(RequestValidationError)
    async def _validation_error(request: Request, exc: RequestValidationError) -> JSONResponse:
        first = exc.errors()[0] if exc.errors() else {}
        field = str(first.get("loc", ["", "request"])[-1])
        return error(422, field, f"{field}: {first.get('msg', 'invalid')}")

    @app.exception_handler(JobLimitError)
    async def _job_limit(request: Request, exc: JobLimitError) -> JSONResponse:
        field = "query" if isinstance(exc, SlowQueriesBusy) else "job"
        return error(507 if isinstance(exc, StateQuotaError) else 429, field, str(exc))

    @app.exception_handler(BodyTooLargeError)
    async def _too_large(request: Request, exc: BodyTooLargeError) -> JSONResponse:
        return error(413, "body", str(exc), {"Connection": "close"})


async def _body_of(request: Request) -> Any:
    return load_json(await request.body())


def _session_units(board: JobBoard, request: Request) -> tuple[str, ...]:
    return board.unit_ids_of(request.state.session)


def _check_model(bench: Bench, board: JobBoard, model: Any, unit: Any, request: Request) -> None:
    """Refuse a model the bench does not have, or a unit this session does not know."""
    choice(model, MODELS, "model", "model")
    if not isinstance(unit, str) or unit not in _session_units(board, request) or not bench.knows(unit):
        raise QueryError("unit", f"unknown unit {str(unit)[:40]!r}")


def _answers_router(bench: Bench, board: JobBoard, answers: AnswerPool) -> APIRouter:
    """The answers: the bench's settings, a query's answer, a design's profiles and shape by the chain."""
    from pneumorph import __version__

    router = APIRouter()

    @router.get("/api/info")
    async def info() -> dict[str, Any]:
        length = await run_in_threadpool(bench.length, "3d")
        chain = bench.chain("3d")
        return {"version": __version__, "models": list(MODELS), "default_model": "3d", "units": bench.units,
                "length_mm": length, "pressures_kpa": [float(p) * 1e3 for p in chain.pressures()],
                "presets": list(PRESETS), "path_presets": list(PATH_PRESETS), "tip_goals": list(TIP_GOALS),
                "axis_mm": float(chain.table.tip_ref[1]),
                "defaults": {"kind": "preset", "name": "sin", "amplitude": 10.0, "periods": 1.0}}

    @router.post("/api/design")
    async def design(request: Request) -> Response:
        body = await _body_of(request)
        query = bench.parse(body, _session_units(board, request))  # a fraction of a millisecond
        answer = bench.recall(query)
        if answer is None:
            answer = await answers.compute(query)
            bench.remember(query, answer)
        # plain data of floats, ints, strings and lists: json.dumps directly, not FastAPI's generic encoder
        try:
            text = json.dumps(answer, allow_nan=False)
        except ValueError:  # an infinite optimistic value, say: null, as in every JSON pneumorph writes
            text = json.dumps(json_safe(answer), allow_nan=False)
        return Response(text, media_type="application/json")

    @router.get("/api/profiles")
    async def profiles(design: str, request: Request, model: str = "3d", unit: str = "builtin") -> dict[str, Any]:
        _check_model(bench, board, model, unit, request)
        return {"design": design, **await run_in_threadpool(bench.chain_lines, design, model, unit)}

    @router.get("/api/shape")
    async def shape(design: str, level: int, request: Request, model: str = "3d",
                    unit: str = "builtin") -> dict[str, Any]:
        _check_model(bench, board, model, unit, request)
        return await run_in_threadpool(bench.chain_shape, design, model, level, unit)

    return router


def _units_router(bench: Bench, board: JobBoard) -> APIRouter:
    """The units: the session's list, and an uploaded unit file's chain table as a job."""
    router = APIRouter()

    @router.get("/api/units")
    async def units(request: Request) -> dict[str, Any]:
        return {"units": [{"id": "builtin", "name": bench.unit_spec().name, "model": "3d and 2d"},
                          *({"id": k, "name": name, "model": "3d"} for k, name in LIBRARIES.items()),
                          *board.units_of(request.state.session)]}

    @router.post("/api/jobs/table", status_code=202)
    async def start_table(request: Request) -> dict[str, Any]:
        # the Guard has bounded the whole body to MAX_UPLOAD bytes: the form is parsed in memory
        form = await request.form(max_files=1, max_fields=4)
        upload = form.get("unit")
        model = choice(form.get("model", "3d"), MODELS, "model", "model")
        if upload is None or isinstance(upload, str):
            raise QueryError("unit", "attach a unit TOML file (a [unit] table, lengths in mm)")
        raw = await upload.read(MAX_UNIT_FILE + 1)
        spec = await run_in_threadpool(read_unit, raw)
        try:  # what it costs, before anything is meshed: the same rule as the command line's
            check_mesh(spec, bench.units, 3 if model == "3d" else 2)
        except MeshLimitError as exc:
            raise QueryError("unit", str(exc)) from None
        return {"job_id": board.table(request.state.session, spec, str(model)).id}

    return router


def _jobs_router(bench: Bench, board: JobBoard) -> APIRouter:
    """The jobs: started (a verification, an export), listed, looked at, cancelled, and their files."""
    router = APIRouter()

    @router.post("/api/jobs", status_code=202)
    async def start_job(request: Request) -> dict[str, Any]:
        body = await _body_of(request)
        kind = body.get("kind") if isinstance(body, dict) else None
        session = request.state.session
        if kind == "verify":
            query = await run_in_threadpool(bench.parse, body.get("query"), _session_units(board, request))
            job = board.verify(session, query)
        elif kind == "export":
            design, unit = body.get("design"), body.get("unit", "builtin")
            _check_model(bench, board, "3d", unit, request)
            try:
                design = bench.model("3d", unit).parse(design if isinstance(design, str) else "").text
            except PneumorphError as exc:
                raise QueryError("design", str(exc)) from None
            job = board.export(session, design, unit)
        else:
            raise QueryError("kind", f"a job is 'verify' or 'export', got {str(kind)[:40]!r}")
        return {"job_id": job.id}

    @router.get("/api/jobs")
    async def jobs(request: Request) -> dict[str, Any]:
        return {"jobs": [j.to_dict() for j in board.of(request.state.session)]}

    @router.get("/api/jobs/{job_id}")
    async def job(job_id: str, request: Request) -> Any:
        found = board.get(request.state.session, job_id)
        if found is None:
            return error(404, "job", "no such job in this session")
        return found.to_dict()

    @router.delete("/api/jobs/{job_id}")
    async def cancel_job(job_id: str, request: Request) -> Any:
        found = await run_in_threadpool(board.cancel, request.state.session, job_id)
        if found is None:
            return error(404, "job", "no such job in this session")
        return found.to_dict()

    @router.get("/api/jobs/{job_id}/files/{name}")
    async def job_file(job_id: str, name: str, request: Request) -> Any:
        path = board.file(request.state.session, job_id, name)
        if path is None:
            return error(404, "file", "no such file in this session's jobs")
        return FileResponse(path, filename=name)

    return router


__all__ = ["Guard", "Signing", "create_app", "default_state_dir", "error_body", "static_dir"]

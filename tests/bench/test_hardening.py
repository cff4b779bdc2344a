"""The bench against hostile or careless requests, through its HTTP API.

Each test states a behaviour the bench keeps: a unit's cost bounded before any job, jobs in
worker processes with limits, cancel, expiry and a quota, bodies counted as they arrive,
cross-site and foreign-host requests refused, sessions issued by the server only, and one
error format for every error, a 500 included.
"""

from __future__ import annotations

import itertools
import json
import logging
import os
import time
from pathlib import Path

import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from pneumorph.bench import create_app
from pneumorph.bench.guard import COOKIE
from pneumorph.bench.jobs import JobLimits
from pneumorph.design.config import to_toml
from pneumorph.errors import StateQuotaError
from pneumorph.geometry.limits import MeshLimitError
from pneumorph.geometry.meshsize import MAX_NODES_3D, check_mesh, estimate_mesh
from pneumorph.geometry.unit import UnitSpec

BASE = "http://127.0.0.1:8000"
SIN = {"target": {"kind": "preset", "name": "sin", "amplitude": 10, "periods": 1}}


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("hardening")


@pytest.fixture(scope="module")
def app(root: Path):  # type: ignore[no-untyped-def]
    return create_app(state_dir=root / "state", cache=root / "cache.sqlite", answer_workers=0,
                      limits=JobLimits(per_session=2, queued=3))


@pytest.fixture()
def client(app) -> TestClient:  # type: ignore[no-untyped-def]
    return TestClient(app, base_url=BASE)


def _error(r) -> dict:  # type: ignore[no-untyped-def]
    body = r.json()
    assert set(body) == {"error"} and set(body["error"]) == {"field", "message"}, body
    return body["error"]


def _wait(client: TestClient, job_id: str, states: tuple[str, ...], timeout: float = 60.0) -> dict:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        job = client.get(f"/api/jobs/{job_id}").json()
        if job["state"] in states:
            return job
        time.sleep(0.1)
    raise AssertionError(f"job {job_id} never reached {states}: {job}")


def _upload(client: TestClient, text: str, model: str = "3d", **headers: str):  # type: ignore[no-untyped-def]
    return client.post("/api/jobs/table", files={"unit": ("u.toml", text.encode())}, data={"model": model},
                       headers=headers)


# -- 1. what a unit may be ------------------------------------------------------------------
def test_a_unit_beyond_the_limits_is_refused_with_its_estimate_before_any_job(client: TestClient) -> None:
    jobs_before = client.get("/api/jobs").json()["jobs"]
    r = _upload(client, "[unit]\npitch = 1e4\n")  # passed every check before, then grew 150 MB/s
    assert r.status_code == 422
    assert _error(r)["field"] == "unit" and "MAX_LENGTH_MM" in _error(r)["message"]
    r = _upload(client, "[unit]\npitch = 240.0\n")  # within the lengths and castable, but its mesh is not
    err = _error(r)
    assert r.status_code == 422 and err["field"] == "unit"
    assert "nodes" in err["message"] and "GB" in err["message"] and "MAX_NODES_3D" in err["message"]
    assert client.get("/api/jobs").json()["jobs"] == jobs_before  # nothing was queued


def test_the_mesh_estimate_is_the_meshs_size_and_the_rule_is_shared() -> None:
    from pneumorph.geometry.assembly import assemble
    from pneumorph.models.factory import make_model

    for spec, units, dim in [(UnitSpec(), 15, 3), (UnitSpec(), 15, 2), (UnitSpec(element_size=1.0, pitch=14.0), 4, 3)]:
        mesh = assemble(spec, "0" * units, dim, half=True)
        estimate = estimate_mesh(spec, units, dim)
        assert len(mesh.points) <= estimate.nodes <= 1.2 * len(mesh.points)  # the cavity cells are counted
    with pytest.raises(MeshLimitError, match="MAX_NODES_3D"):
        check_mesh(UnitSpec(element_size=0.5), 15, 3)
    with pytest.raises(MeshLimitError, match="nodes"):  # the command line's models: the same rule
        make_model(15, {"fidelity": "3d", "unit": {"pitch": 400.0}})
    assert estimate_mesh(UnitSpec(pitch=999.0), 15, 3).nodes > MAX_NODES_3D
    with pytest.raises(MeshLimitError, match="MAX_NAME_CHARS"):
        UnitSpec(name="u" * 500_000)


# -- 2. jobs: in worker processes, cancel, limits, expiry and quota ---------------------------
def test_jobs_run_in_their_own_process_and_the_server_answers_meanwhile(client: TestClient, app) -> None:  # type: ignore[no-untyped-def]
    board = app.state.board
    client.get("/api/jobs")
    job = board.submit(_session(client), "wait", {"seconds": 4})
    _wait(client, job.id, ("running",))
    deadline = time.monotonic() + 5
    while job.process is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert job.process is not None and job.process.pid != os.getpid()
    assert os.getpgid(job.process.pid) == job.process.pid  # a process group of its own
    t = time.perf_counter()
    assert client.post("/api/design", json={**SIN, "top": 3}).status_code == 200
    assert time.perf_counter() - t < 2.0
    done = _wait(client, job.id, ("done", "failed"))
    assert done["state"] == "done" and done["result"] == {"seconds": 4}
    assert client.delete(f"/api/jobs/{job.id}").status_code == 200  # a finished job is deleted
    assert client.get(f"/api/jobs/{job.id}").status_code == 404 and not job.folder.exists()


def _session(client: TestClient) -> str:
    return client.cookies[COOKIE].split(".")[0]


def test_a_running_job_is_cancelled_with_delete_and_its_processes_end(client: TestClient, app) -> None:  # type: ignore[no-untyped-def]
    import psutil

    board = app.state.board
    client.get("/api/jobs")
    job = board.submit(_session(client), "wait", {"seconds": 60})
    _wait(client, job.id, ("running",))
    while job.process is None:
        time.sleep(0.05)
    pid = job.process.pid
    other = TestClient(app, base_url=BASE)
    assert other.delete(f"/api/jobs/{job.id}").status_code == 404  # not another session's to cancel
    t = time.monotonic()
    r = client.delete(f"/api/jobs/{job.id}")
    assert r.status_code == 200 and r.json()["state"] == "cancelled"
    assert time.monotonic() - t < 5
    assert not psutil.pid_exists(pid) or psutil.Process(pid).status() == psutil.STATUS_ZOMBIE
    assert json.loads((job.folder / "job.json").read_text())["state"] == "cancelled"


def test_a_session_may_have_two_jobs_and_the_bench_three(client: TestClient, app) -> None:  # type: ignore[no-untyped-def]
    board = app.state.board
    client.get("/api/jobs")
    mine = [board.submit(_session(client), "wait", {"seconds": 30}) for _ in range(2)]
    r = client.post("/api/jobs", json={"kind": "export", "design": "0" * 15})  # without the limit, 50 would queue
    assert r.status_code == 429 and "jobs-per-session" in _error(r)["message"]
    other = TestClient(app, base_url=BASE)
    other.get("/api/jobs")
    theirs = board.submit(_session(other), "wait", {"seconds": 30})
    third = TestClient(app, base_url=BASE)
    r = third.post("/api/jobs", json={"kind": "export", "design": "0" * 15})
    assert r.status_code == 429 and "max-jobs" in _error(r)["message"]
    for c, j in [(client, mine[1]), (client, mine[0]), (other, theirs)]:
        assert c.delete(f"/api/jobs/{j.id}").json()["state"] == "cancelled"


def test_finished_jobs_expire_and_the_oldest_go_past_the_quota(tmp_path: Path) -> None:
    from pneumorph.bench.answer import Bench
    from pneumorph.bench.jobs import Job, JobBoard

    board = JobBoard(Bench(), tmp_path, tmp_path / "cache.sqlite", limits=JobLimits(expiry_days=1, quota_mb=1.0))
    jobs = []
    for i, age_days in enumerate([3.0, 0.5, 0.4, 0.1]):
        job = Job(f"j{i}", "s", "export", board.root / f"f{i}", {}, "done", created=time.time() - age_days * 86400)
        job.folder.mkdir()
        (job.folder / "files.bin").write_bytes(b"\0" * 400_000)  # 0.4 MB each
        job.save()
        board._jobs[job.id] = job
        jobs.append(job)
    shapes = tmp_path / "shapes"
    shapes.mkdir()
    old, new = shapes / "old.json", shapes / "new.json"
    for path in (old, new):
        path.write_text("{}")
    os.utime(old, (time.time() - 2 * 86400,) * 2)
    used = board.sweep()
    assert "j0" not in board._jobs and not jobs[0].folder.exists()  # older than a day
    assert "j1" not in board._jobs  # the oldest of the rest, to get under 1 MB
    assert {"j2", "j3"} <= set(board._jobs) and used <= 1e6
    assert not old.exists() and new.exists()
    (tmp_path / "units").mkdir()
    (tmp_path / "units" / "big.bin").write_bytes(b"\0" * 2_000_000)  # what no finished job can make room for
    with pytest.raises(StateQuotaError, match="state-quota"):
        board.submit("s", "wait", {"seconds": 0})
    board.close()


# -- 3. bodies: counted as they arrive -------------------------------------------------------
def test_a_body_without_content_length_is_refused_past_the_limit(client: TestClient) -> None:
    def chunks():  # type: ignore[no-untyped-def]
        for _ in range(40):
            yield b" " * 65536
    r = client.post("/api/design", content=chunks(), headers={"content-type": "application/json"})
    assert r.status_code == 413 and _error(r)["field"] == "body"
    r = client.post("/api/jobs/table", files={"unit": ("u.toml", b"#" * (200 * 1024))}, data={"model": "2d"})
    assert r.status_code == 413  # the upload's limit is the unit file's and its form's


# -- 4. cross-site requests and foreign hosts ---------------------------------------------
@pytest.mark.parametrize("headers", [
    {"origin": "http://evil.example"},
    {"origin": "null"},
    {"origin": "http://127.0.0.1:9999"},  # another port is another origin
    {"sec-fetch-site": "cross-site"},
    {"sec-fetch-site": "same-site"},
])
def test_cross_site_requests_may_not_start_work(client: TestClient, headers: dict[str, str]) -> None:
    r = client.post("/api/design", json=SIN, headers=headers)
    assert r.status_code == 403 and _error(r)["field"] == "origin"
    r = client.post("/api/jobs", json={"kind": "export", "design": "0" * 15}, headers=headers)
    assert r.status_code == 403
    r = _upload(client, to_toml({"unit": UnitSpec().to_dict()}), **headers)
    assert r.status_code == 403


def test_only_json_may_start_work(client: TestClient) -> None:
    body = json.dumps({"kind": "export", "design": "0" * 15})
    for kind in ("text/plain", "application/x-www-form-urlencoded", "multipart/form-data; boundary=x", ""):
        r = client.post("/api/jobs", content=body, headers={"content-type": kind})
        assert r.status_code == 415 and _error(r)["field"] == "content-type", kind
    r = client.post("/api/jobs/table", content=b"[unit]\n", headers={"content-type": "application/toml"})
    assert r.status_code == 415
    same = client.post("/api/design", json=SIN, headers={"origin": BASE, "sec-fetch-site": "same-origin"})
    assert same.status_code == 200


def test_only_the_hosts_the_server_was_started_for_are_served(app) -> None:  # type: ignore[no-untyped-def]
    for host in ("evil.example", "evil.example:8000", "127.0.0.1.evil.example"):
        r = TestClient(app, base_url=f"http://{host}").get("/api/info")
        assert r.status_code == 400 and _error(r)["field"] == "host"
    for host in ("localhost:8000", "127.0.0.1", "[::1]:8000"):
        assert TestClient(app, base_url=f"http://{host}").get("/api/jobs").status_code == 200


# -- 5. sessions and units ---------------------------------------------------------------------
def test_sessions_are_issued_by_the_server_only(app) -> None:  # type: ignore[no-untyped-def]
    chosen = "0123456789abcdef0123456789abcdef"
    c = TestClient(app, base_url=BASE, cookies={COOKIE: chosen})
    r = c.get("/api/jobs")
    issued = r.cookies.get(COOKIE)
    assert issued and issued != chosen and issued.split(".")[0] != chosen  # a fixed id is not taken
    again = TestClient(app, base_url=BASE, cookies={COOKIE: issued})
    assert COOKIE not in again.get("/api/jobs").cookies  # a signed one is kept
    forged = issued.split(".")[0] + "." + "A" * 27
    assert COOKIE in TestClient(app, base_url=BASE, cookies={COOKIE: forged}).get("/api/jobs").cookies


def test_a_malformed_neighbouring_cookie_keeps_the_session(client: TestClient, app) -> None:  # type: ignore[no-untyped-def]
    client.get("/api/jobs")
    value = client.cookies[COOKIE]
    job = app.state.board.submit(_session(client), "wait", {"seconds": 0.5})
    raw = TestClient(app, base_url=BASE)
    r = raw.get("/api/jobs", headers={"cookie": f'theme="dark; {COOKIE}={value}; x=\\q'})
    assert COOKIE not in r.cookies
    assert job.id in [j["id"] for j in r.json()["jobs"]]
    _wait(client, job.id, ("done", "failed"))


def test_uploaded_units_are_their_sessions_and_their_ids_are_random(client: TestClient, app) -> None:  # type: ignore[no-untyped-def]
    from pneumorph.bench.jobs import Job

    board, bench = app.state.board, app.state.bench
    client.get("/api/jobs")
    spec = UnitSpec(layer=2.5)
    unit_id = bench.add_unit(spec)
    assert unit_id != bench.add_unit(spec) and len(unit_id) == 17  # no hash of the parameters to guess
    job = Job("t" * 32, _session(client), "table", board.root / "t", {}, "done",
              result={"unit_id": unit_id, "name": spec.name, "model": "2d", "window": 2, "centre_worst_mm": 0.1})
    job.folder.mkdir()
    board._jobs[job.id] = job
    body = {**SIN, "model": "2d", "unit": unit_id}
    # its session may name it (no table yet: the model is what is missing), another may not
    assert _error(client.post("/api/design", json=body))["field"] == "model"
    other = TestClient(app, base_url=BASE)
    assert _error(other.post("/api/design", json=body))["field"] == "unit"
    assert _error(other.post("/api/jobs", json={"kind": "export", "design": "0" * 15, "unit": unit_id}))["field"] \
        == "unit"
    assert unit_id in [u["id"] for u in client.get("/api/units").json()["units"]]
    assert unit_id not in [u["id"] for u in other.get("/api/units").json()["units"]]


# -- 6. one error format, no 500 -------------------------------------------------------------
@pytest.mark.parametrize(("method", "path", "status", "field"), [
    ("GET", "/api/nothing", 404, "path"),
    ("GET", "/api/design", 405, "method"),
    ("GET", "/api/shape?design=001111010001001", 422, "level"),
    ("GET", "/api/shape?design=001111010001001&level=abc", 422, "level"),
    ("GET", "/api/jobs/nope", 404, "job"),
])
def test_framework_errors_are_in_the_benchs_format(client: TestClient, method: str, path: str, status: int,
                                                    field: str) -> None:
    r = client.request(method, path)
    assert r.status_code == status
    assert _error(r)["field"] == field


@pytest.mark.parametrize(("body", "field"), [
    ({"target": {"kind": "tip", "goal": ["max-x"]}}, "goal"),
    ({"target": {"kind": "tip", "goal": {"a": 1}}}, "goal"),
    ({"target": {"kind": "preset", "name": ["sin"]}}, "preset"),
    ({"target": {"kind": ["preset"]}}, "target"),
    ({"target": SIN["target"], "model": {"3d": 1}}, "model"),
    ({"target": {"kind": "preset", "name": "sin", "amplitude": 10**400}}, "amplitude"),
    ({"target": {"kind": "curve", "points": [[0, 0], [10**400, 1], [150, 2]]}}, "points"),
    ({"target": {"kind": "expression", "expression": "y = " + "9" * 400}}, "expression"),
    ({"target": {"kind": "expression", "expression": "y = 1e100"}}, "expression"),
    ({"target": {"kind": "expression", "expression": "y = 2e5"}}, "expression"),
    ({"target": SIN["target"], "top": 10**400}, "top"),
    ({**SIN, "unit": "u" * 500_000}, "unit"),
])
def test_inputs_that_were_500s_are_field_errors(client: TestClient, body: object, field: str) -> None:
    r = client.post("/api/design", json=body)
    assert r.status_code == 422, r.text[:300]
    assert _error(r)["field"] == field and len(_error(r)["message"]) <= 500


@pytest.mark.parametrize("raw", [
    b"[" * 100_000 + b"]" * 100_000,
    b'{"target": ' + b"[" * 5000 + b"]" * 5000 + b"}",
    b'{"target": {"kind": "preset", "amplitude": ' + b"1" * 5000 + b"}}",
])
def test_deep_or_huge_json_is_a_field_error(client: TestClient, raw: bytes) -> None:
    r = client.post("/api/design", content=raw, headers={"content-type": "application/json"})
    assert r.status_code == 422 and _error(r)["field"] in ("target", "amplitude"), r.text[:200]
    r = client.post("/api/jobs", content=raw, headers={"content-type": "application/json"})
    assert r.status_code == 422 and _error(r)["field"] in ("target", "kind"), r.text[:200]


def test_a_deeply_nested_toml_upload_is_a_field_error(client: TestClient) -> None:
    r = _upload(client, "[unit]\nname = " + "[" * 20_000 + "]" * 20_000 + "\n")
    assert r.status_code == 422 and _error(r)["field"] == "unit"


def test_a_500_is_in_the_format_and_logs_neither_the_body_nor_more_than_a_line(app, root: Path,
                                                                            caplog: pytest.LogCaptureFixture,
                                                                            monkeypatch: pytest.MonkeyPatch) -> None:  # type: ignore[no-untyped-def]
    bench = app.state.bench

    def broken(body, units=None):  # type: ignore[no-untyped-def]
        raise RuntimeError("a fault of the bench")

    monkeypatch.setattr(bench, "parse", broken)
    secret = "S" * 500_000
    with caplog.at_level(logging.INFO, logger="pneumorph.bench"):
        r = TestClient(app, base_url=BASE, raise_server_exceptions=False).post(
            "/api/design", json={**SIN, "note": secret})
    assert r.status_code == 500 and _error(r)["field"] == "server"
    logged = "\n".join(rec.getMessage() for rec in caplog.records)
    assert "a fault of the bench" in logged and "SSSS" not in logged and len(logged) < 2000


def test_a_client_that_goes_away_is_one_log_line_without_traceback(app, caplog: pytest.LogCaptureFixture) -> None:  # type: ignore[no-untyped-def]
    import asyncio

    sent: list[dict] = []

    async def receive():  # type: ignore[no-untyped-def]
        return {"type": "http.disconnect"}

    async def send(message):  # type: ignore[no-untyped-def]
        sent.append(message)

    scope = {"type": "http", "asgi": {"version": "3.0"}, "http_version": "1.1", "method": "POST",
             "scheme": "http", "path": "/api/design", "raw_path": b"/api/design", "query_string": b"",
             "headers": [(b"host", b"127.0.0.1:8000"), (b"content-type", b"application/json")],
             "client": ("127.0.0.1", 5), "server": ("127.0.0.1", 8000), "root_path": "", "state": {}}
    with caplog.at_level(logging.INFO, logger="pneumorph.bench"):
        asyncio.run(app(scope, receive, send))
    records = [r for r in caplog.records if r.name == "pneumorph.bench"]
    assert len(records) == 1 and "went away" in records[0].getMessage() and records[0].exc_info is None


# -- 6. progress that follows the work -----------------------------------------------------------
def test_a_table_jobs_progress_follows_its_solves() -> None:
    from pneumorph.bench.worker import TableProgress
    from pneumorph.models.chain.plan import build_plan
    from pneumorph.models.factory import make_model

    plan = build_plan(make_model(15, {"fidelity": "2d", "unit": {"layer": 2.5}}))
    progress = TableProgress(plan.solves)
    n = plan.covering[0]
    seen = [progress(f"window +-{plan.windows[0]}: {n} covering designs")]
    seen += [progress(f"  covering: {i}/{n} solved (solved d, 3 s)") for i in range(1, n + 1)]
    # window +-1 has 2 covering designs of 22 solves: 0.95 after them (2/2 covering) would overstate it
    assert seen[2] == pytest.approx(0.02 + 0.95 * 2 / plan.solves[0], abs=1e-3) and seen[2] < 0.15
    assert seen[n] == pytest.approx(0.02 + 0.95 * n / plan.solves[0], abs=1e-3)
    held = [progress(f"  held-out: {i}/{plan.heldout} solved") for i in range(1, plan.heldout + 1)]
    assert held[-1] == pytest.approx(0.97) and all(a < b for a, b in itertools.pairwise(held))

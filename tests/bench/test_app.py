"""The bench's JSON API: answers equal the certified search's, bad input is a field error, jobs are private."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from pneumorph.bench import Bench, create_app, parse_query
from pneumorph.bench.shapes import chain_placement
from pneumorph.design.certified.search import chain_scores
from pneumorph.design.objectives.targets import make_objective
from pneumorph.geometry.assembly import assemble

SIN = {"target": {"kind": "preset", "name": "sin", "amplitude": 10, "periods": 1}}
BASE = "http://127.0.0.1:8000"  # a host the bench serves (its loopback names)


@pytest.fixture(scope="module")
def state(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("bench")


@pytest.fixture(scope="module")
def app(state: Path):  # type: ignore[no-untyped-def]
    return create_app(state_dir=state / "state", cache=state / "cache.sqlite")


@pytest.fixture()
def client(app) -> TestClient:  # type: ignore[no-untyped-def]
    return TestClient(app, base_url=BASE)


def test_default_answer_is_the_design_commands_certified_optimum(client: TestClient) -> None:
    a = client.post("/api/design", json=SIN).json()
    # docs/chain-model.md: the main job's winner, chain value 7.405 mm at 36 kPa, bound 0.036 mm
    assert a["winner"]["design"] == "001111010001001"
    assert a["winner"]["value"] == pytest.approx(7.405, abs=5e-4)
    assert a["winner"]["pressure_kpa"] == pytest.approx(36.0)
    assert a["certificate"]["bound"] == pytest.approx(0.036, abs=5e-4)
    assert a["certificate"]["designs"] == 2**15 and 10 <= a["certificate"]["scored"] <= 2**15
    assert [r["rank"] for r in a["top"]] == list(range(1, 11))
    values = [r["value"] for r in a["top"]]
    assert values == sorted(values) and values[0] == a["winner"]["value"]
    assert a["top"][1]["value"] > a["top"][0]["optimistic"]
    assert len(a["profiles"]) == len(a["pressures_kpa"]) == 10
    assert len(a["profiles"][0]) == 17  # base, 15 centres, tip
    assert a["target"]["y"][50] == pytest.approx(10.0)  # A sin(2 pi x / L) at x = L/4


def test_the_certificate_counts_every_design_that_could_still_win() -> None:
    bench = Bench()
    q = parse_query({"target": {"kind": "preset", "name": "cos", "amplitude": 20}}, bench.length("3d"))
    a = bench.answer(q)
    chain = bench.chain("3d")
    s = chain_scores(chain, make_objective("cos", 20.0, length=chain.length))
    best = int(np.argmin(s.cost))
    worst_case = s.cost[best] + s.bound[best]
    assert a["certificate"]["candidates"] == int((s.optimistic < worst_case).sum()) >= 1
    assert a["winner"]["value"] == pytest.approx(float(s.cost[best]))


def test_a_drawn_sin_gets_the_presets_answer(client: TestClient) -> None:
    x = np.linspace(0.0, 157.5, 120)
    rng = np.random.default_rng(0)
    stroke = np.c_[x, 10 * np.sin(2 * np.pi * x / 157.5) + rng.normal(0.0, 0.3, x.size)]
    a = client.post("/api/design", json={"target": {"kind": "curve", "points": stroke.tolist()}}).json()
    assert a["winner"]["design"] == "001111010001001"
    # Eq 4.1 is a 2-norm over 15 centres: the drawn target moves it by at most sqrt(15) times
    # the largest gap between the smoothed stroke and the sin
    drawn = np.interp(x, a["target"]["x"], a["target"]["y"])
    gap = np.abs(drawn - 10 * np.sin(2 * np.pi * x / 157.5)).max()
    assert gap < 0.5
    assert abs(a["winner"]["value"] - 7.405) <= np.sqrt(15) * gap + 5e-4


STAGES = {"target": {"kind": "stages", "stages": [
    {"pressure_kpa": 18, "target": {"kind": "expression", "expression": "y = 0.05*x"}},
    {"pressure_kpa": 45, "target": {"kind": "preset", "name": "sin", "amplitude": 10}, "weight": 2}]}, "model": "2d"}


def test_stages_get_the_certified_search_of_their_staged_target(client: TestClient) -> None:
    """A target at each of two pressures: the answer is the chain search's optimum of the staged target, with each
    stage's target and level for the page to draw over the ramp."""
    a = client.post("/api/design", json=STAGES).json()
    bench = Bench()
    chain = bench.chain("2d")
    objective = bench.parse(STAGES).objective(chain.length)
    scores = chain_scores(chain, objective)
    best = scores.order()[0]
    assert a["winner"]["design"] == chain.table.texts(scores.bits[[best]])[0]
    assert a["winner"]["value"] == pytest.approx(float(scores.cost[best]), abs=1e-9)
    assert a["winner"]["pressure_kpa"] == pytest.approx(45.0) and a["target"] is None
    assert [(s["pressure_kpa"], s["level"], s["weight"]) for s in a["stages"]] == [(18.0, 3, 1.0), (45.0, 9, 2.0)]
    assert a["stages"][0]["target"]["y"][-1] == pytest.approx(0.05 * 157.5)
    assert len(a["profiles"]) == 10  # the whole ramp


@pytest.mark.parametrize(("stages", "message"), [
    ([{"pressure_kpa": 20, "target": {"kind": "preset", "name": "sin"}}],
     "not a level of the model's ramp; the levels"),
    ([{"pressure_kpa": 18, "target": {"kind": "tip", "goal": "max-x"}}], "is a maximum"),
    ([{"target": {"kind": "preset", "name": "sin"}}], "pressure_kpa"),
    ([{"pressure_kpa": 18, "target": {"kind": "stages"}}], "target kind"),
    ([{"pressure_kpa": 18, "target": {"kind": "preset", "name": "sin"}},
      {"pressure_kpa": 18, "target": {"kind": "preset", "name": "cos"}}], "two stages"),
    ("18:sin", "list of 1 to"),
])
def test_bad_stages_are_a_stages_error(client: TestClient, stages: object, message: str) -> None:
    r = client.post("/api/design", json={"target": {"kind": "stages", "stages": stages}})
    assert r.status_code == 422
    err = r.json()["error"]
    assert err["field"] == "stages" and message in err["message"] and "\n" not in err["message"]


def test_answers_are_remembered(client: TestClient) -> None:
    body = {"target": {"kind": "preset", "name": "sin", "amplitude": 12.5}}
    first = client.post("/api/design", json=body).json()
    again = client.post("/api/design", json=body).json()
    assert not first["memo"] and again["memo"]
    assert again["winner"] == first["winner"] and again["query_id"] == first["query_id"]


@pytest.mark.parametrize(("body", "field"), [
    ({"target": {"kind": "expression", "expression": "y = __import__('os').system('true')"}}, "expression"),
    ({"target": {"kind": "expression", "expression": "y = 1/x"}}, "expression"),
    ({"target": {"kind": "expression", "expression": ""}}, "expression"),
    ({"target": {"kind": "preset", "name": "sin", "amplitude": -1}}, "amplitude"),
    ({"target": {"kind": "preset", "name": "sin", "amplitude": "ten"}}, "amplitude"),
    ({"target": {"kind": "preset", "name": "sin", "periods": 0}}, "periods"),
    ({"target": {"kind": "preset", "name": "tan"}}, "preset"),
    ({"target": {"kind": "tip", "goal": "reach"}}, "point"),
    ({"target": {"kind": "tip", "goal": "max-z"}}, "goal"),
    ({"target": {"kind": "curve", "points": [[0, 0], [10, 1]]}}, "points"),
    ({"target": {"kind": "curve", "points": [[0, 0], [100, "nan"]]}}, "points"),
    ({"target": {"kind": "curve", "points": "a line"}}, "points"),
    ({"target": {"kind": "spline"}}, "target"),
    ({"target": SIN["target"], "model": "4d"}, "model"),
    ({"target": SIN["target"], "top": 0}, "top"),
    ([1, 2], "target"),
])
def test_bad_input_is_a_field_error(client: TestClient, body: object, field: str) -> None:
    r = client.post("/api/design", json=body)
    assert r.status_code == 422
    err = r.json()["error"]
    assert err["field"] == field and err["message"] and "\n" not in err["message"]


def test_malformed_and_oversized_requests(client: TestClient) -> None:
    r = client.post("/api/design", content=b"{not json", headers={"content-type": "application/json"})
    assert r.status_code == 422 and r.json()["error"]["field"] == "target"
    r = client.post("/api/design", content=b"[" + b"0," * (1 << 20) + b"0]",
                    headers={"content-type": "application/json"})
    assert r.status_code == 413
    assert client.get("/api/shape", params={"design": "0120", "level": 1}).json()["error"]["field"] == "design"
    assert client.get("/api/shape", params={"design": "0" * 15, "level": 10}).json()["error"]["field"] == "level"


def test_the_chain_view_puts_the_units_on_the_predicted_centres() -> None:
    bench = Bench()
    design = "001111010001001"
    response = bench.chain("3d").evaluate(design)
    mesh = assemble(bench.model("3d").unit, design, 3, half=True)
    for level in (0, 7, 9):
        x = chain_placement(mesh, response, level)
        centres = mesh.unit_centres(x - mesh.points)
        assert np.abs(centres - response.centres[level]).max() < 0.5  # mm, against curls up to 300 degrees


def test_the_shape_endpoint_gives_a_closed_triangle_surface(client: TestClient) -> None:
    s = client.get("/api/shape", params={"design": "001111010001001", "level": 7}).json()
    assert s["source"] == "chain"
    pos = np.reshape(s["positions"], (-1, 3))
    tri = np.reshape(s["indices"], (-1, 3))
    assert tri.max() < len(pos) and tri.min() >= 0
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert (counts == 2).all()  # every edge shared by two triangles: watertight, both halves joined
    assert pos[:, 2].min() == pytest.approx(0.0) and pos[:, 2].max() == pytest.approx(15.0)


def _wait(client: TestClient, job_id: str, timeout: float = 120.0) -> dict:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        job = client.get(f"/api/jobs/{job_id}").json()
        if job["state"] in ("done", "failed"):
            return job
        time.sleep(0.2)
    raise AssertionError(f"job {job_id} did not finish in {timeout} s")


def test_verification_runs_the_design_command_and_is_private(client: TestClient, app, state: Path) -> None:  # type: ignore[no-untyped-def]
    body = {"kind": "verify", "query": {**SIN, "model": "2d"}}
    r = client.post("/api/jobs", json=body)
    assert r.status_code == 202
    job = _wait(client, r.json()["job_id"])
    assert job["state"] == "done", job["message"]
    res = job["result"]
    # docs/chain-model.md: the 2D model's optimum for the default target is 001111010001000
    assert res["design"] == "001111010001000" and res["model"] == "2d"
    assert res["fe_value"] == pytest.approx(res["chain_value"], abs=0.3)
    names = {f["name"] for f in job["files"]}
    assert {"report.md", "run.zip", "certificate.json", "profile.png"} <= names
    report = client.get(f"/api/jobs/{job['id']}/files/report.md")
    assert report.status_code == 200 and "001111010001000" in report.text
    # another browser session sees none of it
    other = TestClient(app, base_url=BASE)
    assert other.get("/api/jobs").json()["jobs"] == []
    assert other.get(f"/api/jobs/{job['id']}").status_code == 404
    assert other.get(f"/api/jobs/{job['id']}/files/report.md").status_code == 404
    assert client.get(f"/api/jobs/{job['id']}/files/..%2Fjob.json").status_code == 404
    # a restarted server lists the finished job again
    again = TestClient(create_app(state_dir=state / "state", cache=state / "cache.sqlite"), base_url=BASE,
                       cookies={"pneumorph_session": client.cookies["pneumorph_session"]})
    assert [j["id"] for j in again.get("/api/jobs").json()["jobs"]] == [job["id"]]


@pytest.mark.slow
def test_a_staged_verification_runs_the_design_command_with_its_stages(client: TestClient) -> None:
    r = client.post("/api/jobs", json={"kind": "verify", "query": STAGES})
    assert r.status_code == 202
    job = _wait(client, r.json()["job_id"])
    assert job["state"] == "done", job["message"]
    answer = client.post("/api/design", json=STAGES).json()
    assert job["result"]["design"] == answer["winner"]["design"]
    assert job["result"]["fe_value"] == pytest.approx(answer["winner"]["value"], abs=0.3)
    report = client.get(f"/api/jobs/{job['id']}/files/report.md")
    assert report.status_code == 200 and "18 kPa" in report.text


def test_a_bad_job_is_refused(client: TestClient) -> None:
    assert client.post("/api/jobs", json={"kind": "mine"}).json()["error"]["field"] == "kind"
    assert client.post("/api/jobs", json={"kind": "export", "design": "012"}).json()["error"]["field"] == "design"
    r = client.post("/api/jobs", json={"kind": "verify", "query": {"target": {"kind": "preset", "name": "x"}}})
    assert r.status_code == 422 and r.json()["error"]["field"] == "preset"


def test_the_page_and_its_assets_are_served_from_the_package(client: TestClient) -> None:
    page = client.get("/")
    assert page.status_code == 200 and "<html" in page.text.lower()
    for ref in ("/static/app.js", "/static/style.css"):
        assert client.get(ref).status_code == 200
    assert "http://" not in page.text and "https://" not in page.text  # nothing fetched from the network


def test_units_can_be_uploaded_and_bad_unit_files_are_refused(client: TestClient) -> None:
    from pneumorph.design.config import to_toml
    from pneumorph.geometry.unit import UnitSpec

    def upload(content: bytes, model: str = "2d") -> dict:
        r = client.post("/api/jobs/table", files={"unit": ("u.toml", content)}, data={"model": model})
        return {"status": r.status_code, **r.json()}

    for content, words in [(b"\xff\xff", "not UTF-8 text: byte 0xff at line 1, column 1"), (b"[unit\n", "TOML"),
                           (b"pitch = 1\n", "[unit] table"),
                           (b"[unit]\nflux = 1\n", "unknown unit parameter"), (b"[unit]\npitch = -1\n", "pitch"),
                           (b"#" * (65 * 1024), "at most 64 kB")]:
        r = upload(content)
        assert r["status"] == 422 and r["error"]["field"] == "unit" and words in r["error"]["message"], r
    assert upload(b"[unit]\n", model="1d")["error"]["field"] == "model"
    # the built-in unit's parameters: its shipped table is found at once
    r = upload(to_toml({"unit": UnitSpec().to_dict()}).encode())
    job = _wait(client, r["job_id"], timeout=60)
    assert job["state"] == "done", job["message"]
    assert job["result"]["unit_id"] == "builtin" and job["result"]["window"] >= 1
    assert job["result"]["centre_worst_mm"] < 0.2  # the table's held-out tolerance (docs/chain-model.md)
    assert client.post("/api/design", json={**SIN, "unit": "u0123"}).json()["error"]["field"] == "unit"


def test_a_byte_order_mark_before_an_upload_reads_as_without(client: TestClient) -> None:
    """An editor's UTF-8 byte-order mark before a unit file or a request's JSON is not part of it: the same unit,
    the same answer."""
    import json

    from pneumorph.bench.app import read_unit
    from pneumorph.bench.query import load_json
    from pneumorph.design.config import to_toml
    from pneumorph.geometry.unit import UnitSpec

    unit = to_toml({"unit": {**UnitSpec().to_dict(), "pitch": 7.5}}).encode()
    assert read_unit(b"\xef\xbb\xbf" + unit) == read_unit(unit) and read_unit(unit).pitch == 7.5
    text = json.dumps(SIN)
    assert load_json("\ufeff" + text) == load_json(text.encode()) == SIN
    plain = client.post("/api/design", content=text.encode(), headers={"Content-Type": "application/json"})
    marked = client.post("/api/design", content=b"\xef\xbb\xbf" + text.encode(),
                         headers={"Content-Type": "application/json"})
    assert plain.status_code == marked.status_code == 200
    timing = {"elapsed_ms", "memo"}  # how the answer was served, not what it is (the second from the memo)
    assert {k: v for k, v in marked.json().items() if k not in timing} == \
        {k: v for k, v in plain.json().items() if k not in timing}


def test_export_zips_the_parts_the_mould_and_the_deck(client: TestClient) -> None:
    import io
    import zipfile

    import trimesh

    design = "001111010001001"
    job = _wait(client, client.post("/api/jobs", json={"kind": "export", "design": design}).json()["job_id"])
    assert job["state"] == "done", job["message"]
    assert job["result"]["mould_parts"] == 22  # docs/manufacturing.md
    data = client.get(f"/api/jobs/{job['id']}/files/export-{design}.zip").content
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        names = set(z.namelist())
        assert {"parts/body.stl", "parts/base_block.stl", f"{design}.inp", "mould/mould.png"} <= names
        body = trimesh.load(io.BytesIO(z.read("parts/body.stl")), file_type="stl")
        deck = z.read(f"{design}.inp").decode()
    assert body.is_watertight
    assert "*NODE" in deck.upper() and "C3D20" in deck.upper()


def test_answers_from_worker_processes_equal_answers_computed_here(state: Path) -> None:
    app = create_app(state_dir=state / "pool", cache=state / "cache.sqlite", answer_workers=1)
    body = {"target": {"kind": "expression", "expression": "y = 0.2*x", "amplitude": 1}, "model": "2d"}
    with TestClient(app, base_url=BASE) as c:  # the lifespan starts the worker
        remote = c.post("/api/design", json=body).json()
        assert c.post("/api/design", json={**body, "unit": "u99"}).json()["error"]["field"] == "unit"
    bench = Bench()
    here = bench.compute(bench.parse(body))
    assert remote["winner"] == here["winner"] and remote["top"] == here["top"]
    assert remote["certificate"] == here["certificate"]


def test_an_fe_shape_is_the_solved_surface_at_every_level() -> None:
    from pneumorph.bench.jobs import fe_solve_shape
    from pneumorph.models.factory import make_model

    model = make_model(2, {"fidelity": "3d", "pressure_kpa": 20})
    response, shape, wall = fe_solve_shape(model, "01")
    assert response is not None and response.converged and wall > 0
    assert len(shape["levels"]) == len(model.pressures())
    tri = np.reshape(shape["indices"], (-1, 3))
    for level, tip in zip(shape["levels"], response.tip, strict=False):
        pos = np.reshape(level["positions"], (-1, 3))
        assert tri.max() < len(pos)
        lo, hi = np.array(level["bounds"])
        assert np.all(tip >= lo[:2] - 1e-6) and np.all(tip <= hi[:2] + 1e-6)  # the tip is on the surface's box
    assert np.reshape(shape["levels"][-1]["positions"], (-1, 3))[:, 2].max() > 15.0  # the side walls balloon


def test_an_identified_model_is_under_every_answer_and_job(tmp_path: Path) -> None:
    """serve --model-file: the bench's models carry the file's settings (its unit, its material scales), a verify
    job's design run too; without a table of that model the answer says how to build it."""
    from pneumorph.bench.query import Query
    from pneumorph.models.factory import make_model

    identified = {"fidelity": "2d", "body_shear_scale": 0.9, "unit": {"wall": 1.6}}
    bench = Bench(settings=identified, table_dir=tmp_path / "tables")
    assert bench.model("2d").fingerprint() == make_model(15, identified).fingerprint()
    assert bench.model("3d").fingerprint() == make_model(15, {**identified, "fidelity": "3d"}).fingerprint()
    config = Query("preset", "sin", model="3d").config(15, bench.model_settings("3d"))
    assert config.make_model().fingerprint() == bench.model("3d").fingerprint()  # the verify job's run
    uploaded = bench.add_unit(make_model(1, {"unit": {"layer": 2.5}}).unit)
    assert bench.model_settings("2d", uploaded) == {"fidelity": "2d", "body_shear_scale": 0.9,
                                                    "unit": bench.unit_spec(uploaded).to_dict()}
    client = TestClient(create_app(state_dir=tmp_path / "state", cache=tmp_path / "cache.sqlite", answer_workers=0,
                                   model_settings=identified), base_url=BASE)
    error = client.post("/api/design", json={**SIN, "model": "2d"}).json()["error"]
    assert error["field"] == "model" and "pneumorph design --model-file FILE --model 2d" in error["message"]


def test_serve_refuses_a_bad_model_file_before_it_starts(tmp_path: Path) -> None:
    from click.testing import CliRunner

    from pneumorph.cli import cli

    bad = tmp_path / "identified.toml"
    bad.write_text("[model]\nbody_bulk_scale = 5000\n")
    done = CliRunner().invoke(cli, ["serve", "--model-file", str(bad), "--state", str(tmp_path / "s")])
    assert done.exit_code == 2 and "body_bulk_scale" in done.output and "Traceback" not in done.output
    assert not (tmp_path / "s").exists()


def test_a_space_curve_answers_with_its_view_from_above(client: TestClient) -> None:
    """A helix (radius A about an axis along x through (0, A, 0)): its target samples carry z = -A sin(2 pi x / L),
    y = A (1 - cos(2 pi x / L)); a planar target has no z."""
    r = client.post("/api/design", json={"target": {"kind": "preset", "name": "helix", "amplitude": 20}})
    assert r.status_code == 200, r.text
    a = r.json()
    x, y, z = (np.array(a["target"][k]) for k in ("x", "y", "z"))
    phase = 2 * np.pi * x / a["length_mm"]
    assert np.abs(z + 20 * np.sin(phase)).max() < 1e-3 and np.abs(y - 20 * (1 - np.cos(phase))).max() < 1e-3
    assert "z" not in client.post("/api/design", json=SIN).json()["target"]


def test_a_curve_drawn_in_two_views_is_a_space_curve(client: TestClient) -> None:
    """The side view (x, y) and the view from above (x, z), each a smoothed stroke: the target's z at the side view's
    knots is the stroke from above; Eq 4.1 counts it (the planar winner's value grows by the z terms)."""
    x = np.linspace(0.0, 157.5, 120)
    side = np.c_[x, 10 * np.sin(2 * np.pi * x / 157.5)]
    above = np.c_[x, -0.05 * x]  # a straight line: smoothing keeps it, so z = -0.05 x at every knot
    a = client.post("/api/design", json={"target": {"kind": "curve", "points": side.tolist(),
                                                    "top_points": above.tolist()}}).json()
    tx, tz = np.array(a["target"]["x"]), np.array(a["target"]["z"])
    assert np.abs(tz + 0.05 * tx).max() < 1e-3
    flat = client.post("/api/design", json={"target": {"kind": "curve", "points": side.tolist()}}).json()
    assert "z" not in flat["target"] and a["winner"]["value"] > flat["winner"]["value"] + 5.0
    r = client.post("/api/design", json={"target": {"kind": "curve", "points": side.tolist(), "top_points": [[0, 1]]}})
    assert r.status_code == 422 and "seen from above" in r.text and r.json()["error"]["field"] == "points"

"""Paths on the bench: a drawn stroke that turns back is a path, explicit paths and presets, their answers and
errors; a graph stroke answers as before."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from pneumorph.bench import Bench, create_app
from pneumorph.bench.query import Query
from pneumorph.bench.strokes import is_path_stroke, smooth_path
from pneumorph.design.certified.search import chain_scores
from pneumorph.design.objectives.fitness import path_errors
from pneumorph.design.objectives.targets import smooth_curve

BASE = "http://127.0.0.1:8000"
L = 157.5


def hook(run: float = 62.0, radius: float = 34.0, turn: float = 200.0, noise: float = 0.2) -> np.ndarray:
    """A hand-drawn hook in the profile frame (y above the axis): a straight run along the axis, then an arc of
    ``turn`` degrees curling up and back past vertical; a jitter of ``noise`` mm."""
    run_x = np.linspace(0.0, run, 60)
    theta = np.radians(np.linspace(0.0, turn, 90))[1:]
    p = np.r_[np.c_[run_x, 0 * run_x], np.c_[run + radius * np.sin(theta), radius * (1 - np.cos(theta))]]
    return np.round(p + np.random.default_rng(1).normal(0.0, noise, p.shape), 3)


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> TestClient:
    root = tmp_path_factory.mktemp("paths")
    return TestClient(create_app(state_dir=root / "state", cache=root / "cache.sqlite"), base_url=BASE)


@pytest.fixture(scope="module")
def bench() -> Bench:
    return Bench()


def _check_path_answer(a: dict, bench: Bench, body: dict) -> None:
    """The answer's value is the path's error of the winner's chain centres, its centrelines are those centres (with
    the base on the axis and the tip), and the winner is the certified search's."""
    chain = bench.chain(body.get("model", "3d"))
    objective = bench.parse(body).objective(chain.length)
    placed = objective.at(chain.length, 6.0)
    assert np.abs(placed.polyline()[:, :2] - np.c_[a["path"]["x"], a["path"]["y"]]).max() < 1e-4
    scores = chain_scores(chain, objective)
    best = scores.order()[0]
    assert a["winner"]["design"] == chain.table.texts(scores.bits[[best]])[0]
    response = chain.evaluate(a["winner"]["design"])
    level = a["winner"]["level"]
    assert a["winner"]["value"] == pytest.approx(float(path_errors(response, objective)[level]), abs=1e-9)
    lines = np.array(a["centrelines"])
    assert lines.shape == (10, 17, 2)
    assert np.abs(lines[:, 1:-1] - response.centres).max() < 1e-4  # as the model reports them: not heights
    assert np.abs(lines[:, -1] - response.tip).max() < 1e-4 and lines[0, 0].tolist() == [0.0, a["axis_mm"]]


def test_a_drawn_hook_is_a_path_in_the_centres_frame(client: TestClient, bench: Bench) -> None:
    stroke = hook()
    assert is_path_stroke(stroke)
    body = {"target": {"kind": "curve", "points": stroke.tolist()}}
    a = client.post("/api/design", json=body).json()
    assert a["label"].startswith("path: path through") and a["target"] is None and a["axis_mm"] == 6.0
    path = np.c_[a["path"]["x"], a["path"]["y"]]
    # smoothed along its arc length, lifted by the axis's height: it starts where the stroke does, on the axis
    assert np.abs(path - smooth_path(stroke, L, 6.0)).max() < 1e-4
    assert path[0].tolist() == [stroke[0, 0], stroke[0, 1] + 6.0] and path[:, 0].max() - path[-1, 0] > 40.0
    _check_path_answer(a, bench, body)
    # the preset it was drawn after (shank 0.34, radius 0.19 of 1.15 L) gets the preset's design
    preset_body = {"target": {"kind": "path", "preset": "hook"}}
    preset = client.post("/api/design", json=preset_body).json()
    assert a["winner"]["design"] == preset["winner"]["design"] == "101000000000001"
    assert a["winner"]["value"] == pytest.approx(22.8, abs=0.5) and preset["winner"]["value"] == pytest.approx(21.743,
                                                                                                             abs=1e-3)
    _check_path_answer(preset, bench, preset_body)
    lines = np.array(client.get("/api/profiles", params={"design": "011100000000001"}).json()["centrelines"])
    assert np.abs(lines[:, 1:-1] - bench.chain("3d").evaluate("011100000000001").centres).max() < 1e-4


def test_a_graph_stroke_answers_as_a_curve_as_before(client: TestClient) -> None:
    """A hook that stops before turning back (a quarter arc), or a sin with jitter in x too, is a graph: its
    knots are smooth_curve's, as before paths."""
    for stroke in (hook(turn=80.0), np.c_[np.linspace(0, L, 120) + np.random.default_rng(2).normal(0, 0.3, 120),
                                          10 * np.sin(2 * np.pi * np.linspace(0, L, 120) / L)]):
        assert not is_path_stroke(stroke)
        body = {"target": {"kind": "curve", "points": stroke.tolist()}}
        a = client.post("/api/design", json=body).json()
        assert a["label"].startswith("curve") and a["path"] is None and a["centrelines"] is None
        knots = np.round(smooth_curve(stroke, L), 6)
        q = Bench().parse(body)
        assert q.spec == "curve" and q.path is None and q.curve == tuple((float(x), float(y)) for x, y in knots)
    assert a["winner"]["design"] == "001111010001001"  # the sin's (docs/bench.md)


def test_an_explicit_path_in_the_plane_and_in_space(client: TestClient, bench: Bench) -> None:
    body = {"target": {"kind": "path", "points": [[0, 6], [90, 6], [90, 6], [120, 40]]}, "model": "2d"}
    a = client.post("/api/design", json=body).json()
    assert (a["path"]["x"], a["path"]["y"]) == ([0.0, 90.0, 120.0], [6.0, 6.0, 40.0])  # as given, repeat dropped
    assert "z" not in a["path"]
    _check_path_answer(a, bench, body)
    space = client.post("/api/design", json={"target": {"kind": "path", "points": [[0, 6, 0], [90, 6, 0],
                                                                                   [120, 40, -10]]}}).json()
    assert space["path"]["z"] == [0.0, 0.0, -10.0]
    q = bench.parse(body)
    assert Query.from_dict(json.loads(q.key())) == q  # as a verification job keeps it
    assert q.config(15).make_objective(L) == q.objective(L)  # the verification's design run: the same path


def test_a_path_stage(client: TestClient) -> None:
    body = {"model": "2d", "target": {"kind": "stages", "stages": [
        {"pressure_kpa": 18, "target": {"kind": "expression", "expression": "y = 0.05*x"}},
        {"pressure_kpa": 45, "target": {"kind": "curve", "points": hook().tolist()}}]}}
    a = client.post("/api/design", json=body).json()
    assert [s["path"] is not None for s in a["stages"]] == [False, True] and a["path"] is None
    assert a["stages"][1]["path"]["y"][0] == pytest.approx(6.0, abs=0.5) and len(a["centrelines"]) == 10
    assert "45 kPa: path: path through" in a["label"] and len(a["winner"]["design"]) == 15


@pytest.mark.parametrize(("target", "field", "words"), [
    ({"kind": "path", "points": [[0, 6]]}, "points", "2 to"),
    ({"kind": "path", "points": [[0, 6], [10, "nan"]]}, "points", "numbers"),
    ({"kind": "path", "points": [[0, 6], [10, 1e6]]}, "points", "at most 1e5 in size"),
    ({"kind": "path", "points": "a hook"}, "points", "list of"),
    ({"kind": "path", "points": [[1, 1], [1, 1], [1.2, 1]]}, "points", "within 1 mm"),
    ({"kind": "path"}, "points", "needs its points"),
    ({"kind": "path", "preset": "hooks"}, "preset", "hook"),
    ({"kind": "path", "preset": "hook", "points": [[0, 6], [9, 6]]}, "points", "not both"),
    ({"kind": "curve", "points": [[0, 0], [60, 0], [80, 20], [60, 40], [50, "x"]]}, "points", "numbers"),
    ({"kind": "curve", "points": hook().tolist(), "top_points": [[0, 0], [150, 10]]}, "points", "view from above"),
])
def test_bad_paths_are_a_one_line_field_error(client: TestClient, target: dict, field: str, words: str) -> None:
    r = client.post("/api/design", json={"target": target})
    assert r.status_code == 422
    err = r.json()["error"]
    assert err["field"] == field and words in err["message"] and "\n" not in err["message"], err


def test_a_nan_in_a_path_is_refused(client: TestClient) -> None:
    r = client.post("/api/design", content=b'{"target": {"kind": "path", "points": [[0, 6], [NaN, 1]]}}',
                    headers={"content-type": "application/json"})
    assert r.status_code == 422 and r.json()["error"]["field"] == "points"


def test_strokes_turn_back_beyond_jitter_only() -> None:
    x = np.linspace(0.0, L, 200)
    jitter = np.c_[x + 0.9 * np.sin(7 * x), 0 * x]  # back and forth by up to 1.8 mm: not summed, not a turn
    assert not is_path_stroke(jitter)
    back = np.r_[np.c_[x[:100], 0 * x[:100]], np.c_[x[99] - np.linspace(0, 5, 20), np.linspace(0, 30, 20)]]
    assert is_path_stroke(back)  # 5 mm back over a span of 78 mm (tolerance 1.6 mm)
    steep = np.c_[np.linspace(0, 20, 50), np.linspace(0, 60, 50)]  # x spans a third of its length: no graph
    assert is_path_stroke(steep) and not is_path_stroke(steep[:, ::-1])


def test_the_page_knows_the_path_presets(client: TestClient) -> None:
    info = client.get("/api/info").json()
    assert "hook" in info["path_presets"] and info["axis_mm"] == 6.0
    page = client.get("/static/app.js").text
    assert "centrelines" in page and "path_presets" in page

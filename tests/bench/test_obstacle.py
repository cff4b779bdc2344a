"""An object on the bench's page: a circle sent with the query, the answer's design solved against it by the 2D FE
model with contact (:mod:`pneumorph.bench.contact`), and the object's checks before any solve."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from pneumorph.bench import create_app

BASE = "http://127.0.0.1:8000"
SIN_2D = {"target": {"kind": "preset", "name": "sin", "amplitude": 10}, "model": "2d"}
#: in front of the 2D sin winner's free end (157.5 mm long; its tip reaches x = 168.6 mm at 45 kPa, 166.8 at 31.5)
CIRCLE = {"centre": [170.0, 4.0], "radius": 4.0}


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> TestClient:
    state = tmp_path_factory.mktemp("bench")
    return TestClient(create_app(state_dir=state / "state", cache=state / "cache.sqlite"), base_url=BASE)


@pytest.mark.parametrize(("obstacle", "model", "match"), [
    ({"centre": ["NaN", 20.0], "radius": 5.0}, "2d", r"the object centre must be"),
    ({"centre": [120.0, 40.0], "radius": 0.0}, "2d", r"the object radius must be a finite number > 0"),
    ({"centre": [120.0, 40.0], "radius": -3.0}, "2d", r"the object radius must be a finite number > 0"),
    ({"centre": [120.0, 400.0], "radius": 5.0}, "2d", r"past the page: within 196.875 mm of the base"),
    ({"centre": [120.0, 40.0], "radius": 100.0}, "2d", r"radius 100 mm is larger than the page takes"),
    ({"centre": [120.0, 40.0]}, "2d", r"must be \{\"centre\": \[x, y\], \"radius\": r\}"),
    ([120.0, 40.0, 5.0], "2d", r"must be \{\"centre\""),
    ({"centre": [120.0, 40.0], "radius": 5.0}, "3d", r"solved by the 2D FE model with contact: choose the 2D"),
    ({"centre": [50.0, 6.0], "radius": 2.0}, "2d", r"inside"),  # in the actuator: refused before the FE solve
])
def test_a_bad_object_is_refused_naming_the_field(client: TestClient, obstacle: object, model: str,
                                                  match: str) -> None:
    body = json.dumps({**SIN_2D, "model": model, "obstacle": obstacle}).replace('"NaN"', "NaN")  # as JSON allows
    got = client.post("/api/design", content=body, headers={"content-type": "application/json"})
    assert got.status_code == 422, got.text[:300]
    error = got.json()["error"]
    assert error["field"] == "obstacle"
    assert re.search(match, error["message"]), error["message"]


def test_an_answer_without_an_object_has_no_contact(client: TestClient) -> None:
    got = client.post("/api/design", json=SIN_2D).json()
    assert "contact" not in got and got["winner"]["design"] == "001111010001000"


@pytest.mark.slow
def test_the_answer_is_solved_against_the_object(client: TestClient) -> None:
    """The winner of the free target, solved by FE against a circle in front of its free end: free (and as the chain
    predicts) until its end reaches the circle, then pressing on it, the clamp holding the same force, the nodes in
    contact on the circle's surface."""
    got = client.post("/api/design", json={**SIN_2D, "obstacle": CIRCLE})
    assert got.status_code == 200, got.text[:300]
    answer = got.json()
    contact = answer["contact"]
    assert contact["design"] == answer["winner"]["design"] and contact["failure"] is None
    assert contact["obstacle"] == {"kind": "cylinder", **CIRCLE}
    levels = contact["levels"]
    chain = np.array(client.get("/api/profiles", params={"design": contact["design"], "model": "2d"}).json()[
        "centrelines"])  # the chain's free base, centres and tip at every level, the model's frame
    assert [lv["pressure_kpa"] for lv in levels] == answer["pressures_kpa"]
    touching = [k for k, lv in enumerate(levels) if lv["points"]]
    assert touching and touching == list(range(touching[0], len(levels)))  # once it touches, it keeps touching
    assert 3 <= touching[0] <= 7  # the free end reaches x = 166 mm between 18 and 36 kPa
    for k, lv in enumerate(levels):
        force, reaction = np.array(lv["force_n"]), np.array(lv["base_reaction_n"])
        if k < touching[0]:  # free: no force, clear of the circle, the chain's centreline within its error
            assert np.abs(force).max() == 0.0 and lv["clearance_mm"] > 0.0
            assert np.abs(np.array(lv["centreline"]) - chain[k]).max() < 0.1  # mm
            continue
        assert force[0] > 0.0 and lv["contact_length_mm"] > 0.0
        assert lv["clearance_mm"] < 0.03  # mm: within the penalty's onset, 2 % of the 1.5 mm element
        assert np.linalg.norm(reaction - force) <= 0.01 * np.linalg.norm(force)  # the clamp balances the object
        points = np.array(lv["points"])
        gaps = np.linalg.norm(points - CIRCLE["centre"], axis=1) - CIRCLE["radius"]
        assert np.abs(gaps).max() < 0.05  # mm: on the circle, within the penalty's small penetration
        assert len(lv["node_pressures_kpa"]) == len(points) and min(lv["node_pressures_kpa"]) >= 0.0

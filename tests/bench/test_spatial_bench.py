"""The bench over the spatial library: sideways units, answers in space, the 3D view along a space centreline."""

from __future__ import annotations

import io
import time
import zipfile
from dataclasses import replace

import numpy as np
import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from pneumorph.bench import Bench, create_app
from pneumorph.bench import answer as answer_module
from pneumorph.bench.query import QueryError
from pneumorph.bench.shapes import chain_placement
from pneumorph.design.certified.spacegrowth import space_scores
from pneumorph.design.objectives.targets import make_objective

HELIX = {"target": {"kind": "preset", "name": "helix", "amplitude": 25, "periods": 1}, "model": "3d",
         "unit": "spatial"}
SIDEWAYS = "LllAAaaaaLlLllL"  # the full model's benchmark design (benchmarks/full_model.py)


@pytest.fixture(scope="module")
def bench() -> Bench:
    return Bench()


@pytest.mark.slow
def test_a_helix_gets_the_certified_searchs_sideways_design(bench: Bench) -> None:
    a = bench.answer(bench.parse(HELIX))
    chain = bench.chain("3d", "spatial")
    s = space_scores(chain, make_objective("helix", 25.0, length=chain.length))
    best = int(s.order()[0])
    # BENCHMARKS.md, "A chain in space": the helix of radius 25 mm, chain value 39.227 mm
    assert a["winner"]["design"] == chain.table.texts(s.bits[best : best + 1])[0] == "LaaaAlllAlAAAAa"
    assert a["winner"]["value"] == pytest.approx(float(s.cost[best])) == pytest.approx(39.227, abs=5e-4)
    assert a["certificate"]["designs"] == 4**15 and a["certificate"]["certified"]
    assert "optimum is one of" in a["certificate"]["statement"]
    assert a["certificate"]["candidates"] == int((s.optimistic < s.cost[best] + s.bound[best]).sum())
    assert all(set(r["design"]) <= set("aAlL") for r in a["top"])
    # profiles in space: the winner's centres off the undeformed axis, z included
    response = chain.evaluate(a["winner"]["design"])
    pts = np.array(a["profiles"])
    assert pts.shape == (10, 17, 3)
    assert np.abs(pts[:, 1:-1, 2] - (response.centres[..., 2] - response.reference_centres[:, 2])).max() < 1e-4
    assert np.abs(pts[-1, 1:-1, 2]).max() > 10.0  # it leaves the plane


def test_the_spatial_library_needs_the_3d_model_and_a_target_its_chain_scores(bench: Bench) -> None:
    with pytest.raises(QueryError) as info:
        bench.parse({**HELIX, "model": "2d"})
    assert info.value.field == "model" and "out of the plane" in info.value.message
    stages = {"kind": "stages", "stages": [{"pressure_kpa": 45, "target": {"kind": "curve",
                                                                           "points": [[0, 0], [80, 10], [150, 0]]}}]}
    with pytest.raises(QueryError) as info:
        bench.parse({**HELIX, "target": stages})
    assert info.value.field == "target" and "spatial" in info.value.message
    with pytest.raises(QueryError) as info:
        bench.chain_shape("LllAAaaaaLlLllx", "3d", 0, "spatial")
    assert info.value.field == "design"


def test_an_answer_whose_floor_is_below_the_winners_worst_case_is_not_called_certified(
        bench: Bench, monkeypatch: pytest.MonkeyPatch) -> None:
    """A branch-and-bound that had to drop open prefixes bounds them by its floor; below the winner's worst case
    an unlisted design could still beat it, and the certificate says so."""
    real = answer_module.space_scores  # a chain in space: within the query's budget of open prefixes

    def dropped(chain, objective, **options):  # type: ignore[no-untyped-def]
        s = real(chain, objective, **options)
        best = int(s.order()[0])
        return replace(s, floor=float(s.cost[best] + s.bound[best]) - 0.25)

    monkeypatch.setattr(answer_module, "space_scores", dropped)
    a = bench.compute(bench.parse(HELIX))
    assert not a["certificate"]["certified"]
    statement = a["certificate"]["statement"]
    floor = a["winner"]["value"] + a["certificate"]["bound"] - 0.25
    assert statement.startswith("Not certified") and f"only by {floor:.4g} mm" in statement


def test_the_chain_view_of_a_sideways_design_follows_its_space_centreline(bench: Bench) -> None:
    chain = bench.chain("3d", "spatial")
    response = chain.evaluate(SIDEWAYS)
    mesh = bench.model("3d", "spatial").mesh(SIDEWAYS)
    assert mesh.symmetry_points is None  # a sideways unit: the full width, nothing mirrored
    for level in (0, 5, 9):
        x = chain_placement(mesh, response, level)
        centres = mesh.unit_centres(x - mesh.points, axes=3)
        assert np.abs(centres - response.centres[level]).max() < 0.6  # mm, the planar view's tolerance
    s = bench.chain_shape(SIDEWAYS, "3d", 9, "spatial")
    assert s["source"] == "chain"
    tri = np.reshape(s["indices"], (-1, 3))
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert (counts == 2).all()  # watertight
    pos = np.reshape(s["positions"], (-1, 3))
    assert pos[:, 2].max() > response.tip[-1, 2] > 40.0  # it reaches across the width as the chain says


@pytest.mark.slow
def test_the_api_offers_the_spatial_library_and_exports_a_sideways_design(tmp_path) -> None:  # type: ignore[no-untyped-def]
    client = TestClient(create_app(state_dir=tmp_path / "state", cache=tmp_path / "cache.sqlite"),
                        base_url="http://127.0.0.1:8000")
    units = client.get("/api/units").json()["units"]
    assert {"id": "spatial", "name": answer_module.LIBRARIES["spatial"], "model": "3d"} in units
    a = client.post("/api/design", json=HELIX).json()
    assert a["winner"]["design"] == "LaaaAlllAlAAAAa"
    r = client.get("/api/profiles", params={"design": SIDEWAYS, "model": "3d", "unit": "spatial"})
    assert np.shape(r.json()["profiles"]) == (10, 17, 3)
    bad = client.post("/api/jobs", json={"kind": "export", "design": "LllAAaaaaLlLllx", "unit": "spatial"})
    assert bad.status_code == 422 and bad.json()["error"]["field"] == "design"
    r = client.post("/api/jobs", json={"kind": "export", "design": "LaaaAlllAlAAAAa", "unit": "spatial"})
    assert r.status_code == 202
    job_id = r.json()["job_id"]
    for _ in range(600):
        job = client.get(f"/api/jobs/{job_id}").json()
        if job["state"] in ("done", "failed"):
            break
        time.sleep(0.1)
    assert job["state"] == "done", job["message"]
    assert {"body.stl", "base_block.stl"} <= set(job["result"]["parts"]) and job["result"]["mould_parts"] > 0
    archive = client.get(f"/api/jobs/{job_id}/files/export-LaaaAlllAlAAAAa.zip")
    with zipfile.ZipFile(io.BytesIO(archive.content)) as z:
        names = z.namelist()
    assert "LaaaAlllAlAAAAa.inp" in names and any(n.startswith("parts/layer_") for n in names)


def test_a_tip_point_off_the_plane_is_reached_in_space(bench: Bench) -> None:
    """A planar actuator's tip stays at z = 0, so a point z off the plane adds z in quadrature to every design's
    distance: the same winner, its value the hypotenuse."""
    flat = bench.answer(bench.parse({"target": {"kind": "tip", "goal": "reach", "point": [100, 40]}}))
    off = bench.answer(bench.parse({"target": {"kind": "tip", "goal": "reach", "point": [100, 40, 12]}}))
    assert off["point"] == [100.0, 40.0, 12.0] and off["winner"]["design"] == flat["winner"]["design"]
    assert off["winner"]["value"] == pytest.approx(float(np.hypot(flat["winner"]["value"], 12.0)), abs=1e-9)
    for bad in ([100, 40, "x"], [100, 40, 1, 2]):
        with pytest.raises(QueryError) as info:
            bench.parse({"target": {"kind": "tip", "goal": "reach", "point": bad}})
        assert info.value.field == "point"


def test_the_chain_view_of_an_undeformed_actuator_with_centres_at_several_heights_moves_nothing() -> None:
    """The built-in library's units have their cavities at different heights, so the undeformed centreline is not
    straight: the view turns each chord relative to its undeformed direction, so nothing moves (the earlier view
    turned them by their absolute angles: 0.85 mm here)."""
    from pneumorph.geometry.assembly import assemble
    from pneumorph.geometry.library import builtin_library
    from pneumorph.models.response import Response

    mesh = assemble(builtin_library(), "aeRS", dim=3, half=True)
    ref = mesh.unit_centres()
    assert np.ptp(ref[:, 1]) > 1.0  # the centres' heights differ
    tip = np.array([mesh.points[:, 0].max(), ref[-1, 1]])
    r = Response("aeRS", np.array([0.01]), ref[None], ref, tip[None], tip, np.zeros(1))
    np.testing.assert_allclose(chain_placement(mesh, r, 0), mesh.points, atol=1e-9, rtol=0)

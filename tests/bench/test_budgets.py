"""The bench's budgets: a slow query (a chain in space) has a worker and a memory budget of its own, at most
SLOW_QUEUE of them at once, and never holds up the plain queries; a unit a mould cannot cast is refused."""

from __future__ import annotations

import subprocess
import sys
import threading
from pathlib import Path

import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from pneumorph.bench import create_app
from pneumorph.bench.answer import QUERY_MEMORY, QUERY_NODES, QUERY_PREFIX_BYTES
from pneumorph.bench.app import SLOW_QUEUE

BASE = "http://127.0.0.1:8000"
SIN = {"target": {"kind": "preset", "name": "sin", "amplitude": 10, "periods": 1}}
MAX_X = {"target": {"kind": "tip", "goal": "max-x"}, "unit": "spatial"}
MIN_Y = {"target": {"kind": "tip", "goal": "min-y"}, "unit": "spatial"}


@pytest.fixture()
def app(tmp_path: Path):  # type: ignore[no-untyped-def]
    return create_app(state_dir=tmp_path / "state", cache=tmp_path / "cache.sqlite", answer_workers=0)


def test_a_unit_a_mould_cannot_cast_is_refused_before_any_job(app) -> None:  # type: ignore[no-untyped-def]
    client = TestClient(app, base_url=BASE)
    r = client.post("/api/jobs/table", files={"unit": ("u.toml", b"[unit]\nwall = 1e-6\n")}, data={"model": "3d"})
    assert r.status_code == 422, r.text
    err = r.json()["error"]
    assert err["field"] == "unit" and "uploaded unit: wall 1e-06 mm is thinner" in err["message"]
    assert "MIN_WALL_MM = 1 mm" in err["message"]
    assert client.get("/api/jobs").json()["jobs"] == []


def test_slow_queries_wait_in_their_own_lane_and_plain_ones_pass(app) -> None:  # type: ignore[no-untyped-def]
    """Two spatial tip queries held in flight: a third is refused with its reason, a plain query is answered."""
    bench = app.state.bench
    entered, release = threading.Semaphore(0), threading.Event()
    real = bench.compute

    def held(query):  # type: ignore[no-untyped-def]
        if bench.slow(query):
            entered.release()
            assert release.wait(60)
            return {"held": query.spec}
        return real(query)

    bench.compute = held
    answers: dict[str, int] = {}

    def ask(body: dict, name: str) -> None:
        answers[name] = TestClient(app, base_url=BASE).post("/api/design", json=body).status_code

    slow = [threading.Thread(target=ask, args=(body, name)) for body, name in ((MAX_X, "max-x"), (MIN_Y, "min-y"))]
    for thread in slow:
        thread.start()
    try:
        for _ in slow:
            assert entered.acquire(timeout=60)  # both are being answered: the lane is full (SLOW_QUEUE = 2)
        client = TestClient(app, base_url=BASE)
        third = client.post("/api/design", json={**MAX_X, "top": 5})
        assert SLOW_QUEUE == 2 and third.status_code == 429, third.text
        assert third.json()["error"]["field"] == "query"
        assert "2 slow queries (a chain in space searched by branch-and-bound" in third.json()["error"]["message"]
        plain = client.post("/api/design", json=SIN)  # answered while the slow ones are in flight
        assert plain.status_code == 200 and plain.json()["winner"]["design"] == "001111010001001"
    finally:
        release.set()
        for thread in slow:
            thread.join(60)
    assert answers == {"max-x": 200, "min-y": 200}


def test_the_workers_split_into_plain_and_slow_ones() -> None:
    from pneumorph.bench.answer import Bench
    from pneumorph.bench.app import AnswerPool

    pool = AnswerPool(Bench(), workers=2)
    assert pool.workers == 2 and QUERY_NODES == QUERY_MEMORY // 16_000 == 46_875


def test_a_query_prefix_holds_the_search_s_children_and_levels() -> None:
    """A bench query's open prefix in space (the spatial library: 2 unit types, 2 orientations each; 10 levels)
    holds at least what the certified search measured per child and level in space."""
    from pneumorph.design.certified.branching import prefix_bytes
    from pneumorph.models import make_model

    model = make_model(15, {"fidelity": "3d", "library": "spatial"})
    children, levels = 2 * len(model.library.units), len(model.pressures())
    assert (children, levels) == (4, 10)
    assert prefix_bytes(space=True) * children * levels <= QUERY_PREFIX_BYTES < 1.5 * 12_500
    assert QUERY_NODES * QUERY_PREFIX_BYTES <= QUERY_MEMORY


# The peak is this process's own VmHWM, not ru_maxrss: Linux keeps ru_maxrss across exec, so a child forked from a
# large test worker would report the worker's size.
_MEASURE = """
import json, sys
from pathlib import Path
from pneumorph.bench.answer import Bench
bench = Bench(memo=0)
answer = bench.compute(bench.parse(json.loads(sys.argv[1])))
status = Path("/proc/self/status").read_text().splitlines()
peak = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 1024
print(json.dumps({"peak_mb": peak, "winner": answer["winner"], "certificate": answer["certificate"]}))
"""


@pytest.mark.slow
def test_a_spatial_tip_query_stays_within_a_workers_memory() -> None:
    """max-x of the spatial library: 6.0 GB with the design command's 500,000 open prefixes; within 1.5 GB here."""
    import json

    done = subprocess.run([sys.executable, "-c", _MEASURE, json.dumps(MAX_X)], capture_output=True, text=True,
                          timeout=600, check=True)
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["peak_mb"] < 1500, out
    # every sideways unit alternately turned over, stretched to 45 kPa: 196.3 mm along x by the shipped table
    assert out["winner"]["design"] == "lLlLlLlLlLlLlLl" and out["winner"]["value"] == pytest.approx(196.3135, abs=1e-3)
    assert out["winner"]["pressure_kpa"] == pytest.approx(45.0)
    assert out["certificate"]["certified"] is False and "Not certified" in out["certificate"]["statement"]


def test_a_table_fitted_to_fewer_levels_remakes_the_benchs_model(tmp_path: Path) -> None:
    """A table built to the levels every design reached serves its unit's model at those levels, the FE model
    (of the verifications) remade with them."""
    from dataclasses import replace

    from pneumorph.bench.answer import Bench
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.models.chain.levels import ramp_source
    from pneumorph.models.chain.model import ChainTable, source_description, source_key
    from pneumorph.models.chain.sources import restrict_table, shipped_path, table_file
    from pneumorph.models.factory import make_model

    spec = UnitSpec(layer=2.5)
    full = make_model(15, {"fidelity": "2d", "unit": spec.to_dict()})
    shipped = ChainTable.load(shipped_path("2d"))
    description = source_description(full)
    own = replace(shipped, source={**shipped.source, "key": source_key(full), "description": description})
    cut = restrict_table(own, 6)  # its entries: the first 6 levels, its source the ramp of those levels
    source = ramp_source(own.source, own.pressures, 6, cut_from={
        "key": source_key(full), "levels": 10, "pressure_mpa": 0.045, "why": "every design reached (1 did not "
        "converge beyond)", "failed": {"0" * 15: 6}})
    replace(cut, source={k: v for k, v in source.items() if k != "restricted_from"}).save(
        table_file(tmp_path, full))
    bench = Bench(table_dir=tmp_path)
    unit = bench.add_unit(spec)
    model = bench.model("2d", unit)
    assert model.ramp.steps.increments == 6 and model.ramp.pressure == pytest.approx(0.027)
    assert bench.chain("2d", unit).table.n_levels == 6

"""Where chain tables come from: a table of a longer ramp serves lower pressures by its levels, a build says
what it builds first, and two processes that need the same table build it once."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import ChainTableError
from pneumorph.models.chain.model import ChainModel, ChainTable, check_source, source_key
from pneumorph.models.chain.plan import build_plan
from pneumorph.models.chain.sources import (
    build_options,
    ramp_variant,
    restrict_table,
    restriction_levels,
    serve_table,
    shipped_path,
)
from pneumorph.models.factory import make_model
from pneumorph.sensitivity.robust import find_tolerance_tables
from pneumorph.sensitivity.tolerances import Tolerance

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def table3d() -> ChainTable:
    return ChainTable.load(shipped_path("3d"))


def test_a_restricted_table_predicts_exactly_the_first_levels_of_the_full_one(table3d: ChainTable) -> None:
    short = restrict_table(table3d, 5)
    assert short.n_levels == 5 and np.array_equal(short.pressures, table3d.pressures[:5])
    bits = np.random.default_rng(3).integers(0, 2, size=(40, 12), dtype=np.uint8)
    full_c, full_t, full_curl = table3d.predict(bits)
    c, t, curl = short.predict(bits)
    assert np.array_equal(c, full_c[:, :5]) and np.array_equal(t, full_t[:, :5])
    assert np.array_equal(curl, full_curl[:, :5])
    for key in ("centre_worst_mm", "centre_mean_mm", "tip_worst_mm", "curl_worst_deg", "norm_worst_mm"):
        assert short.validation[key] == table3d.validation[key][:5]
    assert short.validation["designs"] == table3d.validation["designs"]  # 20 held-out designs, not levels
    # the table's own file round trip keeps it (its fingerprint is that of the restricted arrays)
    again = ChainTable.from_dict(json.loads(json.dumps(short.to_dict())))
    assert again.fingerprint() == short.fingerprint() != table3d.fingerprint()
    assert restrict_table(table3d, 10) is table3d
    assert short.source["restricted_from"] == {"key": table3d.source["key"], "levels": 10, "pressure_mpa": 0.045}


def test_the_source_check_passes_for_the_model_remade_with_the_tables_levels(table3d: ChainTable) -> None:
    asked = make_model(10, {"fidelity": "3d", "pressure_kpa": 25})
    assert restriction_levels(table3d, asked) == 5
    remade = ramp_variant(asked, 0.0225, 5)
    short = restrict_table(table3d, 5)
    check_source(short, remade)  # the remade model's levels are the restricted table's
    assert np.allclose(remade.pressures(), short.pressures, rtol=0, atol=1e-12)
    assert short.source["fingerprint"] == remade.with_units(15).fingerprint()  # the training model's
    with pytest.raises(ChainTableError, match="another model"):
        check_source(short, asked)  # the ramp asked for (10 levels of 2.5 kPa) is not the table's
    with pytest.raises(ChainTableError, match="another model"):
        check_source(short, make_model(10, {"fidelity": "3d"}))
    served = serve_table(asked)
    assert served is not None and served.restricted and served.model.fingerprint() == remade.fingerprint()
    given = serve_table(asked, path=shipped_path("3d"))  # a table given by its file is restricted alike
    assert given is not None and given.table.fingerprint() == served.table.fingerprint()
    with pytest.raises(ChainTableError, match="another model"):
        serve_table(make_model(10, {"fidelity": "2d", "pressure_kpa": 25}), path=shipped_path("3d"))
    assert served.levels_text() == "scored at the table's levels 4.5-22.5 kPa (5 levels) at or below 25 kPa"
    # the chain of the served table is the full table's chain at its first five levels
    design = "0111100001"
    full = ChainModel(table3d, 10).evaluate(design)
    part = ChainModel(served.table, 10).evaluate(design)
    assert np.array_equal(part.centres, full.centres[:5]) and np.array_equal(part.tip, full.tip[:5])


@pytest.mark.parametrize(("fidelity", "settings", "levels"), [
    ("3d", {"pressure_kpa": 45}, 10),  # the table's own ramp: no restriction
    ("3d", {"pressure_kpa": 45, "increments": 20}, 10),  # a finer ramp to the same top: the table's levels
    ("3d", {"pressure_kpa": 4.5}, 1),
    ("3d", {"pressure_kpa": 44.9}, 9),
    ("3d", {"pressure_kpa": 4.4}, None),  # below the first level
    ("3d", {"pressure_kpa": 46}, None),  # beyond the table
    ("2d", {"pressure_kpa": 25}, 5),
    ("2d", {"pressure_kpa": 25, "substeps": 2}, None),  # the 2D model's substeps are part of its source
    ("2d", {"pressure_kpa": 25, "unit": {"wall": 1.4}}, None),  # another unit
])
def test_which_levels_of_the_shipped_tables_serve_a_pressure(fidelity: str, settings: dict, levels: int | None) -> None:
    model = make_model(7, {"fidelity": fidelity, **settings})
    served = serve_table(model)
    if levels is None:
        assert served is None
        return
    assert served is not None and served.table.n_levels == levels
    assert served.restricted == (source_key(model) != ChainTable.load(shipped_path(fidelity)).source["key"])
    check_source(served.table, served.model)
    assert served.model.n_units == 7 and served.model.pressures()[-1] == pytest.approx(0.0045 * levels, abs=1e-12)


def test_a_restriction_is_refused_out_of_range_or_without_a_source_description(table3d: ChainTable) -> None:
    for bad in (0, 11, 2.5):
        with pytest.raises(ChainTableError, match="restricted to 1 to 10"):
            restrict_table(table3d, bad)  # type: ignore[arg-type]
    bare = ChainTable(**{**table3d.__dict__, "source": {k: v for k, v in table3d.source.items() if k != "description"}})
    with pytest.raises(ChainTableError, match="does not hold its model's description"):
        restrict_table(bare, 5)


def test_the_tolerance_tables_serve_the_remade_model_restricted_likewise() -> None:
    served = serve_table(make_model(10, {"fidelity": "3d", "pressure_kpa": 25}))
    assert served is not None
    tables = find_tolerance_tables(served.model, Tolerance(0.1))
    assert tables is not None and tables.source["key"] == source_key(served.model)
    full = find_tolerance_tables(make_model(10, {"fidelity": "3d"}), Tolerance(0.1))
    assert full is not None
    for short, long in zip((tables.nominal, *tables.minus, *tables.plus, *tables.corners),
                           (full.nominal, *full.minus, *full.plus, *full.corners), strict=True):
        assert short.n_levels == 5 and np.array_equal(short.turn, long.turn[:, :5])
    moved = tables.perturbed(served.table, np.array([0.05, -0.1, 0.02]))
    whole = full.perturbed(ChainTable.load(shipped_path("3d")), np.array([0.05, -0.1, 0.02]))
    assert np.allclose(moved.turn, whole.turn[:, :5], rtol=0, atol=1e-15)
    assert find_tolerance_tables(make_model(10, {"fidelity": "3d", "pressure_kpa": 25}), Tolerance(0.1)) is None


# -- one build of a table, however many processes need it ----------------------------------------------
_BUILDER = textwrap.dedent("""
    import json, sys, time
    from pathlib import Path
    from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
    from pneumorph.models.chain.sources import table_for
    from pneumorph.models.factory import make_model

    name, tables, go = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    model = make_model(7, {"fidelity": "2d", "unit": {"element_size": 3.0}, "pressure_kpa": 10})
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(tables.parent / f"cache-{name}.sqlite"))
    lines = []
    (tables.parent / f"ready-{name}").touch()
    while not go.exists():  # both processes imported and ready: they ask for the table at the same moment
        time.sleep(0.01)
    table = table_for(model, model.with_units, folder=tables, evaluator=evaluator, on_progress=lines.append)
    print(json.dumps({"solves": evaluator.solves, "fingerprint": table.fingerprint(), "lines": lines}))
""")


@pytest.mark.slow
def test_two_processes_that_need_the_same_table_build_it_once(tmp_path: Path) -> None:
    tables = tmp_path / "chain-tables"
    go = tmp_path / "go"
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "PYTHONPATH": str(REPO / "src")}
    procs = [subprocess.Popen([sys.executable, "-c", _BUILDER, name, str(tables), str(go)], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for name in ("a", "b")]
    deadline = time.monotonic() + 120
    while not all((tmp_path / f"ready-{n}").exists() for n in ("a", "b")):
        assert time.monotonic() < deadline and all(p.poll() is None for p in procs), [p.communicate() for p in procs]
        time.sleep(0.02)
    go.touch()
    out = []
    for p in procs:
        stdout, stderr = p.communicate(timeout=300)
        assert p.returncode == 0, stderr
        out.append(json.loads(stdout))
    builder, waiter = sorted(out, key=lambda o: -o["solves"])
    plan_model = make_model(15, {"fidelity": "2d", "unit": {"element_size": 3.0}, "pressure_kpa": 10})
    plan = build_plan(plan_model, **build_options(plan_model))
    # built once, by one of them: its covering designs and 6 to 20 held-out designs per window tried
    assert plan.fewest <= builder["solves"] <= plan.solves[-1] and waiter["solves"] == 0
    assert builder["fingerprint"] == waiter["fingerprint"]  # the other reused it
    assert builder["lines"][0].startswith("building the chain table of the 2d model")  # the plan, first
    assert f"{plan.fewest}-{plan.solves[-1]} FE solves, estimated" in builder["lines"][0]
    name = f"chain table chain-2d-{source_key(plan_model)}.json"
    assert waiter["lines"][0].startswith(f"waiting for {name}: another process builds it (pid ")
    pid = waiter["lines"][0].split("(pid ")[1].split(" ")[0]
    assert pid in {str(p.pid) for p in procs}
    assert waiter["lines"][1:] == [f"{name} was built meanwhile by pid {pid} on {socket.gethostname()}: reusing it"]
    assert [p.name for p in tables.iterdir()] == [name.removeprefix("chain table ")]  # and no lock file left


def test_a_plan_with_short_designs_estimates_them_by_their_units() -> None:
    """Short training designs count in the estimate by their units' share of a full-length solve (a solve's time
    grows with the units): the built-in unit's 3D plan with short end designs (23-73 solves) costs 21.3-46.2
    full-length solves; without short designs every solve is a full one."""
    model = make_model(15, {"fidelity": "3d"})
    short = build_plan(model, workers=2, short=True)
    assert short.solves == (23, 33, 73) and short.work[-1] < short.solves[-1]
    assert short.work == pytest.approx((21.2667, 25.4, 46.2), abs=1e-4)
    assert "estimated 2.8 min to 6 min with 2 workers" in short.cost_text()  # 15 s x ceil(21.27 / 2) .. ceil(46.2 / 2)
    assert "shorter designs by their units" in short.cost_text()
    full = build_plan(model, workers=2)
    assert full.work == tuple(float(s) for s in full.solves) and "shorter designs" not in full.cost_text()

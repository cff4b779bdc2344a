"""One background job of the bench, in a process of its own: ``python -m pneumorph.bench.worker``.

The server (:class:`~pneumorph.bench.jobs.JobBoard`) starts one such process per job, in a
new process group, writes the job's description to its standard input as one JSON object,
and reads what the job says from its standard output, one JSON object a line:

- ``{"say": text, "progress": p}``: a log line, with the share done (0-1) or null;
- ``{"file": name}``: a file written into the job's ``files/`` folder, offered for download;
- ``{"result": {...}}``: the job's result, before it ends well;
- ``{"error": message}``: why the job failed (the process then exits 1).

Whatever else the job's libraries print goes to standard error (the job's ``worker.log``).
The server cancels a job, or stops it when the server stops, by signalling the whole
process group, so the FE worker processes a job starts end with it; a job whose server
has gone (killed outright) ends itself (:func:`pneumorph.execution.evaluators.prepare_worker`).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

from pneumorph.bench.answer import Bench
from pneumorph.bench.query import Query
from pneumorph.errors import PneumorphError
from pneumorph.io.files import json_safe

SHOWN = ("report.md", "certificate.json", "top.csv", "profile.png", "chain-vs-fe.png", "mould.png")


class Reporter:
    """What a job says, as JSON lines on a stream (the server reads them).

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> Reporter(out).say("casting mould", 0.3)
    >>> out.getvalue()
    '{"say": "casting mould", "progress": 0.3}\\n'
    >>> Reporter(out).send({"result": {"gap": float("nan")}})  # NaN and infinities as null, as in every JSON
    >>> out.getvalue().splitlines()[-1]
    '{"result": {"gap": null, "gap_reason": "not a number"}}'
    """

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream
        self._lock = threading.Lock()

    def send(self, event: dict[str, Any]) -> None:
        with self._lock:
            self.stream.write(json.dumps(json_safe(event), allow_nan=False, default=str) + "\n")
            self.stream.flush()

    def say(self, text: str, progress: float | None = None) -> None:
        self.send({"say": str(text)[:2000], "progress": progress})

    def offer(self, folder: Path, path: Path, name: str | None = None) -> None:
        """Copy ``path`` into the job's ``files/`` (unless it is there) and offer it."""
        out = folder / "files"
        out.mkdir(exist_ok=True)
        target = out / (name or path.name)
        if path.resolve() != target.resolve():
            shutil.copyfile(path, target)
        self.send({"file": target.name})


class TableProgress:
    """The share of a chain-table build done, from its progress lines and its plan's solve counts.

    Each ``"... N/M solved"`` line is one more design solved (or found in the cache); the
    share is the designs done over the designs of the windows begun so far (covering and
    held-out, :attr:`pneumorph.models.chain.plan.BuildPlan.solves`), so it follows the work
    whatever the order of the solves.

    Parameters
    ----------
    solves : sequence of int
        Distinct solves if the build stops at each window (cumulated), from the build plan.

    Examples
    --------
    >>> p = TableProgress([40, 70])
    >>> p("window +-1: 20 covering designs"), p("  covering: 1/20 solved (solved 0, 3 s)")
    (None, 0.044)
    >>> [p(f"  covering: {i}/20 solved") for i in range(2, 21)][-1]  # half the first window's 40 designs
    0.495
    """

    def __init__(self, solves: list[int] | tuple[int, ...], start: float = 0.02, end: float = 0.97) -> None:
        self.solves = [max(int(s), 1) for s in solves] or [1]
        self.window = 0
        self.done = 0
        self.start, self.end = start, end

    def __call__(self, text: str) -> float | None:
        window = re.match(r"window \+-(\d+): \d+ covering designs", text.strip())
        if window is not None:
            self.window += 1
            return None
        if re.search(r"\d+/\d+ solved", text) is None:
            return None
        self.done += 1
        total = self.solves[min(max(self.window, 1), len(self.solves)) - 1]
        return round(self.start + (self.end - self.start) * min(self.done / total, 1.0), 3)


def verify(job: dict[str, Any], bench: Bench, report: Reporter) -> dict[str, Any]:
    """Certify a query's optimum by FE: ``pneumorph design --certify`` for its target and model.

    In 3D the chain's best design is solved first, keeping its fields for the 3D view; its
    response goes into the cache, where the design run finds it.
    """
    from pneumorph.design.driver import run_design

    query = Query.from_dict(job["params"]["query"])
    folder = Path(job["folder"])
    config = query.config(bench.units, bench.model_settings(query.model, query.unit), certify=True,
                          executor="processes", workers=job["workers"], cache=job["cache"])
    model = bench.model(query.model, query.unit)
    if query.model == "3d":  # solve the chain's best once, keeping its fields for the 3D view
        design = bench.answer(query)["winner"]["design"]
        report.say(f"solving {design} by 3D FE (its shape and its verification)", 0.05)
        presolve(bench, model, design, query.unit, job["cache"])
    run = folder / "run"
    report.say(f"design run: certified search on the {query.model.upper()} model", 0.5)
    result = run_design(config, model, run, on_message=lambda text: report.say(str(text)))
    cert = result.certified
    if result.status != "finished" or cert is None:
        raise RuntimeError(f"the design run ended {result.status}")
    winner = cert.winner
    report.say(f"verified {winner.design}: {winner.value:.4g} {result.objective.unit} by FE", 0.9)
    for path in result.files:
        if path.name in SHOWN:
            report.offer(folder, path)
    archive = shutil.make_archive(str(folder / "run"), "zip", root_dir=run)
    report.offer(folder, Path(archive))
    return {"design": winner.design, "fe_value": winner.value, "chain_value": cert.winner_chain.value,
            "level": winner.level, "pressure_kpa": None if winner.pressure is None else winner.pressure * 1e3,
            "certified": bool(cert.certificate["certified"]), "gap": cert.certificate["gap"],
            "could_beat": cert.certificate["could_beat"], "verified": cert.certificate["verified"],
            "solves": result.solves, "unit": result.objective.unit, "model": query.model,
            "shape": bench.fe_shape_file(winner.design, query.unit) is not None}


def presolve(bench: Bench, model: Any, design: str, unit: str, cache_path: str) -> None:
    """Solve ``design`` here: its surface for the viewer, its response into the cache."""
    from pneumorph.bench.jobs import fe_solve_shape
    from pneumorph.execution.cache import EvaluationCache
    from pneumorph.execution.outcome import Outcome

    with EvaluationCache(cache_path) as cache:
        fe_known = bench.fe_shape_file(design, unit) is not None
        if cache.get(model.fingerprint(), design) is not None and fe_known:
            return  # verified and drawn before
    response, shape, wall = fe_solve_shape(model, design)
    if response is None or shape is None:
        return  # the design run solves it again and reports the failure
    bench.add_fe_shape(design, shape, unit)
    with EvaluationCache(cache_path) as cache:
        if cache.get(model.fingerprint(), design) is None:
            cache.put(model.fingerprint(), Outcome(design, response, wall_time=wall))


def table(job: dict[str, Any], bench: Bench, report: Reporter) -> dict[str, Any]:
    """The chain table of an uploaded unit, built through the evaluation cache (or found)."""
    from pneumorph.execution import CachedEvaluator, EvaluationCache, make_evaluator
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.models.chain.plan import build_plan
    from pneumorph.models.chain.sources import TRAINING_UNITS, build_options, table_for

    params = job["params"]
    spec = UnitSpec.from_dict(params["unit"], "uploaded unit")
    fidelity, unit_id = params["model"], params["unit_id"]
    bench.add_unit(spec, unit_id)
    model = bench.model(fidelity, unit_id)
    training = model.with_units(TRAINING_UNITS)
    progress = TableProgress(build_plan(training, **build_options(training)).solves)
    report.say(f"chain table of unit {spec.name!r} for the {fidelity.upper()} model", 0.02)
    with EvaluationCache(job["cache"]) as cache, make_evaluator("processes", job["workers"]) as inner:
        built = table_for(model, model.with_units, folder=bench.table_dir, evaluator=CachedEvaluator(inner, cache),
                          on_progress=lambda t: report.say(str(t), progress(str(t))))
    val = built.validation
    worst = max(val.get("centre_worst_mm", [float("nan")]))
    report.say(f"unit {spec.name!r} ready: window {built.window}, held-out centre error at most {worst:.3g} mm", 0.99)
    return {"unit_id": unit_id, "name": spec.name, "model": fidelity, "window": built.window,
            "centre_worst_mm": worst}


def export(job: dict[str, Any], bench: Bench, report: Reporter) -> dict[str, Any]:
    """STL parts, casting mould and CalculiX deck of a design, zipped."""
    from pneumorph.export import BaseBlock, MouldSpec, actuator_parts, casting_mould, plot_mould, write_stl
    from pneumorph.export.calculix import write_calculix_deck

    design, unit_id = job["params"]["design"], job["params"]["unit"]
    folder = Path(job["folder"])
    model = bench.model("3d", unit_id)
    unit = model.library if model.mixed else model.unit  # a library's design: its units and their strips
    out = folder / "export"
    report.say(f"parts of {design}", 0.1)
    write_stl(actuator_parts(unit, design, BaseBlock()), out / "parts")
    report.say("casting mould", 0.3)
    mould = casting_mould(unit, design, MouldSpec())
    write_stl(mould.parts, out / "mould")
    plot_mould(mould, out / "mould" / "mould.png")
    report.offer(folder, out / "mould" / "mould.png")
    report.say("CalculiX deck", 0.8)
    write_calculix_deck(model, design, out / f"{design}.inp")
    archive = shutil.make_archive(str(folder / f"export-{design}"), "zip", root_dir=out)
    report.offer(folder, Path(archive))
    return {"design": design, "parts": sorted(p.name for p in (out / "parts").glob("*.stl")),
            "mould_parts": len(mould.parts)}


def wait(job: dict[str, Any], bench: Bench, report: Reporter) -> dict[str, Any]:
    """Sleep for ``params["seconds"]``, saying so each second: a job of known length for tests."""
    seconds = float(job["params"].get("seconds", 1.0))
    start = time.monotonic()
    while (left := seconds - (time.monotonic() - start)) > 0:
        report.say(f"waiting, {left:.0f} s left", min((seconds - left) / seconds, 0.99))
        time.sleep(min(left, 1.0))
    return {"seconds": seconds}


KINDS: dict[str, Callable[[dict[str, Any], Bench, Reporter], dict[str, Any]]] = {
    "verify": verify, "table": table, "export": export, "wait": wait}


def main() -> int:
    """Run the job described on standard input; report on standard output (see the module)."""
    job = json.loads(sys.stdin.read())
    events = os.fdopen(os.dup(1), "w", encoding="utf-8")
    os.dup2(2, 1)  # the libraries' prints go to the log, not into the events
    sys.stdout = sys.stderr
    report = Reporter(events)
    from pneumorph.execution.evaluators import prepare_worker

    prepare_worker()  # one BLAS thread; an exit of its own when the server is gone
    bench = Bench(table_dir=job["table_dir"], unit_dir=job["unit_dir"], memo=0, settings=job.get("model_settings"))
    bench.shape_dir = Path(job["shape_dir"])
    try:
        result = KINDS[job["kind"]](job, bench, report)
    except PneumorphError as exc:
        report.send({"error": str(exc)})
        return 1
    except Exception as exc:  # the job fails, the server goes on; the message says why
        report.send({"error": f"{type(exc).__name__}: {exc}"[:2000]})
        raise
    report.send({"result": result})
    return 0


if __name__ == "__main__":
    sys.exit(main())

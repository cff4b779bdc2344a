"""Tables and solves on a real Dask cluster against the process pool.

    python benchmarks/cluster.py solve                     # one 3D solve: pool, nanny worker, without and with settings
    python benchmarks/cluster.py solve --units 15 --repeat 2
    python benchmarks/cluster.py table                     # 2D table build: pool and 1, 2 Dask workers
    python benchmarks/cluster.py table --model 3d          # the same for 3D (long: about 20 min per build on 2 cores)

``solve`` starts a scheduler and one standard worker (``dask scheduler``, ``dask worker ADDR
--nworkers 1 --nthreads 1``: with its nanny, which sets ``MALLOC_TRIM_THRESHOLD_=65536``) as
separate processes and times one 3D solve of a design three ways: on that worker as it is
(a plain ``Client.submit``, before pneumorph's worker settings are registered), through
:class:`~pneumorph.execution.DaskEvaluator` (which registers them), and in a process pool of
one worker. The times are those of the solve inside its process (wall, user and system CPU
from ``getrusage``: no start-up, no transfer). ``--repeat`` repeats the three on a fresh cluster.

``table`` runs ``pneumorph chain build`` as a subprocess, each with a fresh evaluation cache:
``--executor processes --workers N`` and ``--executor dask --scheduler ADDR`` with N
standard workers, for each N of ``--workers``; prints the wall time, the FE solves and the
solves per minute, and checks that every build wrote the same table (fit and validation).
Prints the machine.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

PYTHON = sys.executable
DASK_BIN = Path(PYTHON).with_name("dask")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@contextmanager
def cluster(workers: int, log: Path) -> Iterator[str]:
    """A scheduler and ``workers`` standard workers on 127.0.0.1, each a separate process; the address."""
    from distributed import Client

    address = f"tcp://127.0.0.1:{free_port()}"
    env = {**os.environ}
    procs = [subprocess.Popen([str(DASK_BIN), "scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1],
                               "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=open(log / "scheduler.log", "w"),
                              env=env)]
    try:
        for i in range(workers):
            procs.append(subprocess.Popen([str(DASK_BIN), "worker", address, "--nworkers", "1", "--nthreads", "1",
                                           "--no-dashboard"], stdout=subprocess.DEVNULL,
                                          stderr=open(log / f"worker{i}.log", "w"), env=env))
        with Client(address, timeout=30) as client:
            client.wait_for_workers(workers, timeout=60)
        yield address
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()


def machine() -> str:
    return f"{platform.node()}: {os.cpu_count()} cores, {platform.platform()}, Python {platform.python_version()}"


# -- one 3D solve ------------------------------------------------------------------------
def solve_case(units: int) -> tuple[object, str]:
    from pneumorph.models.factory import make_model

    model = make_model(units, {"fidelity": "3d"})
    design = ("0110" * units)[:units]
    return model, design


def timed_solve(model: object, design: str) -> tuple[object, float, float, float]:
    """Solve in this process: the outcome, and the wall, user CPU and system CPU seconds of the solve."""
    import resource

    from pneumorph.execution import solve

    before = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    outcome = solve(model, design)  # type: ignore[arg-type]
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_SELF)
    return outcome, wall, after.ru_utime - before.ru_utime, after.ru_stime - before.ru_stime


def time_solve(args: argparse.Namespace) -> None:
    from distributed import Client

    from pneumorph.execution import DaskEvaluator, ProcessPoolEvaluator

    model, design = solve_case(args.units)
    rows: list[tuple[str, tuple[float, float, float]]] = []
    plain_name = "dask worker, nanny defaults (MALLOC_TRIM_THRESHOLD_=65536)"
    tuned_name = "dask worker with pneumorph's worker settings (DaskEvaluator connected)"
    pool_name = "process pool, 1 worker"
    for r in range(args.repeat):
        results = {}
        with tempfile.TemporaryDirectory() as tmp, cluster(1, Path(tmp)) as address:
            with Client(address, timeout=30) as client:  # the standard worker as it is
                results[plain_name] = client.submit(timed_solve, model, design, pure=False).result()
            with DaskEvaluator(address) as ev:  # registers the worker settings
                ev.client.restart()  # a fresh worker process, as the first case had, now with the settings
                results[tuned_name] = ev.client.submit(timed_solve, model, design, pure=False).result()
        with ProcessPoolEvaluator(workers=1) as pool:
            results[pool_name] = pool._ensure_pool(model).submit(timed_solve, model, design).result()
        outcomes = [v[0] for v in results.values()]
        same = all(o.ok for o in outcomes) and all(  # type: ignore[attr-defined]
            bool((o.response.centres == outcomes[0].response.centres).all()) for o in outcomes)  # type: ignore
        print(f"repeat {r + 1}: the three responses are {'bit-identical' if same else 'DIFFERENT'}", flush=True)
        for name, (_, wall, user, system) in results.items():
            rows.append((name, (wall, user, system)))
            print(f"  {name}: {wall:.1f} s wall, {user:.1f} s user, {system:.1f} s system", flush=True)
    print(f"\none 3D solve of {args.units} units (design {design}), {args.repeat} repeat(s); {machine()}")
    best = {name: min((t for n, t in rows if n == name), key=lambda t: t[0]) for name, _ in rows}
    pool = best[pool_name]
    print("| where | wall, s (best) | user CPU, s | system CPU, s | wall against the pool |")
    print("|---|---|---|---|---|")
    for name, (wall, user, system) in best.items():
        print(f"| {name} | {wall:.1f} | {user:.1f} | {system:.1f} | {wall / pool[0]:.2f}x |")


# -- table builds ------------------------------------------------------------------------
def build(command: list[str], out: Path) -> tuple[float, dict]:
    t0 = time.perf_counter()
    done = subprocess.run([PYTHON, "-m", "pneumorph", *command, "--out", str(out), "--json"], capture_output=True,
                          text=True)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)} failed ({done.returncode}): {done.stderr.strip().splitlines()[-1:]}")
    return wall, json.loads(out.read_text())


def time_tables(args: argparse.Namespace) -> None:
    base = ["chain", "build", "--model", args.model, "--units", str(args.units), "--heldout", str(args.heldout)]
    rows = []
    tables = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for n in args.workers:
            runs = [("process pool", ["--executor", "processes", "--workers", str(n)], None)]
            runs.append(("Dask (scheduler + workers as processes)", ["--executor", "dask"], n))
            for name, options, dask_workers in runs:
                tag = f"{len(rows)}"
                cache = ["--cache", str(folder / f"cache{tag}.sqlite")]
                if dask_workers is None:
                    wall, table = build(base + options + cache, folder / f"t{tag}.json")
                else:
                    with cluster(dask_workers, folder) as address:
                        wall, table = build(base + options + ["--scheduler", address] + cache, folder / f"t{tag}.json")
                solves = int(table["metadata"]["solves"])
                rows.append((name, n, wall, solves))
                tables.append(table)
                print(f"{name}, {n} worker(s): {wall:.1f} s, {solves} solves, {60 * solves / wall:.1f} solves/min",
                      flush=True)
    keys = ("window", "windows", "turn_rad", "length_mm", "end_windows", "end_turn_rad", "training", "validation",
            "fingerprint")
    same = all(all(t.get(k) == tables[0].get(k) for k in keys) for t in tables)
    print(f"\n`pneumorph {' '.join(base)}` (a fresh cache each); {machine()}")
    print(f"every build wrote the same table (fit, training designs, validation): {same}")
    print("| executor | workers | wall, s | FE solves | solves per minute |")
    print("|---|---|---|---|---|")
    for name, n, wall, solves in rows:
        print(f"| {name} | {n} | {wall:.1f} | {solves} | {60 * solves / wall:.1f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    s = sub.add_parser("solve", help="one 3D solve: pool against a standard Dask worker")
    s.add_argument("--units", type=int, default=15)
    s.add_argument("--repeat", type=int, default=1)
    t = sub.add_parser("table", help="a chain table build: pool against 1 and 2 Dask workers")
    t.add_argument("--model", choices=["2d", "3d"], default="2d")
    t.add_argument("--units", type=int, default=15)
    t.add_argument("--heldout", type=int, default=20)
    t.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    args = parser.parse_args()
    (time_solve if args.what == "solve" else time_tables)(args)


if __name__ == "__main__":
    main()

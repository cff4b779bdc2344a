"""The bench under load: latency of design queries from concurrent clients against 127.0.0.1.

    python benchmarks/bench_server.py                       # 20 clients, 15 queries each
    python benchmarks/bench_server.py --clients 20 --queries 15 --think 0

Starts ``pneumorph serve`` in a subprocess (a fresh state folder and cache), waits for it,
and runs ``--clients`` clients at once, each sending ``--queries`` design queries one after
the other (after ``--think`` seconds of a user's pause, drawn uniformly from [0, 2 think]).
Every query is a different target (a sin or cos preset with a random amplitude and number of
periods, a profile expression or a drawn curve), so no answer comes from the bench's memo.
The run is bounded in count and in time (``--timeout``). Prints the percentiles of the
latency seen by the clients (request sent to answer read), the throughput and the machine.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import platform
import random
import socket
import subprocess
import sys
import tempfile
import time

import httpx
import numpy as np


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def query(rng: random.Random) -> dict:
    kind = rng.choice(["preset", "preset", "expression", "curve"])
    if kind == "preset":
        target = {"kind": "preset", "name": rng.choice(["sin", "cos"]), "amplitude": round(rng.uniform(2, 30), 6),
                  "periods": round(rng.uniform(0.5, 2.0), 6)}
    elif kind == "expression":
        a, b = rng.uniform(0.05, 0.4), rng.uniform(-0.002, 0.002)
        target = {"kind": "expression", "expression": f"y = {a:.6f}*x + {b:.6f}*x**2"}
    else:
        x = np.linspace(0, 157.5, 80)
        y = rng.uniform(5, 25) * np.sin(np.pi * x / 157.5 * rng.uniform(0.5, 2.5))
        target = {"kind": "curve", "points": np.c_[x, y].round(3).tolist()}
    return {"target": target, "model": rng.choice(["3d", "3d", "2d"]), "top": 10}


async def client(url: str, n: int, think: float, seed: int, out: list[float], errors: list[str],
                 deadline: float) -> None:
    rng = random.Random(seed)
    async with httpx.AsyncClient(base_url=url, timeout=30.0) as http:
        for _ in range(n):
            if time.monotonic() > deadline:
                return
            if think > 0:
                await asyncio.sleep(rng.uniform(0, 2 * think))
            body = query(rng)
            t = time.perf_counter()
            r = await http.post("/api/design", json=body)
            r.read()
            out.append(time.perf_counter() - t)
            if r.status_code != 200 or r.json().get("memo"):
                errors.append(f"{r.status_code} {r.text[:100]}")


async def load(url: str, clients: int, queries: int, think: float,
               timeout: float) -> tuple[list[float], list[str], float]:
    out: list[float] = []
    errors: list[str] = []
    start = time.monotonic()
    await asyncio.gather(*(client(url, queries, think, seed, out, errors, start + timeout) for seed in range(clients)))
    return out, errors, time.monotonic() - start


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clients", type=int, default=20)
    ap.add_argument("--queries", type=int, default=15, help="queries per client")
    ap.add_argument("--think", type=float, default=0.0, help="mean pause between a client's queries, s")
    ap.add_argument("--timeout", type=float, default=300.0, help="stop sending after this many seconds")
    args = ap.parse_args()
    port = free_port()
    url = f"http://127.0.0.1:{port}"
    with tempfile.TemporaryDirectory() as tmp:
        server = subprocess.Popen([sys.executable, "-m", "pneumorph", "serve", "--port", str(port), "--state",
                                   f"{tmp}/state", "--cache", f"{tmp}/cache.sqlite"], stdout=subprocess.DEVNULL)
        try:
            for _ in range(300):
                try:
                    if httpx.get(f"{url}/api/info", timeout=1.0).status_code == 200:
                        break
                except httpx.HTTPError:
                    time.sleep(0.1)
            else:
                raise SystemExit("the server did not start")
            for model in ("3d", "2d"):  # first answers load the tables: not part of the load
                httpx.post(f"{url}/api/design", json={"target": {"kind": "preset", "name": "sin"}, "model": model},
                           timeout=60.0)
            lat, errors, wall = asyncio.run(load(url, args.clients, args.queries, args.think, args.timeout))
        finally:
            server.terminate()
            server.wait(10)
    ms = np.asarray(lat) * 1e3
    print(f"machine: {platform.node()} {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"{platform.machine()}")
    print(f"{args.clients} clients x {args.queries} queries, think {args.think:g} s: {len(ms)} answered in "
          f"{wall:.1f} s ({len(ms) / wall:.1f} per s), {len(errors)} errors")
    print(f"latency ms: p50 {np.percentile(ms, 50):.0f}, p95 {np.percentile(ms, 95):.0f}, "
          f"p99 {np.percentile(ms, 99):.0f}, max {ms.max():.0f}")
    for e in errors[:5]:
        print("  error:", e)


if __name__ == "__main__":
    main()

"""The bench with slow queries in flight: every answer worker's peak memory and the plain queries' latency.

    python benchmarks/bench_budgets.py                  # 2 query clients, the two spatial tip queries at 2 s
    python benchmarks/bench_budgets.py --clients 2 --think 0.2

Starts ``pneumorph serve`` in a subprocess (a fresh state folder and cache, the default
options); ``--clients`` clients send plain design queries (3D and 2D, ``--think`` seconds
apart on average) while two queries of the spatial library's chain in space, the tip goals
``max-x`` and ``min-y``, are sent at once, and a third one while they are in flight (it is to
be refused). Prints the plain queries' latency percentiles while the slow ones were in
flight, what each slow query got back and how long it took, and the peak resident memory of
the server and of each of its answer workers (sampled every 0.1 s).
"""

from __future__ import annotations

import argparse
import asyncio
import os
import platform
import random
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import httpx
import numpy as np
import psutil

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_probe import free_port, query, serve

SLOW = [{"target": {"kind": "tip", "goal": "max-x"}, "unit": "spatial"},
        {"target": {"kind": "tip", "goal": "min-y"}, "unit": "spatial"}]


class Peaks(threading.Thread):
    """Peak resident memory of the server and of each of its descendants (by pid), sampled every 0.1 s."""

    def __init__(self, pid: int) -> None:
        super().__init__(daemon=True)
        self.proc = psutil.Process(pid)
        self.peaks: dict[int, float] = {}
        self.running = True

    def run(self) -> None:
        while self.running:
            try:
                procs = [self.proc, *self.proc.children(recursive=True)]
            except psutil.Error:
                return
            for p in procs:
                try:
                    self.peaks[p.pid] = max(self.peaks.get(p.pid, 0.0), p.memory_info().rss / 1e6)
                except psutil.Error:
                    continue
            time.sleep(0.1)


async def plain(url: str, seed: int, think: float, stop: asyncio.Event, out: list[tuple[float, float]]) -> None:
    rng = random.Random(seed)
    async with httpx.AsyncClient(base_url=url, timeout=120.0) as http:
        while not stop.is_set():
            await asyncio.sleep(rng.uniform(0, 2 * think))
            t = time.perf_counter()
            r = await http.post("/api/design", json=query(rng))
            r.read()
            out.append((t, time.perf_counter() - t))


async def slow(url: str, body: dict) -> dict:
    async with httpx.AsyncClient(base_url=url, timeout=600.0) as http:
        t = time.perf_counter()
        r = await http.post("/api/design", json=body)
        took = time.perf_counter() - t
        if r.status_code == 200:
            c = r.json()["certificate"]
            return {"status": 200, "seconds": round(took, 1), "winner": r.json()["winner"]["design"],
                    "certified": c["certified"], "start": t, "end": t + took}
        return {"status": r.status_code, "seconds": round(took, 1), "error": r.text[:200], "start": t, "end": t + took}


async def run(url: str, clients: int, think: float) -> tuple[list[tuple[float, float]], list[dict], dict]:
    lat: list[tuple[float, float]] = []
    stop = asyncio.Event()
    load = [asyncio.create_task(plain(url, seed, think, stop, lat)) for seed in range(clients)]
    await asyncio.sleep(2.0)
    first = [asyncio.create_task(slow(url, body)) for body in SLOW]
    await asyncio.sleep(1.0)
    third = await slow(url, {**SLOW[0], "top": 5})
    answers = await asyncio.gather(*first)
    stop.set()
    await asyncio.gather(*load)
    return lat, list(answers), third


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clients", type=int, default=2)
    ap.add_argument("--think", type=float, default=0.2, help="mean pause between a client's queries (s)")
    args = ap.parse_args()
    port = free_port()
    with tempfile.TemporaryDirectory() as tmp:
        server, url = serve(Path(tmp), port)
        try:
            peaks = Peaks(server.pid)
            peaks.start()
            lat, answers, third = asyncio.run(run(url, args.clients, args.think))
            peaks.running = False
        finally:
            server.send_signal(signal.SIGINT)
            try:
                server.wait(30)
            except subprocess.TimeoutExpired:
                os.killpg(server.pid, signal.SIGKILL)
    lo, hi = min(a["start"] for a in answers), max(a["end"] for a in answers)
    during = np.asarray([d for t, d in lat if lo <= t <= hi]) * 1e3
    print(f"machine: {platform.node()}, {os.cpu_count()} cores, Python {platform.python_version()}")
    for body, a in zip(SLOW, answers, strict=True):
        print(f"slow query {body['target']['goal']}: {({k: v for k, v in a.items() if k not in ('start', 'end')})}")
    print(f"a third slow query while they ran: {({k: v for k, v in third.items() if k not in ('start', 'end')})}")
    if during.size:
        print(f"plain /api/design while the slow ones ran ({hi - lo:.0f} s): {during.size} answers, latency ms p50 "
              f"{np.percentile(during, 50):.1f}, p95 {np.percentile(during, 95):.1f}, max {during.max():.1f}")
    print("peak memory, MB: " + ", ".join(f"{'server' if pid == server.pid else pid} {mb:.0f}"
                                          for pid, mb in sorted(peaks.peaks.items(), key=lambda kv: -kv[1])))


if __name__ == "__main__":
    main()

"""The bench under hostile probes: answers stay fast, memory bounded, cross-site requests refused.

    python benchmarks/bench_probe.py                    # 4 query clients for 30 s, every probe once
    python benchmarks/bench_probe.py --clients 4 --seconds 30 --think 0.1

Starts ``pneumorph serve`` in a subprocess (a fresh state folder and cache, the default
options) and, while ``--clients`` clients send design queries (each a different target,
``--think`` seconds apart on average), sends these probes:

- hostile uploads: a unit with ``pitch = 1e4`` (which grew a job's worker by 150 MB/s), one
  whose mesh would be 0.8 million nodes, and a 200 MB multipart upload streamed in chunks;
- a 300 MB chunked JSON body (no Content-Length);
- 50 job requests (exports) from one session and 50 from 50 new sessions;
- cross-site requests: a ``text/plain`` POST, a JSON POST and a multipart upload from
  another origin, a POST with ``Sec-Fetch-Site: cross-site``, a cross-site DELETE, and
  requests naming a foreign host (DNS rebinding).

Prints the latency percentiles of ``/api/design`` during the probes, the peak memory of the
server process (and of the server with its answer and job processes), what each probe got
back, how long the server takes to stop on SIGINT (Ctrl-C) with its jobs still queued or
running and the jobs' states then, and the machine.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import platform
import random
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import httpx
import numpy as np
import psutil


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def serve(tmp: Path, port: int, env: dict[str, str] | None = None) -> tuple[subprocess.Popen[bytes], str]:
    """A ``pneumorph serve`` on ``port`` with its state and cache in ``tmp``, its URL once it answers."""
    server = subprocess.Popen([sys.executable, "-m", "pneumorph", "serve", "--port", str(port), "--state",
                               str(tmp / "state"), "--cache", str(tmp / "cache.sqlite")], env=env,
                              start_new_session=True)
    url = f"http://127.0.0.1:{port}"
    for _ in range(600):
        try:
            if httpx.get(url + "/api/info", timeout=5).status_code == 200:
                break
        except httpx.HTTPError:
            time.sleep(0.2)
    return server, url


def query(rng: random.Random) -> dict:
    kind = rng.choice(["preset", "preset", "expression"])
    if kind == "preset":
        target = {"kind": "preset", "name": rng.choice(["sin", "cos"]), "amplitude": round(rng.uniform(2, 30), 6),
                  "periods": round(rng.uniform(0.5, 2.0), 6)}
    else:
        a = rng.uniform(0.05, 0.4)
        target = {"kind": "expression", "expression": f"y = {a:.6f}*x"}
    return {"target": target, "model": rng.choice(["3d", "3d", "2d"]), "top": 10}


class Memory(threading.Thread):
    """Peak resident memory of the server process, and of it with all its descendants, sampled every 0.1 s."""

    def __init__(self, pid: int) -> None:
        super().__init__(daemon=True)
        self.proc = psutil.Process(pid)
        self.server = self.total = 0.0
        self.running = True

    def run(self) -> None:
        while self.running:
            try:
                own = self.proc.memory_info().rss
                rest = 0
                for child in self.proc.children(recursive=True):
                    try:
                        rest += child.memory_info().rss
                    except psutil.Error:
                        continue
            except psutil.Error:
                return
            self.server, self.total = max(self.server, own / 1e6), max(self.total, (own + rest) / 1e6)
            time.sleep(0.1)


def stream(port: int, head: bytes, chunk: bytes, total: int) -> dict:
    """Send a chunked body until ``total`` bytes or until the server stops reading; what came back."""
    sent, t = 0, time.perf_counter()
    with socket.create_connection(("127.0.0.1", port), timeout=60) as sock:
        sock.sendall(head)
        try:
            while sent < total:
                sock.sendall(b"%x\r\n" % len(chunk) + chunk + b"\r\n")
                sent += len(chunk)
            sock.sendall(b"0\r\n\r\n")
        except (BrokenPipeError, ConnectionResetError):
            pass
        answer = b""
        try:
            while len(answer) < 4096:
                part = sock.recv(4096)
                if not part:
                    break
                answer += part
        except (ConnectionResetError, TimeoutError):
            pass
    status = answer.split(b" ", 2)[1].decode() if answer.startswith(b"HTTP/") else "no answer"
    return {"status": status, "sent_mb": round(sent / 1e6, 1), "seconds": round(time.perf_counter() - t, 2)}


def chunked_body(port: int) -> dict:
    head = (f"POST /api/design HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n"
            "Transfer-Encoding: chunked\r\n\r\n").encode()
    return stream(port, head, b" " * (1 << 20), 300 << 20)


def streamed_upload(port: int) -> dict:
    boundary = "pr0be"
    head = (f"POST /api/jobs/table HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
            f"Content-Type: multipart/form-data; boundary={boundary}\r\nTransfer-Encoding: chunked\r\n\r\n").encode()
    part = (f"--{boundary}\r\nContent-Disposition: form-data; name=\"unit\"; filename=\"u.toml\"\r\n\r\n").encode()
    return stream(port, head + b"%x\r\n" % len(part) + part + b"\r\n", b"#" * (1 << 20), 200 << 20)


async def designs(url: str, seed: int, think: float, until: float, out: list[float], errors: list[str]) -> None:
    rng = random.Random(seed)
    async with httpx.AsyncClient(base_url=url, timeout=30.0) as http:
        while time.monotonic() < until:
            await asyncio.sleep(rng.uniform(0, 2 * think))
            t = time.perf_counter()
            r = await http.post("/api/design", json=query(rng))
            r.read()
            out.append(time.perf_counter() - t)
            if r.status_code != 200:
                errors.append(f"{r.status_code} {r.text[:100]}")


async def probes(url: str, port: int) -> dict:
    out: dict = {}
    async with httpx.AsyncClient(base_url=url, timeout=60.0) as http:
        # hostile uploads
        for name, text in [("pitch 1e4", "[unit]\npitch = 1e4\n"), ("pitch 400", "[unit]\npitch = 400.0\n")]:
            r = await http.post("/api/jobs/table", files={"unit": ("u.toml", text.encode())}, data={"model": "3d"})
            out[f"upload {name}"] = f"{r.status_code} {r.json()['error']['message'][:90]}"
        out["upload 200 MB streamed"] = await asyncio.to_thread(streamed_upload, port)
        # 50 job requests from one session, 50 from 50 sessions
        codes: list[int] = []
        for i in range(50):
            r = await http.post("/api/jobs", json={"kind": "export", "design": format(i, "015b")})
            codes.append(r.status_code)
        out["50 jobs, one session"] = {str(c): codes.count(c) for c in sorted(set(codes))}
        codes = []
        for i in range(50):
            async with httpx.AsyncClient(base_url=url, timeout=60.0) as fresh:
                r = await fresh.post("/api/jobs", json={"kind": "export", "design": format(i + 50, "015b")})
                codes.append(r.status_code)
        out["50 jobs, 50 sessions"] = {str(c): codes.count(c) for c in sorted(set(codes))}
        # cross-site requests
        evil = "http://evil.example"
        job = json.dumps({"kind": "export", "design": "0" * 15}).encode()
        cross = [
            ("text/plain POST", http.post("/api/jobs", content=job, headers={"Origin": evil,
                                                                              "Content-Type": "text/plain"})),
            ("text/plain POST, no Origin", http.post("/api/jobs", content=job, headers={"Content-Type": "text/plain"})),
            ("JSON POST", http.post("/api/design", json={"target": {"kind": "preset"}}, headers={"Origin": evil})),
            ("multipart upload", http.post("/api/jobs/table", files={"unit": ("u.toml", b"[unit]\n")},
                                           data={"model": "2d"}, headers={"Origin": evil})),
            ("Sec-Fetch-Site cross-site", http.post("/api/design", json={"target": {"kind": "preset"}},
                                                    headers={"Sec-Fetch-Site": "cross-site"})),
            ("DELETE", http.delete("/api/jobs/x", headers={"Origin": evil})),
            ("foreign Host GET", http.get("/api/jobs", headers={"Host": "rebound.example"})),
            ("foreign Host POST", http.post("/api/design", json={"target": {"kind": "preset"}},
                                            headers={"Host": f"rebound.example:{port}"})),
        ]
        results = {name: (await req).status_code for name, req in cross}
        out["cross-site"] = results
        out["cross-site accepted"] = sum(code < 400 for code in results.values())
    return out


async def run(url: str, port: int, clients: int, seconds: float, think: float) -> tuple[list[float], list[str], dict,
                                                                                       list[float]]:
    lat: list[float] = []
    errors: list[str] = []
    until = time.monotonic() + seconds
    load = [asyncio.create_task(designs(url, seed, think, until, lat, errors)) for seed in range(clients)]
    await asyncio.sleep(2.0)  # the clients run alone first
    quiet = list(lat)
    chunked = asyncio.to_thread(chunked_body, port)
    found, chunk = await asyncio.gather(probes(url, port), chunked)
    found["300 MB chunked body"] = chunk
    await asyncio.gather(*load)
    return lat, errors, found, quiet


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clients", type=int, default=4)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--think", type=float, default=0.1, help="mean pause between a client's queries (s)")
    args = ap.parse_args()
    port = free_port()
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "TMPDIR": tmp}
        state = Path(tmp) / "state"
        server, url = serve(Path(tmp), port, env)
        try:
            memory = Memory(server.pid)
            memory.start()
            lat, errors, found, _quiet = asyncio.run(run(url, port, args.clients, args.seconds, args.think))
            memory.running = False
            spooled = [p.name for p in Path(tmp).iterdir() if p.name not in ("state", "cache.sqlite")
                       and not p.name.startswith(("cache.sqlite", "chain-tables"))]
        finally:
            t = time.perf_counter()
            server.send_signal(signal.SIGINT)  # as Ctrl-C: jobs still queued or running are stopped
            try:
                server.wait(30)
                stop = f"{time.perf_counter() - t:.1f} s"
            except subprocess.TimeoutExpired:
                os.killpg(server.pid, signal.SIGKILL)
                stop = "not within 30 s (killed)"
            states: dict[str, int] = {}
            for record in state.glob("jobs/*/job.json"):
                job_state = json.loads(record.read_text())["state"]
                states[job_state] = states.get(job_state, 0) + 1
    ms = np.asarray(lat) * 1e3
    print(f"machine: {platform.node()}, {os.cpu_count()} cores, {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}")
    print(f"/api/design during the probes: {len(ms)} answers from {args.clients} clients in {args.seconds:g} s "
          f"(think {args.think:g} s), {len(errors)} errors")
    print(f"  latency ms: p50 {np.percentile(ms, 50):.1f}, p95 {np.percentile(ms, 95):.1f}, "
          f"p99 {np.percentile(ms, 99):.1f}, max {ms.max():.1f}")
    print(f"peak memory: server process {memory.server:.0f} MB, with its answer and job processes "
          f"{memory.total:.0f} MB")
    print(f"files left in the server's temporary folder: {spooled or 'none'}")
    for name, value in found.items():
        print(f"{name}: {value}")
    print(f"Ctrl-C (SIGINT) after the probes: the server ended in {stop}; jobs by state: {states}")
    for e in errors[:5]:
        print("  error:", e)


if __name__ == "__main__":
    main()

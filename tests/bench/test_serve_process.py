"""``pneumorph serve`` as a user runs it: a real server process, raw sockets, Ctrl-C and SIGTERM.

What a test client cannot show: a chunked body of 300 MB and a streamed 200 MB multipart
upload are refused after the limit without being read (the server's memory stays small and
nothing is spooled to disk), and Ctrl-C or SIGTERM end a running job's processes at once,
the job marked interrupted.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("uvicorn")
psutil = pytest.importorskip("psutil")
import httpx  # noqa: E402


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class Server:
    def __init__(self, root: Path) -> None:
        self.port = _free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.tmp = root / "tmp"
        self.tmp.mkdir(parents=True, exist_ok=True)
        self.state = root / "state"
        env = {**os.environ, "TMPDIR": str(self.tmp), "OMP_NUM_THREADS": "1"}
        self.proc = subprocess.Popen([sys.executable, "-m", "pneumorph", "serve", "--port", str(self.port), "--state",
                                      str(self.state), "--cache", str(root / "cache.sqlite")],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, start_new_session=True)
        end = time.monotonic() + 120
        while time.monotonic() < end:
            try:
                if httpx.get(self.url + "/api/info", timeout=5).status_code == 200:
                    return
            except httpx.HTTPError:
                pass
            assert self.proc.poll() is None, self.proc.stderr.read().decode() if self.proc.stderr else ""
            time.sleep(0.3)
        raise AssertionError("the bench did not start")

    def rss_mb(self) -> float:
        return float(psutil.Process(self.proc.pid).memory_info().rss / 1e6)

    def stop(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait(10)


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory):  # type: ignore[no-untyped-def]
    srv = Server(tmp_path_factory.mktemp("serve"))
    yield srv
    srv.stop()


def _stream(port: int, head: bytes, chunk: bytes, total: int) -> tuple[int, bytes]:
    """Send ``head`` then ``chunk`` in HTTP chunked encoding until ``total`` bytes or the server stops reading.

    Returns the body bytes sent and the start of what the server answered.
    """
    sent = 0
    with socket.create_connection(("127.0.0.1", port), timeout=30) as sock:
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
    return sent, answer


def test_a_300_mb_chunked_body_is_refused_without_being_read(server: Server) -> None:
    head = (f"POST /api/design HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\nContent-Type: application/json\r\n"
            "Transfer-Encoding: chunked\r\n\r\n").encode()
    before = server.rss_mb()
    sent, answer = _stream(server.port, head, b" " * (1 << 20), 300 << 20)
    assert answer.startswith(b"HTTP/1.1 413"), answer[:200]
    assert b'"field":"body"' in answer
    assert sent < 100 << 20  # the server stopped reading at 1 MB (the rest is in socket buffers)
    assert server.rss_mb() < before + 50  # read whole, the body took the server to 705 MB


def test_a_200_mb_streamed_upload_is_refused_and_nothing_is_spooled_to_disk(server: Server) -> None:
    boundary = "b0undary"
    head = (f"POST /api/jobs/table HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\n"
            f"Content-Type: multipart/form-data; boundary={boundary}\r\nTransfer-Encoding: chunked\r\n\r\n").encode()
    part = (f"--{boundary}\r\nContent-Disposition: form-data; name=\"unit\"; filename=\"u.toml\"\r\n"
            "Content-Type: application/octet-stream\r\n\r\n").encode()
    before = server.rss_mb()
    sent, answer = _stream(server.port, head + b"%x\r\n" % len(part) + part + b"\r\n", b"#" * (1 << 20), 200 << 20)
    assert answer.startswith(b"HTTP/1.1 413"), answer[:200]
    assert sent < 100 << 20
    assert list(server.tmp.iterdir()) == []  # not 200 MB in a temporary file before the 64 kB check
    assert server.rss_mb() < before + 50


def test_cross_site_and_foreign_host_requests_are_refused_by_the_real_server(server: Server) -> None:
    evil = {"Origin": "http://evil.example", "Content-Type": "text/plain"}
    r = httpx.post(server.url + "/api/jobs", content=b'{"kind": "export", "design": "000000000000000"}',
                   headers=evil)
    assert r.status_code == 403
    r = httpx.get(server.url + "/api/info", headers={"Host": "rebound.example"})
    assert r.status_code == 400 and r.json()["error"]["field"] == "host"


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_and_sigterm_stop_a_running_job_at_once(tmp_path: Path, sig: signal.Signals) -> None:
    srv = Server(tmp_path)
    try:
        unit = b"[unit]\nlayer = 2.5\nname = \"slow\"\n"  # a new unit: its 2D table takes minutes to build
        r = httpx.post(srv.url + "/api/jobs/table", files={"unit": ("u.toml", unit)}, data={"model": "2d"})
        assert r.status_code == 202, r.text
        job_id, cookies = r.json()["job_id"], r.cookies
        end = time.monotonic() + 60
        while time.monotonic() < end:  # until its FE workers solve
            job = httpx.get(f"{srv.url}/api/jobs/{job_id}", cookies=cookies).json()
            if "solved" in job["message"]:
                break
            time.sleep(0.3)
        assert job["state"] == "running" and "solved" in job["message"], job
        family = psutil.Process(srv.proc.pid).children(recursive=True)  # answer workers, the job and its FE workers
        t = time.monotonic()
        os.kill(srv.proc.pid, sig)
        srv.proc.wait(30)
        stopped = time.monotonic() - t
        assert stopped < 10, f"the server took {stopped:.1f} s to stop"  # not the 79 s of waiting for a 3D verification
        _, alive = psutil.wait_procs(family, timeout=5)
        assert not alive, [p.cmdline() for p in alive]
        record = next(srv.state.glob("jobs/*/job.json"))
        assert json.loads(record.read_text())["state"] == "interrupted"
    finally:
        srv.stop()


def test_the_missing_web_extra_is_named_with_the_install_command_of_a_wheel(monkeypatch, capsys) -> None:
    """Without the web extra: one line, exit 2, `pip install "pneumorph[web]"` (quoted for every shell; the editable
    install of a checkout only as the second way)."""
    import sys

    from pneumorph.cli import main

    monkeypatch.setitem(sys.modules, "uvicorn", None)  # an import of it raises ImportError
    assert main(["serve", "--port", "8765"]) == 2  # refused before the port is bound
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'uvicorn is missing): pip install "pneumorph[web]" (in a checkout' in err

"""Every text input is read bounded: regular files only, at most a size per kind, refused in one line before it
costs (a device such as /dev/zero, a named pipe, a folder, a file of 1 GB)."""

from __future__ import annotations

import codecs
import os
import re
import signal
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.errors import SettingsError
from pneumorph.io.files import MAX_TEXT_BYTES, read_text_file


@pytest.fixture(autouse=True)
def no_hang() -> Iterator[None]:
    """A read that blocks (a pipe opened for reading waits for a writer) fails the test instead of hanging it."""
    def hung(signum: int, frame: object) -> None:
        raise AssertionError("the input was read or waited on instead of refused")
    previous = signal.signal(signal.SIGALRM, hung)
    signal.alarm(30)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


@pytest.fixture
def fifo(tmp_path: Path) -> Path:
    path = tmp_path / "pipe.toml"
    os.mkfifo(path)
    return path


@pytest.fixture
def huge(tmp_path: Path) -> Path:
    """A file of 1 GB that takes no disk (sparse)."""
    path = tmp_path / "huge.toml"
    with path.open("wb") as fh:
        fh.truncate(2**30)
    return path


def test_a_device_a_pipe_a_folder_and_a_huge_file_are_refused_by_name(tmp_path: Path, fifo: Path,
                                                                      huge: Path) -> None:
    with pytest.raises(SettingsError, match="not a regular file"):
        read_text_file("/dev/zero", "design config")
    with pytest.raises(SettingsError, match="not a regular file"):
        read_text_file(fifo, "design config")  # refused before it is opened: opening would block
    with pytest.raises(SettingsError, match="is a folder"):
        read_text_file(tmp_path, "design config")
    with pytest.raises(SettingsError, match=r"1024 MB, more than the 64 MB a design config may have"):
        read_text_file(huge, "design config")


def test_the_limit_holds_for_a_file_that_reports_no_size(tmp_path: Path) -> None:
    small = tmp_path / "a.txt"
    small.write_text("x" * 100)
    assert read_text_file(small, "path file", limit=100) == "x" * 100
    with pytest.raises(SettingsError, match=r"100 bytes|more than the 9\.44\d*e-05 MB"):
        read_text_file(small, "path file", limit=99)
    status = Path("/proc/self/status")  # a regular file whose size is reported as 0
    assert status.stat().st_size == 0
    with pytest.raises(SettingsError, match=r"status: more than the"):
        read_text_file(status, "path file", limit=10)
    assert MAX_TEXT_BYTES == 64 * 2**20


@pytest.mark.parametrize("args", [
    ["design", "{bad}"],
    ["design", "--library", "{bad}"],
    ["design", "--unit", "{bad}"],
    ["design", "--chain-table", "{bad}"],
    ["design", "--target", "path:{bad}"],
    ["materials", "fit", "{bad}"],
])
@pytest.mark.parametrize("kind", ["device", "pipe", "huge"])
def test_path_inputs_refuse_them_in_one_line_at_once(args: list[str], kind: str, fifo: Path, huge: Path,
                                                     tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = {"device": "/dev/zero", "pipe": str(fifo), "huge": str(huge)}[kind]
    out = tmp_path / "run"
    code = main([a.replace("{bad}", bad) for a in args] + (["--out", str(out)] if args[0] == "design" else []))
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and "Traceback" not in err and "internal error" not in err
    assert ("regular file" in err) if kind != "huge" else ("MB" in err and "may have" in err)
    assert not out.exists()


@pytest.mark.parametrize("levels", [33, 100_000])
def test_a_chain_table_nested_too_deep_is_refused_in_one_line(levels: int, tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    """Through the one bounded JSON reader: past MAX_JSON_DEPTH (32) levels, whether Python's parser could follow
    (33 objects) or not (100,000 arrays)."""
    deep = tmp_path / "deep.json"
    deep.write_text('{"a": ' * levels + "1" + "}" * levels)
    out = tmp_path / "run"
    assert main(["design", "--chain-table", str(deep), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "internal error" not in err
    assert err.endswith(f"chain table {deep}: nested more than 32 levels deep (MAX_JSON_DEPTH)")
    assert not out.exists()


def test_a_chain_table_past_its_size_is_refused_in_one_line(tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    """A sparse file of 1 GB named as the chain table (bigger than MAX_TEXT_BYTES, 64 MB): refused by its size."""
    from pneumorph.errors import ChainTableError
    from pneumorph.models.chain.table import ChainTable

    huge = tmp_path / "huge.json"
    with huge.open("wb") as fh:
        fh.truncate(2**30)
    with pytest.raises(ChainTableError, match=r"1024 MB, more than the 64 MB a chain table may have"):
        ChainTable.load(huge)


def test_a_scan_listed_twice_in_a_manifest_is_refused(tmp_path: Path) -> None:
    from pneumorph.identify.scans import read_manifest

    manifest = tmp_path / "scans.toml"
    entry = '[[scan]]\nfile = "a.xyz"\ndesign = "0110"\npressure_kpa = 30\n'
    manifest.write_text(entry + '[[scan]]\nfile = "b.xyz"\ndesign = "0110"\npressure_kpa = 30\n' + entry)
    with pytest.raises(SettingsError, match=r"\[\[scan\]\] 3: the same scan at the same pressure as \[\[scan\]\] 1"):
        read_manifest(manifest)
    manifest.write_text(entry + entry.replace("30", "36"))  # one cast scanned at two pressures: two scans
    assert [s.pressure_kpa for s in read_manifest(manifest)] == [30.0, 36.0]


def _saved_response(tmp_path: Path) -> Path:
    from pneumorph.models import Response

    p = np.linspace(0.01, 0.02, 2)
    Response.empty("01", p, np.zeros((2, 2)), np.array([21.0, 0.0]), converged=True, reached=0.02).save(
        tmp_path / "resp")
    return tmp_path / "resp.json"


@pytest.mark.parametrize("kind", ["deep", "huge", "latin-1", "not a response"])
def test_a_response_file_is_read_by_the_one_reader(kind: str, tmp_path: Path) -> None:
    """Response.load refuses in one line naming the file what the bounded JSON reader refuses."""
    from pneumorph.errors import DataFormatError
    from pneumorph.models import Response

    js = _saved_response(tmp_path)
    if kind == "deep":
        js.write_text("[" * 100_000 + "]" * 100_000)
    elif kind == "huge":
        with js.open("wb") as fh:
            fh.truncate(2**30)
    elif kind == "latin-1":
        js.write_bytes(js.read_bytes().replace(b'"01"', b'"0\xe9"'))
    else:
        js.write_text('{"orientation": "01"}')
    expected = {"deep": "nested more than 32 levels deep (MAX_JSON_DEPTH)", "huge": "more than the 64 MB",
                "latin-1": "not UTF-8 text: byte 0xe9", "not a response": "not a response file (KeyError"}[kind]
    with pytest.raises(DataFormatError, match=re.escape(expected)) as info:
        Response.load(tmp_path / "resp")
    assert str(info.value).startswith(f"response {js}") and "\n" not in str(info.value)


def test_a_response_file_with_a_byte_order_mark_is_read(tmp_path: Path) -> None:
    from pneumorph.models import Response

    js = _saved_response(tmp_path)
    js.write_bytes(codecs.BOM_UTF8 + js.read_bytes())
    back = Response.load(tmp_path / "resp")
    assert back.orientation == "01" and back.converged and back.reached == 0.02


def test_a_run_folders_config_nested_too_deep_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The config.toml of an output folder (compared to resume a run) goes through the one TOML reader: nested
    past its parser's recursion, it is refused in one line, exit 2, the folder left as it was."""
    out = tmp_path / "run"
    out.mkdir()
    body = "[design]\nobjective = " + "[" * 100_000 + "]" * 100_000 + "\n"
    (out / "config.toml").write_text(body)
    assert main(["design", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "internal error" not in err and "Traceback" not in err
    assert f"config.toml {out / 'config.toml'}: nested more than 32 levels deep (MAX_TOML_DEPTH)" in err
    assert [p.name for p in out.iterdir()] == ["config.toml"] and (out / "config.toml").read_text() == body


@pytest.mark.parametrize("levels", [40, 10_000])  # what Python's parser follows, and what it cannot (in 64 kB)
def test_an_uploaded_unit_nested_too_deep_is_refused_by_the_one_reader(levels: int) -> None:
    """The bench's unit upload is parsed as a unit file is read: past MAX_TOML_DEPTH, one line naming the field."""
    from pneumorph.bench.app import read_unit
    from pneumorph.bench.query import QueryError

    with pytest.raises(QueryError, match=re.escape("the unit file: nested more than 32 levels deep (MAX_TOML_DEPTH)")):
        read_unit(("[unit]\npitch = " + "[" * levels + "]" * levels + "\n").encode())


def test_a_pipe_in_place_of_an_old_runs_report_is_not_read(tmp_path: Path) -> None:
    """The files an earlier run wrote are listed from its report.md: a named pipe in its place is passed over (read,
    it would wait for a writer), the run's own files still found."""
    from pneumorph.design.runs.folder import run_files

    os.mkfifo(tmp_path / "report.md")
    (tmp_path / "config.toml").write_text("[design]\n")
    assert run_files(tmp_path) == [tmp_path / "config.toml"]


def test_a_pipe_in_place_of_a_lock_file_is_not_waited_on(tmp_path: Path, fifo: Path) -> None:
    """Who holds a lock is read from its file: a named pipe there reads as no holder, at once."""
    from pneumorph.io.lock import FileLock

    assert FileLock.read(fifo) == {}
    (tmp_path / "held.lock").write_text("pid=12\nhost=h\n")
    assert FileLock.read(tmp_path / "held.lock") == {"pid": "12", "host": "h"}

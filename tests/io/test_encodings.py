"""Files as other tools write them: a byte-order mark read (UTF-8, UTF-16, UTF-32), another encoding refused with
where its first foreign byte is, a settings file past its kind's limit, JSON nested past its limit, scans with faces
that point past their vertices or points on a line, and a model file's fidelity checked whatever the command says."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.errors import ChainTableError, GeometryError, ScanError, SettingsError
from pneumorph.geometry.unit import UnitSpec
from pneumorph.io.reading import (
    MAX_SETTINGS_BYTES,
    check_text_file,
    read_json,
    read_text_file,
    read_toml,
)

UNIT = "[unit]\nwall = 1.75\n"


@pytest.mark.parametrize("codec", ["utf-8-sig", "utf-16", "utf-16-be", "utf-32"])
def test_a_byte_order_mark_is_read(tmp_path: Path, codec: str) -> None:
    """Notepad saves "UTF-8 with BOM" or "Unicode" (UTF-16 LE with a BOM); tomllib refused the mark as a key."""
    path = tmp_path / "unit.toml"
    data = UNIT.encode(codec)
    if codec == "utf-16-be":
        data = b"\xfe\xff" + data  # the big-endian codec writes no mark of its own
    path.write_bytes(data)
    assert read_text_file(path, "unit file") == UNIT
    assert UnitSpec.from_toml(path).wall == 1.75
    check_text_file(path, "--unit")  # the option's check agrees


def test_another_encoding_is_refused_where_it_starts(tmp_path: Path) -> None:
    path = tmp_path / "unit.toml"
    path.write_bytes(UNIT.encode() + "name = 'Gießform'\n".encode("cp1252"))
    where = r"byte 0xdf at line 3, column 12 \(text in another encoding"
    with pytest.raises(SettingsError, match=where):
        read_text_file(path, "unit file")
    with pytest.raises(SettingsError, match=where):
        check_text_file(path, "--unit", chunk=5)  # the same place, found a few bytes at a time
    with pytest.raises(GeometryError, match=where):
        UnitSpec.from_toml(path)


def test_a_settings_file_past_its_kinds_limit_is_refused_naming_it(tmp_path: Path) -> None:
    path = tmp_path / "big.toml"
    path.write_bytes(b"# " + b"x" * MAX_SETTINGS_BYTES + b"\n")
    with pytest.raises(SettingsError, match=r"8 MB, more than the 8 MB a design config may have \(MAX_SETTINGS_BYTES"):
        read_toml(path, "design config")
    assert read_text_file(path, "chain table").startswith("# x")  # the kinds with a larger limit read it


def test_json_nested_past_its_limit_is_refused_without_recursion(tmp_path: Path) -> None:
    path = tmp_path / "tables.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ChainTableError, match="nested more than 32 levels deep"):
        read_json(path, "tolerance tables", ChainTableError)
    path.write_text(json.dumps({"a": [[[[1]]]]}))
    assert read_json(path, "tolerance tables") == {"a": [[[[1]]]]}
    path.write_text(json.dumps([0.0, 1.0, 2.0]))  # a list, not tables: refused by the reader of tables
    from pneumorph.sensitivity.robust import ToleranceTables

    with pytest.raises(ChainTableError, match="not a tolerance table file"):
        ToleranceTables.load(path)


def _ply(faces: str) -> str:
    return ("ply\nformat ascii 1.0\nelement vertex 12\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {faces.count(chr(10))}\nproperty list uchar int vertex_indices\nend_header\n"
            + "".join(f"{i} {i * i % 7} {i % 3}\n" for i in range(12)) + faces)


def test_a_mesh_whose_faces_point_past_its_vertices_is_refused(tmp_path: Path) -> None:
    from pneumorph.correlation import read_scan

    path = tmp_path / "scan.ply"
    path.write_text(_ply("3 0 1 2\n3 1 2 12\n"))
    with pytest.raises(ScanError, match=r"face 2 refers to vertex 12, but the file has 12 vertices \(0 to 11\)"):
        read_scan(path)
    path.write_text(_ply("3 0 1 2\n3 1 2 11\n"))
    assert read_scan(path).faces.tolist() == [[0, 1, 2], [1, 2, 11]]


@pytest.mark.parametrize(("points", "shape"), [
    (np.c_[np.linspace(0, 40, 500), np.linspace(0, 20, 500)], "a straight line"),
    (np.c_[np.linspace(0, 40, 50), np.linspace(0, 20, 50), np.zeros(50)], "a straight line"),
    (np.c_[np.random.default_rng(1).uniform(0, 40, (50, 2)), np.full(50, 3.0)], "a plane"),
    (np.ones((20, 2)), "a single point"),
])
def test_points_without_spread_are_refused_before_any_solve(points: np.ndarray, shape: str) -> None:
    from pneumorph.correlation.scans import check_spread

    with pytest.raises(ScanError, match=f"lie on {shape}"):
        check_spread("scan", points)


def test_a_model_files_fidelity_is_checked_whatever_the_command_line_says(tmp_path: Path,
                                                                          capsys: pytest.CaptureFixture[str]) -> None:
    """``[model] fidelity = "4d"`` was accepted when --model 2d was typed (the option won over the file)."""
    model = tmp_path / "identified.toml"
    model.write_text('[model]\nfidelity = "4d"\n')
    out = tmp_path / "run"
    assert main(["design", "--model", "2d", "--model-file", str(model), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "[model] fidelity must be one of 2d, 3d, got '4d'" in err and "--model-file" in err
    assert len(err.splitlines()) == 1 and not out.exists()

"""Limits on what a unit may be, from the command line: refused before any mesh, with the estimate."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path


def _run(*args: str) -> tuple[int, str, float]:
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "pneumorph", *args], capture_output=True, text=True, timeout=120)
    return done.returncode, done.stdout + done.stderr, time.perf_counter() - start


def test_a_simulation_past_the_memory_is_refused_with_its_estimate(tmp_path: Path) -> None:
    """The command line's limit is the memory available: 15 units at 0.4 mm elements would need ~100 GB."""
    unit = tmp_path / "fine.toml"
    unit.write_text("[unit]\nelement_size = 0.4\n")
    code, out, seconds = _run("simulate", "-o", "0" * 15, "--model", "3d", "--unit", str(unit))
    assert code == 2 and "nodes" in out and "GB for one solve" in out and "GB are available" in out
    assert "Traceback" not in out and seconds < 30


def test_a_unit_file_with_a_huge_pitch_is_refused(tmp_path: Path) -> None:
    unit = tmp_path / "big.toml"
    unit.write_text("[unit]\npitch = 1e9\n")  # unbounded, a base block 1e9 mm long goes past 6 GB
    code, out, _ = _run("simulate", "-o", "0" * 15, "--model", "2d", "--unit", str(unit))
    assert code == 2 and "MAX_LENGTH_MM" in out and "Traceback" not in out


def test_list_fields_of_a_unit_file_are_checked(tmp_path: Path) -> None:
    """Text in a unit's list fields is a one-line refusal naming the field, not an internal error."""
    for body, message in (('filler_coefficients = ["a", "b"]', "filler_coefficients must be a list of numbers"),
                          ('filler_range_kpa = "x"', "filler_range_kpa must be a list of 2 numbers"),
                          ("filler_range_kpa = [45, 0]", "must rise from its low to its high pressure"),
                          ("filler_coefficients = [true, 1]", "filler_coefficients must be a list of numbers")):
        unit = tmp_path / "u.toml"
        unit.write_text(f"[unit]\n{body}\n")
        code, out, _ = _run("simulate", "-o", "01", "--unit", str(unit))
        assert code == 2 and message in out and "internal error" not in out, out


def test_an_actuator_of_solid_units_only_is_refused(tmp_path: Path) -> None:
    unit = tmp_path / "solid.toml"
    unit.write_text("[unit]\nsolid = true\n")
    for command in (("simulate", "-o", "01", "--unit", str(unit)),
                    ("simulate", "-o", "01", "--model", "3d", "--unit", str(unit))):
        code, out, _ = _run(*command)
        assert code == 2 and "nothing to inflate" in out and "internal error" not in out, out


def test_the_estimate_counts_the_base_block_and_the_end_cap() -> None:
    """The mesh estimate is an upper bound of the mesh built, a base block (length, margin) and an end cap included:
    without them a base block 1000 mm long (7 times the actuator) passed a check made for the actuator alone."""
    from pneumorph.geometry.assembly import assemble
    from pneumorph.geometry.features import BaseBlock
    from pneumorph.geometry.meshsize import estimate_mesh
    from pneumorph.geometry.unit import UnitSpec

    coarse = {"element_size": 3.0}
    for unit, base in ((UnitSpec(**coarse), BaseBlock(length=200.0)), (UnitSpec(**coarse), BaseBlock(margin=6.0)),
                       (UnitSpec(**coarse, end_cap=60.0), None), (UnitSpec(**coarse, end_cap=9.0), BaseBlock())):
        for dim in (2, 3):
            mesh = assemble(unit, "0110", dim, half=True, base=base)
            estimate = estimate_mesh(unit, 4, dim, base=base)
            assert len(mesh.points) <= estimate.nodes <= 1.3 * len(mesh.points), (unit, base, dim)
            assert len(mesh.cells) <= estimate.elements, (unit, base, dim)
    long = estimate_mesh(UnitSpec(), 15, 3, base=BaseBlock(length=1000.0))
    assert long.cells[0] == 105 + 667 and long.nodes > 7 * estimate_mesh(UnitSpec(), 15, 3).nodes


def test_a_base_block_past_the_memory_is_refused_with_its_estimate(tmp_path: Path) -> None:
    """sensitivity simplifications meshes its base block's cases longer by --base-length: counted before any mesh."""
    unit = tmp_path / "fine.toml"
    unit.write_text("[unit]\nelement_size = 0.75\n")  # 3 units: 1.6 GB; with a 1000 mm block about 160 GB
    code, out, seconds = _run("sensitivity", "simplifications", "--units", "3", "--unit", str(unit),
                              "--base-length", "1000", "--executor", "serial", "--out", str(tmp_path / "out"))
    assert code == 2 and "--base-length" in out and "with a base block of 1000 mm" in out, out
    assert "GB for one solve" in out and "GB are available" in out and "Traceback" not in out
    assert seconds < 30 and not (tmp_path / "out").exists()


def test_a_configs_base_block_past_the_memory_is_refused_with_its_estimate(tmp_path: Path) -> None:
    """A design config's [model.base_block] counts in the model factory's mesh check: 3 units at 0.75 mm need
    about 1.6 GB, with a 1000 mm block about 160 GB (refused); the same unit without the block is built."""
    from pneumorph.geometry.limits import MeshLimitError
    from pneumorph.models.factory import make_model

    unit = {"element_size": 0.75}
    try:
        make_model(3, {"fidelity": "3d", "unit": unit, "base_block": {"length": 1000.0}})
    except MeshLimitError as exc:
        assert "base block of 1000 mm" in str(exc) and "GB for one solve" in str(exc), exc
    else:
        raise AssertionError("a 160 GB mesh was built")
    assert make_model(3, {"fidelity": "3d", "unit": unit}).n_units == 3
    config = tmp_path / "design.toml"
    config.write_text('[design]\nunits = 3\nsearch = "ga"\n[model]\nfidelity = "3d"\n[model.unit]\n'
                      'element_size = 0.75\n[model.base_block]\nlength = 1000.0\n')
    code, out, seconds = _run("design", str(config), "--out", str(tmp_path / "run"))
    assert code == 2 and "base block of 1000 mm" in out and "Traceback" not in out, out
    assert seconds < 30 and not (tmp_path / "run").exists()

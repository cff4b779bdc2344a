"""``design --refine`` and the unit's element size on every path of a run: the FE solves get the mesh they name.

The FE solve is replaced by an analytical stand-in (the ``solves`` fixture of ``tests/design/conftest.py``, its turn
grown with the element size so that the two meshes differ) that records the element size of every model it solves;
the paths: the certified search with the chain, the certified search handed to the FE exhaustive search (a short
actuator), the GA and the exhaustive search. Where a run falls back to the genetic algorithm, which does not refine, the
refinement is refused in one line, before any solve.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main


def _design(tmp_path: Path, capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, dict, str]:
    out = tmp_path / "run"
    code = main(["design", "--model", "2d", "--tolerance", "0", "--executor", "serial", "--out", str(out), "--json",
                 *args])
    captured = capsys.readouterr()
    return code, (json.loads(captured.out) if code == 0 else {}), captured.err


def test_a_short_certified_run_handed_to_the_exhaustive_search_refines_its_best_designs(
        solves: list[tuple[float, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, data, err = _design(tmp_path, capsys, "--units", "3", "--objective", "max-y", "--refine", "1.0")
    assert code == 0, err
    assert "FE exhaustive search over all 8 designs" in err
    fine = [d for h, d in solves if h == 1.0]
    assert {h for h, _ in solves} == {1.5, 1.0}
    # the best three of the ranking (the winner first), solved again on the 1.0 mm mesh
    assert len(fine) == 3 and fine[0] == data["best"]["design"]
    mesh = data["mesh"]
    assert mesh["element_size_mm"] == [1.5, 1.0] and [r["design"] for r in mesh["rows"]] == fine
    # the stand-in turns more on the coarser mesh: every refined max-y is its own solve's, lower than the coarse one
    for row in mesh["rows"]:
        assert row["refined"] < row["value"]
    assert "## Mesh" in (tmp_path / "run" / "report.md").read_text()


def test_the_certified_search_with_the_chain_refines_its_verified_designs(
        solves: list[tuple[float, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, data, err = _design(tmp_path, capsys, "--refine", "0.75", "--verify", "2")
    assert code == 0, err
    coarse = [d for h, d in solves if h == 1.5]
    fine = [d for h, d in solves if h == 0.75]
    assert {h for h, _ in solves} == {1.5, 0.75}
    assert sorted(fine) == sorted(set(coarse)) and len(fine) >= 3  # every verified design, again
    assert data["mesh"]["element_size_mm"] == [1.5, 0.75]


@pytest.mark.parametrize("search", ["ga", "exhaustive"])
def test_the_units_element_size_reaches_every_fe_solve(search: str, solves: list[tuple[float, str]], tmp_path: Path,
                                                       capsys: pytest.CaptureFixture[str]) -> None:
    unit = tmp_path / "unit.toml"
    unit.write_text("[unit]\nelement_size = 1.25\n")
    code, data, err = _design(tmp_path, capsys, "--units", "3", "--objective", "max-y", "--search", search,
                              "--unit", str(unit), "--pop", "4", "--gen", "1")
    assert code == 0, err
    assert solves and {h for h, _ in solves} == {1.25}
    assert "mesh" not in data or data["mesh"] is None


def test_a_refinement_the_gravity_fallback_would_drop_is_refused(solves: list[tuple[float, str]], tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    config = tmp_path / "hanging.toml"
    config.write_text('[design]\nrefine = 1.0\n\n[model]\ngravity = "hanging"\n')
    out = tmp_path / "never"
    code = main(["design", str(config), "--model", "2d", "--executor", "serial", "--pop", "4", "--gen", "1",
                 "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert "[design] refine 1: the certified search needs a free actuator" in err
    assert "does not refine" in err
    assert not out.exists() and solves == []


def test_a_refinement_the_locality_fallback_would_drop_is_refused(solves: list[tuple[float, str]], tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str],
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    from pneumorph.design.algorithms import certified
    from pneumorph.errors import LocalityError

    def cannot(*args: object, **kwargs: object) -> None:
        raise LocalityError("the chain model does not reproduce this model within 0.5 mm")

    monkeypatch.setattr(certified, "plan_search", cannot)
    out = tmp_path / "never"
    code = main(["design", "--model", "2d", "--refine", "1.0", "--tolerance", "0", "--executor", "serial", "--pop",
                 "4", "--gen", "1", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    assert "--refine 1: the chain model does not reproduce" in err and "is not started" in err
    assert not out.exists() and solves == []


def test_a_refinement_whose_library_units_no_longer_join_is_refused_before_any_solve(
        solves: list[tuple[float, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The built-in library's units share grid lines at 1.5 mm (and 0.75 mm), not at 1.0 mm: refused after the
    verification's solves, at the refinement, before the check built the refined library."""
    out = tmp_path / "never"
    code = main(["design", "--model", "2d", "--library", "builtin", "--refine", "1.0", "--tolerance", "0",
                 "--executor", "serial", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert "'--refine'" in err and "cannot be joined" in err
    assert not out.exists() and solves == []


def test_the_units_element_size_reaches_the_chain_tables_solves_and_a_refinement_stops_the_fall_back(
        solves: list[tuple[float, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A unit of 1.25 mm elements has no shipped table: the table's build solves at 1.25 mm; the stand-in's units
    interact further than any window, so the run would fall back to the GA, which a refinement stops in one line
    (the build's solves stay in the evaluation cache for the run without it)."""
    unit = tmp_path / "unit.toml"
    unit.write_text("[unit]\nelement_size = 1.25\n")
    out = tmp_path / "never"
    code = main(["design", "--model", "2d", "--unit", str(unit), "--refine", "1.0", "--tolerance", "0",
                 "--executor", "serial", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    last = err.strip().splitlines()[-1]
    assert last.startswith("error: --refine 1: the chain model does not reproduce this model") and "not started" in last
    assert solves and {h for h, _ in solves} == {1.25}
    assert not out.exists()

"""What a certified run handed to the FE exhaustive search (an actuator shorter than its chain table needs) does
with the certified search's settings.

The exhaustive search solves every design: ``--certify`` is met (no design can beat the winner), ``--refine``
solves its best designs again and ``--verify`` sets how many (at least three, as the certified search refines its
verified ones); ``--margin``, ``--epsilon``, ``--max-open``, ``--robust`` and ``--verify`` without a refinement
mean nothing there and are refused in one line naming them as given, exit 2, before any solve, nothing written.
The FE solve is the analytical stand-in of the ``solves`` fixture.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main
from pneumorph.design import DesignConfig, run_design
from pneumorph.errors import SearchConfigError


def _short(tmp_path: Path, *args: str) -> tuple[int, Path]:
    out = tmp_path / "run"
    tolerance = [] if "--tolerance" in args else ["--tolerance", "0"]
    return main(["design", "--units", "3", "--objective", "max-y", "--model", "2d", *tolerance, "--executor", "serial",
                 "--out", str(out), "--json", *args]), out


def test_verify_sets_how_many_best_designs_the_refinement_solves_again(
        solves: list[tuple[float, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _ = _short(tmp_path, "--refine", "1.0", "--verify", "5")
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "FE exhaustive search over all 8 designs" in captured.err
    fine = [d for h, d in solves if h == 1.0]
    data = json.loads(captured.out)
    assert len(fine) == 5 and fine[0] == data["best"]["design"]  # five of the five solved designs (mirrors aside)
    assert [r["design"] for r in data["mesh"]["rows"]] == fine


def test_certify_is_met_by_the_exhaustive_search(solves: list[tuple[float, str]], tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _short(tmp_path, "--certify")
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert json.loads(captured.out)["search"] == "exhaustive" and (out / "ranking.csv").is_file()
    assert len({d for _, d in solves}) == len(solves) == 5  # every design with a first unit 0, and a mirror check


@pytest.mark.parametrize(("args", "named", "cannot"), [
    (["--verify", "2"], "--verify 2", "verifies no batches"),
    (["--margin", "2"], "--margin 2", "has no chain bound to widen"),
    (["--epsilon", "0.1"], "--epsilon 0.1", "has no chain bound to certify within"),
    (["--max-open", "1000"], "--max-open 1000", "keeps no open prefixes"),
    (["--tolerance", "0.1", "--robust", "mean"], "--robust mean", "ranks no design by the chain"),
    (["--margin", "2", "--epsilon", "0.5"], "--margin 2, --epsilon 0.5", "widen and has no chain bound")])
def test_a_setting_the_exhaustive_search_has_no_use_for_is_refused_before_any_solve(
        args: list[str], named: str, cannot: str, solves: list[tuple[float, str]], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _short(tmp_path, *args)
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert f"error: {named}: FE exhaustive search over all 8 designs instead of the certified search, which" in err
    assert cannot in err and not out.exists() and solves == []


def test_the_config_files_key_is_named(solves: list[tuple[float, str]], tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    config = tmp_path / "short.toml"
    config.write_text("[design]\nmax_open = 5000\n")
    code, out = _short(tmp_path, str(config))
    err = capsys.readouterr().err
    assert code == 2 and "error: [design] max_open 5000: FE exhaustive search over all 8 designs" in err
    assert not out.exists() and solves == []


def test_the_api_refuses_it_too_before_the_folder_is_touched(solves: list[tuple[float, str]], tmp_path: Path) -> None:
    config = DesignConfig(units=3, objective="max-y", epsilon=0.2, executor="serial", tolerance=0.0,
                          model={"fidelity": "2d"})
    with pytest.raises(SearchConfigError, match=r"^\[design\] epsilon 0.2: FE exhaustive search over all 8"):
        run_design(config, config.make_model(), tmp_path / "api", figures=False)
    assert not (tmp_path / "api").exists() and solves == []

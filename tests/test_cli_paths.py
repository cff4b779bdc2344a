"""Paths on the command line: `--target path:FILE`, the presets, `objective = "path"` in a config, the refusals."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.design.certified.search import certified_search
from pneumorph.design.objectives.paths import path_target
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import find_table
from pneumorph.models.factory import make_model


def test_a_path_through_a_2d_designs_own_fe_centres_curling_past_vertical_gives_it_back() -> None:
    """The 2D FE centres of 000000100000000 at 40.5 kPa (x turns back) as a path: the certified search on the 2D
    model returns that design, its FE value 0, certified."""
    model = make_model(15, {"fidelity": "2d"})
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
    (own,) = evaluator.evaluate_many(model, ["000000100000000"])
    centres = own.response.centres[8]
    assert int(np.sum(np.diff(centres[:, 0]) < 0)) >= 5  # the actuator curls past vertical there
    chain = ChainModel(find_table(model), 15)
    result = certified_search(model, chain, path_target(centres), evaluator)
    assert result.winner.design == "000000100000000" and result.winner.value == pytest.approx(0.0, abs=1e-9)
    assert result.certificate["certified"] and result.winner.level == 8


def test_design_takes_a_path_file_and_reports_its_rms_per_centre(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    file = tmp_path / "hook.csv"
    file.write_text("x,y\n0,6\n60,6\n90,20\n100,45\n95,70\n80,80\n")
    out = tmp_path / "run"
    assert main(["design", "--target", f"path:{file}", "--model", "2d", "--tolerance", "0", "--verify", "1",
                 "--executor", "serial", "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["objective"] == "path: path through 6 points"
    assert summary["path"][:2] == [[0.0, 6.0, 0.0], [60.0, 6.0, 0.0]]
    assert summary["rms_per_centre_mm"] == pytest.approx(summary["best"]["fitness"] / 15**0.5)
    report = (out / "report.md").read_text()
    assert "- RMS distance per centre:" in report and "- the path: 6 points, " in report
    assert (out / "profile.png").stat().st_size > 10_000
    config = (out / "config.toml").read_text()
    assert 'objective = "path"' in config and "path = [[0.0, 6.0, 0.0], [60.0, 6.0, 0.0]" in config


def test_a_preset_path_runs_from_the_cli_and_its_folder_is_its_own(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    assert main(["design", "--target", "letter-l", "--model", "2d", "--units", "8", "--tolerance", "0",
                 "--executor", "serial", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "path error" in text and "RMS per centre" in text
    assert "letter-l" in (out / "report.md").read_text()
    assert main(["design", "--target", "letter-l", "--model", "2d", "--units", "8", "--tolerance", "0",
                 "--executor", "serial", "--out", str(out), "--json"]) == 0  # the same run: from its folder
    path = np.array(json.loads(capsys.readouterr().out)["path"])  # drawn for the 8-unit actuator, on its axis
    assert path[0].tolist() == [0.0, 6.0, 0.0]
    assert np.linalg.norm(np.diff(path, axis=0), axis=1).sum() == pytest.approx(1.15 * 8 * 10.5)


@pytest.mark.parametrize("content, message", [
    ("0 0\n", "needs 2 to 2000 points"),
    ("0 0\n10 nan\n", "finite number"),
    ("5 5\n5 5\n5 5\n", "all lie within 1 mm"),
    ("0 0\n0.1 0.1\n", "its length is 0.141 mm"),
    ("a path\nfrom here\nto there\n", "line 2 is not numbers"),
])
def test_bad_path_files_are_refused_in_one_line_with_nothing_written(tmp_path: Path, content: str, message: str,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    file = tmp_path / "bad.txt"
    file.write_text(content)
    out = tmp_path / "run"
    assert main(["design", "--target", f"path:{file}", "--model", "2d", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "--target" in err and len(err.splitlines()) == 1 and "Traceback" not in err
    assert not out.exists()


def test_a_missing_path_file_and_a_curve_that_turns_back_are_refused(tmp_path: Path,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["design", "--target", f"path:{tmp_path / 'none.csv'}", "--out", str(tmp_path / "a")]) == 2
    assert "none.csv: no such file" in capsys.readouterr().err
    config = tmp_path / "curl.toml"
    config.write_text('[design]\nobjective = "curve"\ncurve = [[0, 0], [80, 10], [70, 40]]\n')
    assert main(["design", str(config), "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err.strip()
    assert "turns back in x" in err and "path" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "b").exists()


def test_a_target_option_replaces_a_configs_path(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    config = tmp_path / "path.toml"
    config.write_text('[design]\nobjective = "path"\npath = [[0, 6], [100, 6], [120, 40]]\nunits = 6\n'
                      'tolerance = 0\nsearch = "exhaustive"\n[execution]\nexecutor = "serial"\n[model]\n'
                      'fidelity = "2d"\n')
    out = tmp_path / "run"
    assert main(["design", str(config), "--target", "y = 0.1*x", "--out", str(out)]) == 0
    assert "error" in capsys.readouterr().out
    assert "path = " not in (out / "config.toml").read_text()

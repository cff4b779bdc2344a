"""What a certified run that falls back to the genetic algorithm does with the options only the certified search reads.

The genetic algorithm reads none of them (``--certify``, ``--verify``, ``--margin``, ``--epsilon``, ``--max-open``,
``--refine``, ``--chain-table``, ``--robust``), is not the ``--search certified`` typed, and ``--no-build`` asks to
stop instead of falling back: each given one is refused in one line naming it as given, exit 2, nothing written.
Two paths: a model the certified search is known not to serve from its settings (gravity), refused before any
solve; a model the chain turns out not to represent (a ``LocalityError`` of the plan, after a table build's
solves), refused before the GA starts. Options at their defaults, not given, fall back as before. The FE solve is
the analytical stand-in of the ``solves`` fixture.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pneumorph.cli import main
from pneumorph.models.chain.sources import shipped_path

#: each option only the certified search reads (and --no-build), as typed, with what the refusal names
GIVEN = [(["--certify"], "--certify:"), (["--verify", "2"], "--verify 2:"), (["--margin", "2"], "--margin 2:"),
         (["--margin", "1"], "--margin 1:"), (["--epsilon", "0.1"], "--epsilon 0.1:"),
         (["--max-open", "1000"], "--max-open 1000:"), (["--refine", "1.0"], "--refine 1:"),
         (["--robust", "worst"], "--robust worst:"), (["--no-build"], "--no-build:"),
         (["--search", "certified"], "--search certified:")]


def _hanging(tmp_path: Path, design: str = "") -> Path:
    config = tmp_path / "hanging.toml"
    config.write_text(f'[design]\nunits = 3\nobjective = "max-y"\n{design}\n[model]\ngravity = "hanging"\n')
    return config


def _refused(code: int, err: str, out: Path, solves: list[tuple[float, str]]) -> str:
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert not out.exists() and solves == []
    return err


def _run(tmp_path: Path, *args: str) -> tuple[int, Path]:
    out = tmp_path / "run"
    return main(["design", *args, "--model", "2d", "--executor", "serial", "--pop", "4", "--gen", "1",
                 "--out", str(out), "--json"]), out


@pytest.mark.parametrize(("args", "named"), [*GIVEN, (["--chain-table", "TABLE"], "--chain-table ")])
def test_an_option_the_gravity_fall_back_would_drop_is_refused_before_any_solve(
        args: list[str], named: str, solves: list[tuple[float, str]], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    args = [str(shipped_path("2d")) if a == "TABLE" else a for a in args]
    code, out = _run(tmp_path, str(_hanging(tmp_path)), *args)
    err = _refused(code, capsys.readouterr().err, out, solves)
    assert f"error: {named}" in err and "the certified search needs a free actuator" in err
    assert "is not started" in err and "falling back" not in err


def test_the_config_files_certified_settings_are_refused_by_their_keys(
        solves: list[tuple[float, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _run(tmp_path, str(_hanging(tmp_path, "verify = 2\nepsilon = 0.5\n")))
    err = _refused(code, capsys.readouterr().err, out, solves)
    assert "error: [design] verify 2, [design] epsilon 0.5: the certified search needs a free actuator" in err
    assert "verifies no chain's best designs by FE and has no chain bound to certify within" in err
    assert "run without them to start it" in err


def test_certified_settings_at_their_defaults_fall_back_under_gravity(
        solves: list[tuple[float, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    config = _hanging(tmp_path, "certify = false\nmargin = 1.0\nepsilon = 0.0\n")
    code, out = _run(tmp_path, str(config))
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "the certified search needs a free actuator (its chain model does not hold under gravity): falling back " \
           "to the genetic algorithm" in captured.err
    assert json.loads(captured.out)["search"] == "ga" and solves and (out / "generations.csv").is_file()


@pytest.fixture
def no_locality(monkeypatch: pytest.MonkeyPatch) -> None:
    """The certified search's plan finds (as after a table build) that the chain does not represent the model."""
    from pneumorph.design.algorithms import certified
    from pneumorph.errors import LocalityError

    def cannot(*args: object, **kwargs: object) -> None:
        raise LocalityError("the chain model does not reproduce this model within 0.5 mm")

    monkeypatch.setattr(certified, "plan_search", cannot)


@pytest.mark.parametrize(("args", "named"), GIVEN)
def test_an_option_the_locality_fall_back_would_drop_is_refused_before_the_ga(
        args: list[str], named: str, no_locality: None, solves: list[tuple[float, str]], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _run(tmp_path, "--units", "8", "--objective", "max-y", *args)
    err = _refused(code, capsys.readouterr().err, out, solves)
    assert f"error: {named} the chain model does not reproduce this model" in err
    assert "is not started" in err and "falling back" not in err


def test_without_certified_options_the_locality_fall_back_runs_the_ga(
        no_locality: None, solves: list[tuple[float, str]], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _run(tmp_path, "--units", "8", "--objective", "max-y")
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "does not reproduce this model within 0.5 mm; falling back to the genetic algorithm" in captured.err
    assert json.loads(captured.out)["search"] == "ga" and solves and (out / "generations.csv").is_file()


def test_no_build_is_refused_beside_another_search(solves: list[tuple[float, str]], tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    code, out = _run(tmp_path, "--search", "ga", "--no-build")
    err = _refused(code, capsys.readouterr().err, out, solves)
    assert "--no-build only applies to --search certified" in err

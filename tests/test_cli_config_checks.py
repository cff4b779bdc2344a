"""A config's settings are checked as the options that mirror them are."""

from __future__ import annotations

from pathlib import Path

import pytest

from pneumorph.cli import main


@pytest.mark.parametrize(("value", "words"), [
    ("1.0", "'[design] tolerance': the tolerance +-1 mm is not smaller than the unit's side_wall (1 mm)"),
    ('"x"', "[design] tolerance must be a finite number >= 0 and <= 1 (mm), got 'x'"),
    ("2.0", "[design] tolerance must be a finite number >= 0 and <= 1 (mm), got 2.0"),
    ("true", "[design] tolerance must be a finite number"),
])
def test_a_configs_tolerance_is_checked_as_the_option_is(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                         value: str, words: str) -> None:
    """--tolerance was refused where it would leave no wall; the same value in a config was not checked."""
    (tmp_path / "thin.toml").write_text("[unit]\nside_wall = 1.0\n", encoding="utf-8")  # the thinnest a mould casts
    config = tmp_path / "run.toml"
    unit = (tmp_path / "thin.toml").as_posix()
    config.write_text(f'[design]\nobjective = "sin"\ntolerance = {value}\n[model]\nunit_file = "{unit}"\n',
                      encoding="utf-8")
    out = tmp_path / "never"
    assert main(["design", str(config), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0], err
    assert not out.exists()

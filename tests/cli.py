"""Running a pneumorph command in-process in a test: its exit code, standard output and standard error."""

from __future__ import annotations

import pytest

from pneumorph.cli import main


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """``pneumorph ARGV`` as the command line runs it (one-line errors, exit codes), and what it printed."""
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err

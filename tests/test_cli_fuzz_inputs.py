"""The systematic input round (``benchmarks/fuzz_inputs.py``): its cases cover every file and number option of the
command tree, and a case is judged by how the command ended (a hostile file refused, a byte-order mark read)."""

from __future__ import annotations

import sys

import click
import pytest

from pneumorph.cli.options import params as P
from tests.benchmark import load

FUZZ = load("fuzz_inputs")


def test_every_file_and_number_option_has_its_cases() -> None:
    paths, numbers = FUZZ.all_cases()
    covered = {(c.command.removesuffix("-config"), c.option) for c in [*paths, *numbers]}
    for key, command in FUZZ._leaves().items():
        assert key in FUZZ.BASE, f"no baseline for pneumorph {key}"
        for param in command.params:
            if isinstance(param, click.Option) and isinstance(param.type, (P.InputFile, P.Real, P.Count, P.RealList)):
                assert (key, max(param.opts, key=len)) in covered, (key, param.opts)
    options = {(c.command, c.option) for c in numbers}
    drawn = FUZZ.cases(len(paths) + len(options), seed=0)
    assert len(drawn) == len(paths) + len(options)
    assert options <= {(c.command, c.option) for c in drawn}  # every number option once before any twice


@pytest.mark.slow  # a subprocess each, about 2 s alone
@pytest.mark.parametrize(("option", "value", "code"), [("--unit", "pipe", 2), ("--unit", "bom", 99),
                                                        ("--pressure", "nan", 2)])
def test_a_case_ends_as_its_input_deserves(option: str, value: str, code: int) -> None:
    """A named pipe is refused by name (exit 2, one line); a unit file with a byte-order mark is read and the run
    goes on to its solve (the tripwire's exit 99); nan refused."""
    case = FUZZ.Case("simulate", option, value, FUZZ.spoil(FUZZ.BASE["simulate"], option, value),
                     FUZZ.PATHS.get(value, "refuse"))
    outcome = FUZZ.run_case(case)
    assert outcome.verdict == "clean" and outcome.code == code, outcome


pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="named pipes and /dev")

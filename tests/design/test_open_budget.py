"""The certified search's budget of open prefixes: the branch-and-bound's open list grows with the chain table's
bound, and its cap (``[design] max_open``, :data:`~pneumorph.design.certified.branching.MAX_NODES` by default,
lowered to fit :data:`~pneumorph.design.certified.branching.MAX_OPEN_MEMORY`) holds it; a cap whose memory would pass
the budget is refused before the search, and a search that reaches its cap says so, naming the table's bound and
what lists more. Chain-only searches on the shipped tables (no FE solve).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pneumorph.cli import main
from pneumorph.design.certified.bounds import chain_errors
from pneumorph.design.certified.branching import (
    MAX_NODES,
    BranchOverflow,
    OpenWatch,
    cap_text,
    more_open_advice,
    watching,
)
from pneumorph.design.certified.planegrowth import chain_scores, grow_designs
from pneumorph.design.objectives.targets import make_objective
from pneumorph.errors import SearchBudgetError
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import find_table
from pneumorph.models.factory import make_model


def _chain(units: int, fidelity: str = "2d") -> ChainModel:
    return ChainModel(find_table(make_model(units, {"fidelity": fidelity})), units)


def _peak(chain: ChainModel, margin: float, cap: int = MAX_NODES) -> OpenWatch:
    lines: list[str] = []
    with watching(OpenWatch(lines.append, cap=cap, every=1e9)) as watch:
        chain_scores(chain, make_objective("sin", 10.0, length=chain.length), margin, max_nodes=cap)
    watch.lines = lines  # type: ignore[attr-defined]
    return watch


def test_the_open_list_grows_with_the_tables_bound() -> None:
    """22 units of the 2D table, a sine: the most open prefixes at one depth 68 at the table's own bound, about 600
    at 4 times it, over 16,000 at 16 times it (BENCHMARKS.md): the cap is what holds a loose table."""
    chain = _chain(22)
    peaks = [_peak(chain, margin).peak for margin in (1.0, 4.0, 16.0)]
    assert peaks[0] <= 100 and 400 <= peaks[1] <= 900 and peaks[2] >= 10_000
    assert not any(_peak(chain, margin).reached for margin in (1.0, 4.0))


def test_a_loose_table_reaches_its_cap_and_says_so_with_the_bound() -> None:
    """At 32 times the bound every prefix stays open (the list doubles at every depth); a cap of 2,000 keeps the
    best, and the line names the table's bound and what lists more."""
    chain = _chain(22)
    watch = _peak(chain, 32.0, cap=2_000)
    assert watch.reached and watch.peak == 2_000
    worst = float(np.max(chain_errors(chain, 32.0)["centre"]))
    assert worst == pytest.approx(2.94, abs=0.005)
    assert watch.lines[0] == "  branch-and-bound: unit 11/22, 2,000 open prefixes (at the cap of 2,000; the best kept)"


def test_without_keeping_the_best_the_cap_is_a_budget_error_naming_what_to_do() -> None:
    """The branch-and-bound that lists every design below its threshold (no spill) stops at the cap, at once."""
    chain = _chain(22)
    objective = make_objective("sin", 10.0, length=chain.length)
    with pytest.raises(BranchOverflow) as caught:
        grow_designs(chain, objective, chain_errors(chain, 32.0), threshold=1e9, max_nodes=1_000)
    assert isinstance(caught.value, SearchBudgetError)
    text = str(caught.value)
    assert "past the cap of 1,000" in text and "a tighter table" in text and "larger max_open" in text


def test_the_overflow_and_the_caps_note_give_the_one_advice() -> None:
    """The error of a branch-and-bound past its cap and the note of one that kept the best at its cap word what
    lists more alike: from one source, the note's sentence capitalised."""
    chain = _chain(22)
    objective = make_objective("sin", 10.0, length=chain.length)
    with pytest.raises(BranchOverflow) as caught:
        grow_designs(chain, objective, chain_errors(chain, 32.0), threshold=1e9, max_nodes=1_000)
    assert str(caught.value).endswith(f"list them all; {more_open_advice('--search ga')}")
    advice = more_open_advice()
    assert cap_text(chain, 32.0, 1_000).endswith(f"bounds the rest. {advice[0].upper()}{advice[1:]} lists more")


def test_the_default_main_job_keeps_far_fewer_open_prefixes_than_the_cap() -> None:
    """``pneumorph design``'s job, 15 units of the 3D table for the sine: every one of its 2^15 designs is scored
    from the kept prefix geometry, no branch-and-bound (no open list at all), and 2^15 is 1/15 of the cap."""
    chain = _chain(15, "3d")
    watch = _peak(chain, 1.0)
    scores = chain_scores(chain, make_objective("sin", 10.0, length=chain.length))
    assert watch.peak == 0 and scores.complete and len(scores.bits) == 32_768 < MAX_NODES / 15


def test_a_cap_past_the_memory_budget_is_refused_before_the_search(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """``--max-open 5000000`` on the main job: 5 million open prefixes of 2 children over 10 levels, 30 GB: one
    line naming the option, the memory and the largest cap that fits; exit 2, nothing written, no solve."""
    import pneumorph.models.fe as fe

    def tripped(*args: object, **kwargs: object) -> None:
        raise AssertionError("a solve was reached")

    monkeypatch.setattr(fe.FEModel, "solve", tripped)
    monkeypatch.setattr(fe.FEModel, "evaluate", tripped)
    monkeypatch.chdir(tmp_path)
    code = main(["design", "--max-open", "5000000", "--executor", "serial", "--out", "run"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and not (tmp_path / "run").exists()
    assert err[0].startswith("error: Invalid value for '--max-open': max_open 5,000,000: the open prefixes of a loose "
                             "chain table could take 30.0 GB at one depth")
    assert "past the 4.0 GB budget (MAX_OPEN_MEMORY); give at most 666,666" in err[0]


def test_a_chain_in_space_budgets_its_prefixes_by_their_own_bytes() -> None:
    """Over the ``spatial`` library (4 children a prefix, 10 levels) a prefix in space takes SPACE_PREFIX_BYTES
    (310 bytes a child and level, measured; 300 in the plane): 322,580 open prefixes fit the 4 GB budget, where a
    planar library of two types (``a`` and the rigid ``r`` of the examples) fits 333,333; a cap of 330,000 is
    refused in space only."""
    from pneumorph.design.algorithms.certified import max_open
    from pneumorph.design.config import DesignConfig

    space = make_model(15, {"fidelity": "3d", "library": "spatial"})
    rigid = Path(__file__).resolve().parents[2] / "examples" / "libraries" / "units-bending-rigid.toml"
    plane = make_model(15, {"fidelity": "3d", "library": str(rigid)})
    assert len(space.library.units) == len(plane.library.units) == 2
    assert len(space.pressures()) == len(plane.pressures()) == 10
    assert max_open(DesignConfig(max_open=330_000), plane) == 330_000
    with pytest.raises(SearchBudgetError, match=r"in space\), past the 4.0 GB budget .*give at most 322,580"):
        max_open(DesignConfig(max_open=330_000), space)

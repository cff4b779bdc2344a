"""The certified search over a chain in space: its scores against every design scored one by one, and its
bounds against enumeration (no design left out could beat the floor it states)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from pneumorph.design.certified import spacegrowth
from pneumorph.design.certified.bounds import chain_errors, score_designs
from pneumorph.design.certified.prefixes import depths
from pneumorph.design.certified.spacegrowth import check_space_objective, space_scores
from pneumorph.design.objectives.targets import make_objective, tip_goal
from pneumorph.errors import SearchConfigError
from pneumorph.models.chain.fit import fit_table
from pneumorph.models.chain.fit import training_designs as covering
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.windows import design_numbers, every_design
from tests.spacelaw import ALPHABET, LEVELS, LIBRARY, W, _law, _response, _source, undeformed_of

N = 7


@pytest.fixture(scope="module")
def chain() -> ChainModel:
    law, undeformed = _law(11), undeformed_of()
    table = fit_table([_response(d, law, undeformed) for d in covering(N, W, False, True, ALPHABET)], W, _source(),
                      library=LIBRARY)
    errors = {"centre_worst_mm": [0.05] * LEVELS, "tip_worst_mm": [0.08] * LEVELS, "curl_worst_deg": [1.0] * LEVELS}
    return ChainModel(replace(table, validation=errors), N)


@pytest.fixture(scope="module")
def every(chain: ChainModel) -> np.ndarray:
    return every_design(N, np.asarray(chain.table.unit_codes, dtype=np.uint8))


def _objectives(chain: ChainModel) -> list:
    length = chain.length
    return [make_objective("helix", 6.0, length=length), make_objective("sin", 4.0, length=length),
            make_objective("y = 0.05*x, z = -0.002*x**2", length=length), tip_goal("reach", (60.0, 8.0, -12.0)),
            tip_goal("max-x"), tip_goal("min-y"), tip_goal("min-distance"), tip_goal("max-y"), tip_goal("min-x"),
            tip_goal("reach", (20.0, 30.0, 25.0))]


@pytest.mark.parametrize("which", range(10))
def test_every_design_scored_in_space_is_its_own_chain_value(chain: ChainModel, every: np.ndarray, which: int) -> None:
    objective = _objectives(chain)[which]
    grown = space_scores(chain, objective)
    assert grown.complete and len(grown.bits) == 4**N
    one_by_one = score_designs(chain, objective, every, chain_errors(chain))
    order = np.argsort(design_numbers(grown.bits, grown.choices))
    np.testing.assert_array_equal(grown.bits[order], one_by_one.bits)
    np.testing.assert_allclose(grown.per_level[order], one_by_one.per_level, atol=1e-9, rtol=0)
    np.testing.assert_allclose(grown.bound[order], one_by_one.bound, atol=1e-12, rtol=0)


@pytest.mark.parametrize("which", range(10))
@pytest.mark.parametrize("max_nodes", [500_000, 40])
def test_no_design_the_branch_and_bound_leaves_out_beats_its_floor(chain: ChainModel, every: np.ndarray, which: int,
                                                                   max_nodes: int,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    objective = _objectives(chain)[which]
    monkeypatch.setattr(spacegrowth, "BEAM", 16)  # the first search's beam: not every prefix of so short a chain
    found = space_scores(chain, objective, max_enumerate=8, max_nodes=max_nodes)  # 4^7 designs: branch-and-bound
    assert not found.complete
    truth = score_designs(chain, objective, every, chain_errors(chain))
    listed = np.isin(design_numbers(truth.bits, 4), design_numbers(found.bits, 4))
    assert listed.sum() < len(every)  # it pruned
    assert truth.optimistic[~listed].min() >= found.floor - 1e-9  # the stated floor holds for all others
    if max_nodes == 500_000:  # nothing spilled: the best and every design within twice the bound of it are listed
        assert truth.cost[listed].min() == pytest.approx(truth.cost.min(), abs=1e-12)
        assert (truth.cost[~listed] >= truth.cost.min() + 2 * found.bound.max() - 1e-9).all()


def test_what_the_chain_in_space_cannot_score_is_refused_in_one_line() -> None:
    for objective in (make_objective("r = 50 + 0*theta"), tip_goal("max-curl")):
        with pytest.raises(SearchConfigError, match="--search ga") as exc:
            check_space_objective(objective)
        assert "\n" not in str(exc.value)


def test_a_search_over_some_unit_codes_finds_the_best_design_made_of_them(chain: ChainModel, every: np.ndarray) -> None:
    objective = _objectives(chain)[0]
    planar = np.array([0, 1], dtype=np.uint8)  # a and A: the designs that stay in the plane
    found = space_scores(chain, objective, codes=planar)
    assert found.complete and len(found.bits) == 2**N and set(np.unique(found.bits)) == {0, 1}
    truth = score_designs(chain, objective, every, chain_errors(chain))
    flat = np.all(truth.bits < 2, axis=1)
    assert found.cost.min() == pytest.approx(truth.cost[flat].min(), abs=1e-12)
    assert truth.cost.min() < found.cost.min()  # the helix is better followed out of the plane
    bnb = space_scores(chain, objective, codes=planar, max_enumerate=4)
    assert not bnb.complete and bnb.cost.min() == pytest.approx(found.cost.min(), abs=1e-12)


@pytest.mark.parametrize("which", [3, 4, 5, 6, 7, 8, 9])
def test_the_cone_of_the_chords_turns_bounds_every_prefix_tighter_than_the_ball(chain: ChainModel, every: np.ndarray,
                                                                              which: int) -> None:
    """Every prefix's tip-goal bound with its frame (the chords still to place turn at most so far from its x axis)
    lies between the ball's bound and the best cost of its completions, and is tighter than the ball somewhere."""
    objective = _objectives(chain)[which]
    truth = score_designs(chain, objective, every, chain_errors(chain))
    numbers = design_numbers(truth.bits, 4)
    codes = np.asarray(chain.table.unit_codes, dtype=np.uint8)
    bits, st = spacegrowth._seed(chain, codes)
    growth = depths(chain, bits, st, place=spacegrowth._placer(chain), codes=codes)
    tighter = 0
    for p, placed, bits, st, centres in growth:
        for _ in centres:
            pass
        if p < N:
            remaining = N + 1 - placed
            ball = spacegrowth._tip_bound(chain, objective, st["point"], remaining)
            cone = spacegrowth._tip_bound(chain, objective, st["point"], remaining, st["frame"])
            best = np.full(4**p, np.inf)  # the best cost of every completion, per prefix
            np.minimum.at(best, numbers // 4 ** (N - p), truth.cost)
            assert (cone >= ball - 1e-9).all()
            assert (cone <= best[design_numbers(bits, 4)] + 1e-9).all()  # admissible
            tighter += int((cone > ball + 1e-6).sum())
            growth.send((bits, st))
    assert tighter > 0


def test_the_verifications_estimate_of_a_model_over_sideways_units_is_the_full_widths(
        monkeypatch: pytest.MonkeyPatch) -> None:
    from pneumorph.models.chain.plan import solve_estimate
    from pneumorph.models.factory import make_model

    monkeypatch.setattr("os.cpu_count", lambda: 2)
    monkeypatch.setattr("os.getloadavg", lambda: (0.0, 0.0, 0.0))  # a quiet machine of 2 cores
    assert solve_estimate(make_model(15, {"fidelity": "3d"}), 2) == " (3d, about 15 s each)"
    assert solve_estimate(make_model(15, {"fidelity": "3d", "library": "spatial"}), 2) == (
        " (3d full-width, about 60 s each)")
    # the load average of this process and two busy ones of other runs: the two verifications at half a core each
    monkeypatch.setattr("os.getloadavg", lambda: (3.0, 3.0, 3.0))
    assert solve_estimate(make_model(15, {"fidelity": "3d"}), 2) == " (3d, about 30 s each)"

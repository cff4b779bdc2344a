"""The bound on the units still to place (design.certified.reach): admissible against enumeration, exact where
it can be."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pneumorph.design.certified import bounds
from pneumorph.design.certified import planegrowth as growth
from pneumorph.design.certified import reach as reach_module
from pneumorph.design.certified import search as cs
from pneumorph.design.certified.prefixes import depths, seed_prefixes
from pneumorph.design.certified.reach import build_reach
from pneumorph.design.certified.remainder import CurveRange
from pneumorph.design.objectives.targets import ProfileTarget, make_objective, tip_goal
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import find_table
from pneumorph.models.factory import make_model

LIBRARY_TABLE = Path(__file__).resolve().parents[2] / "examples" / "libraries" / "chain-3d-bending-rigid.json"


@pytest.fixture(scope="module")
def binary() -> ChainModel:
    """The shipped 2D table (window +-2) on 10 units: 1,024 designs."""
    table = find_table(make_model(15, {"fidelity": "2d"}))
    assert table is not None
    return ChainModel(table, 10)


@pytest.fixture(scope="module")
def library() -> ChainModel:
    """The shipped 3D table of bending and near-rigid units (window +-2) on 7 units: 4^7 = 16,384 designs."""
    return ChainModel(ChainTable.load(LIBRARY_TABLE), 7)


def _slack(chain: ChainModel, objective) -> list[tuple[int, np.ndarray]]:
    """Per depth from 2w: (depth, the least cost of each prefix's completions minus the prefix's bound)."""
    n, c = chain.n_units, growth.choices(chain)
    errors = cs.chain_errors(chain)
    full = cs.grow_designs(chain, objective, errors)  # every design, enumerated
    cost = np.empty(c**n)
    cost[(full.bits.astype(np.int64) * c ** np.arange(n - 1, -1, -1)).sum(axis=1)] = full.cost
    curve = None
    if isinstance(objective, ProfileTarget):
        curve = bounds.curve_range(chain, objective, errors, bounds.target_slope(chain, objective, errors))
    seeds, state = seed_prefixes(chain)
    state["sum"] = np.zeros((len(seeds), chain.table.n_levels))
    out = []
    for p, placed, bits, st, centres in depths(chain, seeds, state):
        for _, x, y in centres:
            if curve is not None:
                st["sum"] = st["sum"] + (objective.curve(x, chain.length) - y) ** 2
        if p == n:
            break
        if not growth._uses_reach(chain, p):
            continue
        bound = growth._prefix_bound(chain, objective, bits, st, placed, curve)
        index = (bits.astype(np.int64) * c ** np.arange(p - 1, -1, -1)).sum(axis=1)
        out.append((p, cost.reshape(-1, c ** (n - p)).min(axis=1)[index] - bound))
    assert out
    return out


OBJECTIVES = ["sin", "cos", "max-x", "min-x", "max-y", "min-y", "min-distance", "max-curl", "reach"]


def _objective(name: str, chain: ChainModel):
    if name in ("sin", "cos"):
        return make_objective(name, 10.0, length=chain.length)
    return tip_goal(name, (60.0, 40.0) if name == "reach" else None)


@pytest.mark.parametrize("name", OBJECTIVES)
def test_no_prefix_is_bounded_above_its_best_completion(binary: ChainModel, library: ChainModel, name: str) -> None:
    """Admissible: at every depth, every prefix's bound is at most the best chain cost of its designs."""
    for chain in (binary, library):
        for _, slack in _slack(chain, _objective(name, chain)):
            assert slack.min() >= -1e-9


@pytest.mark.parametrize("name", ["max-x", "min-x", "max-y", "min-y", "max-curl"])
def test_linear_tip_goals_are_bounded_exactly(binary: ChainModel, name: str) -> None:
    """A support function is the best of a linear goal over the completions: the bound is exact but for the grid.

    The direction grid (1 degree) loosens it by about ``R delta^2 / 8`` per unit: at most 0.05 mm here, and a
    few micrometres for most prefixes.
    """
    for _, slack in _slack(binary, _objective(name, binary)):
        assert slack.max() < 0.05
        assert np.median(slack) < 0.01


def test_the_profile_bound_adds_the_centres_still_to_place(binary: ChainModel) -> None:
    """The centres not yet fixed add to the partial sums: near the end the bound is within 1 mm of the truth."""
    slack = dict(_slack(binary, _objective("sin", binary)))
    assert np.median(slack[9]) < 1.0
    assert np.median(slack[9]) < np.median(slack[6])


def test_the_support_of_one_chord_is_its_length_turned(binary: ChainModel) -> None:
    """After one unit, the support in a direction is the best of the chord steps the windows allow (closed form)."""
    table = binary.table
    reach = build_reach(table, 2, families=("centre",))
    c, w, b = 2, table.window, 4
    digits = (table.codes[:, None] // b ** np.arange(2 * w + 1)) % b
    unit = (digits < c).all(axis=1)
    state = ((digits[unit, 2 * w - reach.memory: 2 * w]) * c ** np.arange(reach.memory)).sum(axis=1)
    for s in np.unique(state)[:4]:
        rows = np.flatnonzero(unit)[state == s]
        for phi in (0.0, 0.7, 2.0):
            exact = (table.length[rows] * np.cos(phi - table.turn[rows])).max(axis=0)
            got = reach.support("centre", 1, np.array([s]), np.full((1, table.n_levels), phi))[0]
            assert np.all(got >= exact - 1e-9)
            assert np.all(got - exact < 1e-3)


@pytest.mark.parametrize("name", ["sin", "max-x", "min-distance", "max-curl"])
def test_clusters_of_windows_stay_admissible(library: ChainModel, name: str) -> None:
    """A table of many windows steps over clusters of close turns: every value still bounds the exact one.

    Forced here on the 3D bending and near-rigid table (window +-2, 1,024 windows of units a
    level) by allowing 60 rows a level: the clustered supports lie above the exact ones and,
    read through the search, no prefix is bounded above its best completion.
    """
    table = library.table
    exact = build_reach(table, 3)
    merged = build_reach(table, 3, max_rows=60)
    for which in ("centre", "tip"):
        for a in range(4):
            e, m = getattr(exact, which)[a], getattr(merged, which)[a]
            alive = e > -1e29
            assert np.all(m[alive] >= e[alive])
            if a:
                assert 0.0 < float(np.median(m[alive] - e[alive])) < 3.0  # looser, but by millimetres
    assert np.all(merged.turn[exact.turn > -1e29] >= exact.turn[exact.turn > -1e29])
    chain = ChainModel(table, library.n_units)
    reach_module._REACH[chain] = {"centre": build_reach(table, 6, families=("centre",), max_rows=60),
                                  "tip": build_reach(table, 7, families=("tip",), max_rows=60)}
    for _, slack in _slack(chain, _objective(name, chain)):
        assert slack.min() >= -1e-9


def test_curve_range_holds_the_curve() -> None:
    f = np.sin
    cr = CurveRange.of(f, -10.0, 10.0, slope=1.0, step=0.05)
    lo = np.array([-3.0, 0.1, 1.0])
    hi = np.array([3.0, 0.2, 2.5])
    mn, mx = cr.between(lo, hi)
    for a, z, m1, m2 in zip(lo, hi, mn, mx, strict=True):
        x = np.linspace(a, z, 10001)
        assert m1 <= np.sin(x).min() <= m1 + 0.08  # a grid step beyond each end, and the slack
        assert m2 - 0.08 <= np.sin(x).max() <= m2


@pytest.mark.slow
def test_thirty_units_tip_goals_certify_by_branch_and_bound() -> None:
    """With the bound, max-x and min-distance at 30 units (2^30 designs) list every design within reach of the best."""
    table = find_table(make_model(15, {"fidelity": "3d"}))
    assert table is not None
    chain = ChainModel(table, 30)
    for name in ("max-x", "min-distance"):
        s = cs.chain_scores(chain, tip_goal(name))
        best = float(s.cost.min())
        assert not s.complete and s.floor > best
        # the listed designs are those of the chain: scoring them whole gives the same values
        whole = cs.score_designs(chain, tip_goal(name), s.bits, cs.chain_errors(chain))
        assert np.allclose(whole.cost, s.cost, rtol=0, atol=1e-9)
    assert table.texts(s.bits[s.order()[:1]])[0].count("1") > 15  # min-distance: the tip curls back to the base


def test_too_many_open_prefixes_answer_with_a_sound_floor() -> None:
    """Past max_nodes the search answers with the beam's designs and a floor that no unlisted design beats.

    16 units through branch-and-bound (2^16 designs, checked against all of them) with room for 50 open prefixes.
    """
    table = find_table(make_model(15, {"fidelity": "2d"}))
    assert table is not None
    chain = ChainModel(table, 16)
    for objective in (make_objective("sin", 10.0, length=chain.length), tip_goal("min-distance")):
        every = cs.grow_designs(chain, objective, cs.chain_errors(chain))
        partial = cs.chain_scores(chain, objective, max_enumerate=10, max_nodes=50)
        assert not partial.complete and np.isfinite(partial.floor)
        listed = {tuple(b) for b in partial.bits.tolist()}
        unlisted = np.array([tuple(b) not in listed for b in every.bits.tolist()])
        assert unlisted.sum() > 2**15
        assert np.all(every.optimistic[unlisted] >= partial.floor - 1e-9)
        assert partial.cost.min() >= every.cost.min() - 1e-12


def test_a_probe_past_a_poor_beam_finds_the_optimum(monkeypatch: pytest.MonkeyPatch) -> None:
    """A beam of 2 prefixes misses the optimum; the probes (a branch-and-bound keeping the best open prefixes)
    find it, and the last run lists every design within twice the bound of it (16 units, all 2^16 designs)."""
    table = find_table(make_model(15, {"fidelity": "2d"}))
    assert table is not None
    chain = ChainModel(table, 16)
    objective = make_objective("sin", 10.0, length=chain.length)
    errors = cs.chain_errors(chain)
    every = cs.grow_designs(chain, objective, errors)
    monkeypatch.setattr(growth, "BEAM", 2)
    beamed = cs.grow_designs(chain, objective, errors, beam=2)
    assert beamed.cost.min() > every.cost.min() + 0.5
    spilled = []
    grow = growth.grow_designs

    def counted(*args, **kwargs):
        out = grow(*args, **kwargs)
        spilled.append(np.isfinite(out.floor))
        return out

    monkeypatch.setattr(growth, "grow_designs", counted)
    scores = cs.chain_scores(chain, objective, max_enumerate=10, max_nodes=250)  # probes keep 10
    assert spilled == [False, True, False]  # the beam, a probe that spills, the last run
    beta = float(scores.bound.max())
    assert scores.cost.min() == pytest.approx(every.cost.min(), abs=1e-12)
    within = every.cost < every.cost.min() + 2 * beta
    assert len(scores.cost) == within.sum()
    assert scores.floor == pytest.approx(every.cost.min() + beta, abs=1e-6)

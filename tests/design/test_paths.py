"""Paths: targets of any shape, matched by the unit centres as the model reports them.

The 3D FE response in tests/data/path-3d/ is that of `pneumorph simulate -o 000000100000000 --model 3d` (the
default 3D model, 45 kPa): its centres' x turns back 8 times at 40.5 kPa. The library and spatial ones are the
held-out responses of those tables' builds (tests/data/library-heldout/, tests/data/space-heldout/).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.design.certified.planegrowth import chain_scores
from pneumorph.design.certified.search import certified_search
from pneumorph.design.objectives.fitness import path_errors, score
from pneumorph.design.objectives.paths import PATH_PRESETS, PathTarget, path_target, preset_path, read_path
from pneumorph.design.objectives.targets import make_objective, staged_target
from pneumorph.errors import SearchConfigError, TargetExpressionError
from pneumorph.execution import CachedEvaluator, EvaluationCache, Outcome, SerialEvaluator
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import find_table, shipped_path
from pneumorph.models.factory import make_model
from pneumorph.models.response import Response

DATA = Path(__file__).parents[1] / "data"


def _response(path: Path) -> Response:
    return Response.from_dict(json.loads(path.read_text()))


def _own_path(r: Response, k: int) -> PathTarget:
    """The path through a response's centres at level ``k`` (z from the mid-plane)."""
    c = np.array(r.centres[k], dtype=float)
    if c.shape[1] == 3:
        c[:, 2] -= r.reference_centres[:, 2]
    return path_target(c)


# -- the value against hand values ------------------------------------------------------------------------------
def test_a_straight_path_counts_each_centre_s_offset_from_it() -> None:
    t = path_target([[0.0, 6.0], [160.0, 6.0]])
    n = 15
    x = (np.arange(n) + 0.5) * 160.0 / n
    on = np.column_stack([x, np.full(n, 6.0)])
    assert float(t.error(on)) == pytest.approx(0.0, abs=1e-9)
    assert float(t.error(on + np.array([0.0, 2.0]))) == pytest.approx(2.0 * np.sqrt(n), rel=1e-12)
    assert float(t.rms(on + np.array([0.0, 2.0]))) == pytest.approx(2.0, rel=1e-12)
    shifted = on.copy()
    shifted[4, 1] += 3.0  # one centre 3 mm off: only its term counts
    assert float(t.error(shifted)) == pytest.approx(3.0, rel=1e-12)
    assert float(path_target([[0, 6, 0], [160, 6, 0]]).error(np.column_stack([on, np.full(n, 4.0)]))) == \
        pytest.approx(4.0 * np.sqrt(n), rel=1e-12)  # z counts in space


def test_a_circle_arc_counts_the_radial_offset() -> None:
    """Centres at radius R + d on the arc's own angles: each is d from the arc (up to the polygon's sagitta)."""
    radius, d, n = 40.0, 1.5, 12
    phi = np.linspace(0.0, 1.5 * np.pi, 1441)  # 270 degrees, steps of 0.1875 degrees
    arc = np.column_stack([radius * np.sin(phi), radius * (1 - np.cos(phi))])
    sagitta = radius * (1 - np.cos(np.diff(phi)[0] / 2))
    t = path_target(arc)
    places = (np.arange(n) + 0.5) / n * phi[-1]  # each centre at its place along the arc
    centres = np.column_stack([(radius + d) * np.sin(places), radius - (radius + d) * np.cos(places)])
    assert float(t.rms(centres)) == pytest.approx(d, abs=sagitta + 1e-12)
    assert sagitta < 1e-4


def test_the_value_is_1_lipschitz_in_the_stacked_centres() -> None:
    """|V(c) - V(c')| <= ||c - c'|| (the argument of the chain's bound), for random centres near a hook."""
    rng = np.random.default_rng(3)
    t = preset_path("hook").at(157.5, 6.0)
    base = t.nearest(np.zeros((15, 3)) + np.array([50.0, 20.0, 0.0]))  # any points; then random ones around
    for _ in range(200):
        c = base + rng.normal(scale=20.0, size=base.shape)
        e = rng.normal(scale=rng.uniform(0.01, 5.0), size=c.shape)
        assert abs(float(t.error(c + e)) - float(t.error(c))) <= float(np.linalg.norm(e)) + 1e-9


def test_the_path_keeps_its_order_a_hook_is_not_matched_backwards() -> None:
    t = preset_path("hook").at(157.5, 6.0)
    p = t.polyline()
    arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
    places = (np.arange(15) + 0.5) / 15 * arc[-1]
    on = np.column_stack([np.interp(places, arc, p[:, j]) for j in range(3)])
    assert float(t.error(on)) == pytest.approx(0.0, abs=1e-9)
    assert float(t.rms(on[::-1])) > 30.0  # the same points in the reverse order: far from their stretches


# -- the chain and the FE ---------------------------------------------------------------------------------------
def test_the_fe_value_of_a_response_is_that_of_its_centres_as_reported() -> None:
    r = _response(DATA / "path-3d" / "000000100000000.json")
    t = _own_path(r, 8)
    values = path_errors(r, t)
    assert values[8] == pytest.approx(0.0, abs=1e-9) and np.all(values[:8] > 5.0)
    s = score(r, t)
    assert s.level == 8 and s.value == pytest.approx(0.0, abs=1e-9)


def test_a_path_through_a_3d_designs_fe_centres_curling_past_vertical_gives_it_back_certified() -> None:
    """The FE centres at 40.5 kPa (x turns back 8 times) as a path: the certified search over the shipped 3D table
    returns the design, verified by its FE response (from the cache: no solve), and certifies it."""
    r = _response(DATA / "path-3d" / "000000100000000.json")
    assert int(np.sum(np.diff(r.centres[8][:, 0]) < 0)) == 8
    model = make_model(15, {"fidelity": "3d"})
    chain = ChainModel(ChainTable.load(shipped_path("3d")), 15)
    assert model.fingerprint() == r.metadata["fingerprint"]
    cache = EvaluationCache(":memory:")
    cache.put(model.fingerprint(), Outcome(r.orientation, r))
    result = certified_search(model, chain, _own_path(r, 8), CachedEvaluator(SerialEvaluator(), cache))
    assert result.winner.design == r.orientation and result.winner.value == pytest.approx(0.0, abs=1e-9)
    assert result.solves == 0
    assert result.certificate["certified"]
    assert result.winner_chain.value <= result.certificate["bound"]  # the chain's own centres within its error


@pytest.mark.parametrize("library, file", [
    pytest.param("builtin", "library-heldout/heldout-1.json", marks=pytest.mark.slow),
    ("spatial", "space-heldout/heldout-1.json")])
def test_a_path_through_a_library_designs_fe_centres_gives_it_back_by_branch_and_bound(library: str,
                                                                                       file: str) -> None:
    """Over the four-type library (8^15 designs) and the spatial one (4^15, in space) the branch-and-bound returns
    the held-out design whose FE centres the path goes through, within the chain's bound of 0."""
    r = _response(DATA / file)
    chain = ChainModel(find_table(make_model(15, {"fidelity": "3d", "library": library})), 15)
    s = chain_scores(chain, _own_path(r, 9))
    best = s.order()[0]
    assert chain.table.texts(s.bits[[best]]) == [r.orientation]
    assert s.cost[best] <= s.bound[best] and s.level[best] == 9
    assert not s.complete and s.floor > s.cost[best] + s.bound[best] - 0.02


def test_branch_and_bound_over_a_path_keeps_every_design_that_matters(keeps_every_design) -> None:
    """Forced past enumeration (with the bound on the centres still to place), it keeps every design whose enumerated
    cost is below its threshold, with the same cost, and the same best design."""
    chain = ChainModel(ChainTable.load(shipped_path("3d")), 15)
    for name in ("hook", "letter-l"):
        t = make_objective(name)
        every = chain_scores(chain, t)
        grown = chain_scores(chain, t, max_enumerate=10)
        assert len(grown.cost) < len(every.cost) / 10
        keeps_every_design(every, grown)


def test_the_bound_on_the_centres_still_to_place_is_admissible() -> None:
    """On every prefix of 7 units of the 2D table, the prefix bound is at most the best completion's cost, and the
    centres still to place raise it above the partial sums on many prefixes."""
    from pneumorph.design.certified.planegrowth import _prefix_bound
    from pneumorph.design.certified.prefixes import depths, seed_prefixes

    chain = ChainModel(find_table(make_model(7, {"fidelity": "2d"})), 7)
    t = path_target([[0, 6], [40, 6], [60, 20], [55, 45]]).at(chain.length, 6.0)
    every = chain_scores(chain, t)
    codes = chain.table.texts(every.bits)
    best_of = {}
    for d, c in zip(codes, every.cost, strict=True):
        for p in range(1, 8):
            best_of[d[:p]] = min(best_of.get(d[:p], np.inf), c)
    bits, st = seed_prefixes(chain)
    st["sum"] = np.zeros((len(bits), chain.table.n_levels))
    checked = 0
    growth = depths(chain, bits, st)
    for p, placed, bits, st, centres in growth:
        for j, _, _ in centres:
            st["sum"] = st["sum"] + t.term(j, 7, st["point"])
        if p < 7:
            bound = _prefix_bound(chain, t, bits, st, placed)
            exact = np.array([best_of[d] for d in chain.table.texts(bits)])
            assert np.all(bound <= exact + 1e-9)
            checked += int(np.sum(bound > np.sqrt(st["sum"].min(axis=1)) + 0.1))  # tighter than the partial sums
    assert checked > 20  # and it bites


def test_a_path_stage_is_scored_at_its_pressure() -> None:
    r = _response(DATA / "path-3d" / "000000100000000.json")
    t = staged_target([(0.036, _own_path(r, 7)), (0.0405, _own_path(r, 8))])
    chain = ChainModel(ChainTable.load(shipped_path("3d")), 15)
    s = chain_scores(chain, t)
    assert chain.table.texts(s.bits[s.order()[:1]]) == [r.orientation]
    assert float(score(r, t).value) == pytest.approx(0.0, abs=1e-9)


# -- what is refused --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("points, message", [
    ([[0, 0]], "2 to 2000 points"),
    ([[0, 0], [10, float("nan")]], "finite number"),
    ([[3, 4], [3, 4], [3, 4]], "all lie within 1 mm"),
    ([[0, 0], [0.2, 0.3]], "its length is 0.361 mm"),
    ([[0, 0], ["a", 1]], "numbers of mm"),
    ("0 0 10 10", "list of [x, y]"),
    ([[0, 0, 0, 0], [1, 2, 3, 4]], "shape (2, 4)"),
])
def test_bad_paths_are_refused_in_one_line(points, message: str) -> None:
    with pytest.raises(TargetExpressionError, match=message.replace("[", r"\[").replace("(", r"\(")
                       .replace(")", r"\)")):
        path_target(points)


def test_a_path_file_is_read_with_a_header_and_refused_when_it_is_text(tmp_path: Path) -> None:
    good = tmp_path / "hook.csv"
    good.write_text("x,y\n0,6\n80,6\n# a comment\n110,30\n100,60\n")
    assert read_path(good).points[-1] == (100.0, 60.0, 0.0) and read_path(good).name == "hook"
    text = tmp_path / "notes.txt"
    text.write_text("a path\nfrom the base\nto the tip\n")
    with pytest.raises(TargetExpressionError, match="line 2 is not numbers"):
        read_path(text)
    mixed = tmp_path / "mixed.csv"
    mixed.write_text("0 0\n10 0 1\n")
    with pytest.raises(TargetExpressionError, match="line 2 has 3 numbers"):
        read_path(mixed)


def test_a_curve_that_turns_back_or_stands_too_steep_is_refused_naming_path() -> None:
    with pytest.raises(TargetExpressionError, match=r"turns back in x at its point 3.*give it as a path"):
        make_objective("curve", curve=[[0, 0], [80, 10], [70, 40]])
    with pytest.raises(TargetExpressionError, match=r"spans 10 mm in x.*objective = \"path\""):
        make_objective("curve", curve=[[0, 0], [5, 50], [10, 100]])
    assert make_objective("curve", curve=[[0, 0], [80, 2], [160, 5]]).label == "curve: y = curve through 3 points"


def test_path_settings_are_checked() -> None:
    from pneumorph.design import DesignConfig

    c = DesignConfig(objective="path", path=[[0, 6], [100, 6], [130, 40]], units=15)
    assert DesignConfig.from_dict(c.to_dict()) == c and isinstance(c.make_objective(), PathTarget)
    with pytest.raises(SearchConfigError, match="needs its points"):
        DesignConfig(objective="path")
    with pytest.raises(SearchConfigError, match="only used by the objective 'path'"):
        DesignConfig(objective="sin", path=[[0, 0], [10, 0]])
    with pytest.raises(SearchConfigError, match="anchored = false"):
        DesignConfig(objective="hook", anchored=False)
    assert sorted(PATH_PRESETS) == ["coil", "hook", "letter-l", "letter-r", "letter-s", "spiral"]


def test_the_example_finger_path_is_a_valid_path_file() -> None:
    finger = read_path(Path(__file__).parents[2] / "examples" / "paths" / "finger.csv")
    p = finger.polyline()
    assert finger.arc_length() == pytest.approx(60.0 + 35.0 * np.radians(150.0), abs=0.2)  # 15 chords of the arc
    assert p[0].tolist() == [0.0, 6.0, 0.0] and int(np.sum(np.diff(p[:, 0]) < 0)) > 0  # it curls back past vertical

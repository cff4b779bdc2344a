"""Properties of the chain composition over any design (hypothesis): a design turned over is the mirror image of
its shape, a unit's position depends only on the units within its window before it, and designs parse back to
themselves."""

from __future__ import annotations

from importlib import resources

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pneumorph.geometry.alphabet import parse_design
from pneumorph.geometry.library import builtin_library
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.table import ChainTable

UNITS = 15
TABLE = ChainTable.load(resources.files("pneumorph.models") / "data" / "chain-2d.json")
MODEL = ChainModel(TABLE, UNITS)
AXIS = float(MODEL.evaluate("0" * UNITS).reference_tip[1])  # the mid-plane: the undeformed tip's height
designs = st.lists(st.integers(0, 1), min_size=UNITS, max_size=UNITS)


@settings(max_examples=60, deadline=None)
@given(designs)
def test_a_design_turned_over_is_the_mirror_image(bits: list[int]) -> None:
    b = np.array([bits])
    centres, tip, curl = MODEL.predict(b)
    mirrored, tip_m, curl_m = MODEL.predict(1 - b)
    assert np.allclose(mirrored[..., 0], centres[..., 0], rtol=0, atol=1e-9)
    assert np.allclose(mirrored[..., 1], 2 * AXIS - centres[..., 1], rtol=0, atol=1e-9)
    assert np.allclose(tip_m[..., 1], 2 * AXIS - tip[..., 1], rtol=0, atol=1e-9)
    assert np.allclose(curl_m, -curl, rtol=0, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(designs, designs, st.integers(0, UNITS))
def test_a_unit_depends_on_the_units_before_it_within_its_window_only(a: list[int], b: list[int], k: int) -> None:
    """Two designs that agree on their first k units place their first k - window units alike (the chain's elements
    are local: each unit's chord and turn is its window's)."""
    other = np.array([a[:k] + b[k:]])
    centres, _, _ = MODEL.predict(np.array([a]))
    centres_other, _, _ = MODEL.predict(other)
    same = max(0, k - TABLE.window)
    assert np.allclose(centres[..., :same, :], centres_other[..., :same, :], rtol=0, atol=1e-9)


LIBRARY = builtin_library()
letters = st.text(alphabet="".join(s + s.upper() for s in LIBRARY.symbols) + "01", min_size=1, max_size=30)


@settings(max_examples=200, deadline=None)
@given(letters)
def test_a_design_parses_back_to_itself_and_turns_over_twice_to_itself(text: str) -> None:
    d = parse_design(text, LIBRARY)
    assert parse_design(d.text, LIBRARY) == d and parse_design(d, LIBRARY) is d
    assert d.mirror().mirror() == d and d.mirror().symbols == d.symbols
    assert d.n_units == len(text) and all(o != m for o, m in zip(d.orientation, d.mirror().orientation, strict=True))

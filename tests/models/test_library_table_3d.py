"""The shipped 3D chain table of the built-in library (`a`, `e`, `r`, `s`) against the 3D model.

The table: `pneumorph chain build --model 3d --library builtin --window 2 --far-terms --split-terms --all-heldout
--workers 2 --out src/pneumorph/models/data/chain-3d-builtin.json` (split terms of 4 units, written out at window
+-3). Two of its held-out FE responses (15 units, 45 kPa) are kept in tests/data/library-heldout/ (JSON of
`Response.to_dict`), taken from the build's cache.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import build_options, find_table, shipped_path
from pneumorph.models.chain.training import FIXED, unfixed_error
from pneumorph.models.factory import make_model
from pneumorph.models.response import Response

HELDOUT = sorted((Path(__file__).parents[1] / "data" / "library-heldout").glob("*.json"))


@pytest.fixture(scope="module")
def model():
    return make_model(15, {"fidelity": "3d", "library": "builtin"})


@pytest.fixture(scope="module")
def table(model):
    found = find_table(model)
    assert found is not None and found.alphabet == ("a", "e", "r", "s") and found.symmetric == ("e",)
    return found


def test_the_shipped_table_was_validated_within_0_2_mm_on_20_full_length_designs(table) -> None:
    v = table.validation
    assert shipped_path("3d", "builtin").is_file()
    assert table.window == 3 and table.terms["layout"] == "split"
    assert len(v["designs"]) >= 20 and all(len(d) == 15 for d in v["designs"])
    assert not set(v["designs"]) & set(table.training)
    assert max(v["centre_worst_mm"]) <= 0.2 and len(v["centre_worst_mm"]) == table.n_levels == 10
    assert set("aers") <= set("".join(v["designs"]).lower())


@pytest.mark.slow
def test_its_training_fixes_every_window_it_writes_out(table) -> None:
    assert len(table.training) > 600 and all(len(d) == 15 for d in table.training)
    assert unfixed_error(table.training, 2, table.alphabet, (1,), 15) < FIXED
    assert unfixed_error(table.training[:300], 2, table.alphabet, (1,), 15) > 0.1  # the cover and a few: not yet


@pytest.mark.parametrize("path", HELDOUT, ids=lambda p: p.stem)
def test_the_table_composes_held_out_fe_responses_within_its_validation(table, path: Path) -> None:
    fe = Response.load(path)
    assert fe.orientation in table.validation["designs"] and fe.n_units == 15
    chain = ChainModel(table, 15).evaluate(fe.orientation)
    err = np.linalg.norm(chain.centres - fe.centres, axis=-1)  # (levels, units)
    assert err.max() <= max(table.validation["centre_worst_mm"]) + 1e-9
    assert err.max() > 1e-4  # a held-out design: the chain is close, not the FE itself
    np.testing.assert_allclose(chain.tip, fe.tip, atol=max(table.validation["tip_worst_mm"]) + 1e-9, rtol=0)


def test_a_build_over_the_library_takes_the_shipped_tables_layout(model) -> None:
    options = build_options(model)
    assert options["far"] == "split" and options["first_window"] == 3

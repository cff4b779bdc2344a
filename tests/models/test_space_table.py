"""The shipped chain in space of the built-in spatial library (`a`, `l`) against the full 3D model.

The table: `pneumorph chain build --model 3d --library spatial --window 2 --far-terms --short --all-heldout
--out src/pneumorph/models/data/chain-3d-spatial.json`. Two of its held-out FE responses (15 units, full width,
45 kPa) are kept in tests/data/space-heldout/ (JSON of `Response.to_dict`), taken from the build's cache.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pneumorph.models.chain import ChainModel
from pneumorph.models.chaintables import find_table, shipped_path
from pneumorph.models.factory import make_model
from pneumorph.models.response import Response

HELDOUT = sorted((Path(__file__).parents[1] / "data" / "space-heldout").glob("*.json"))


@pytest.fixture(scope="module")
def table():
    model = make_model(15, {"fidelity": "3d", "library": "spatial"})
    found = find_table(model)
    assert found is not None and found.axes == 3  # shipped, and it serves the model that solves planar designs half
    return found


def test_the_shipped_spatial_table_was_validated_within_0_2_mm_on_20_full_length_designs(table) -> None:
    v = table.validation
    assert shipped_path("3d", "spatial").is_file()
    assert len(v["designs"]) >= 20 and all(len(d) == 15 for d in v["designs"])
    assert not set(v["designs"]) & set(table.training)
    assert max(v["centre_worst_mm"]) <= 0.2 and len(v["centre_worst_mm"]) == table.n_levels == 10
    assert any(set(d) & set("lL") for d in v["designs"])


@pytest.mark.parametrize("path", HELDOUT, ids=lambda p: p.stem)
def test_the_chain_in_space_composes_held_out_fe_responses_within_its_validation(table, path: Path) -> None:
    fe = Response.load(path)
    assert fe.orientation in table.validation["designs"] and fe.frames is not None
    chain = ChainModel(table, 15).evaluate(fe.orientation)
    err = np.linalg.norm(chain.centres - fe.centres, axis=-1)  # (levels, units), in space
    assert err.max() <= max(table.validation["centre_worst_mm"]) + 1e-9
    assert np.abs(fe.centres[..., 2] - 7.5).max() > 1.0  # it leaves the plane: the z the chain gets right
    np.testing.assert_allclose(chain.tip, fe.tip, atol=max(table.validation["tip_worst_mm"]) + 1e-9, rtol=0)

"""The shipped chain in space of the built-in spatial library (`a`, `l`) against the full 3D model.

The table: `pneumorph chain build --model 3d --library spatial --window 2 --far-terms --short --all-heldout
--out src/pneumorph/models/data/chain-3d-spatial.json`. Two of its held-out FE responses (15 units, full width,
45 kPa) are kept in tests/data/space-heldout/ (JSON of `Response.to_dict`), taken from the build's cache.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import find_table, shipped_path
from pneumorph.models.chain.space import angle_between
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


def test_the_shipped_spatial_table_predicts_the_end_face_s_frame(table) -> None:
    v = table.validation
    assert table.end_space.shape == (len(table.end_codes), table.n_levels, 3)
    assert len(v["end_frame_worst_deg"]) == table.n_levels and np.isfinite(v["end_frame_worst_deg"]).all()
    assert len(table.validation["designs"]) >= 20  # every held-out design's end face, not a few


@pytest.mark.parametrize("path", HELDOUT, ids=lambda p: p.stem)
def test_the_chain_in_space_gives_the_end_face_s_frame_and_curl_of_held_out_fe_responses(table, path: Path) -> None:
    """The end face's frame composed from the last unit's, against the full model's; its curl is closer to the FE's
    than the view of the chain's projection on the x-y plane gives."""
    fe = Response.load(path)
    assert fe.end_frame is not None
    chain = ChainModel(table, 15).evaluate(fe.orientation)
    assert chain.end_frame is not None
    angle = np.degrees(angle_between(chain.end_frame, fe.end_frame))
    assert angle.max() <= max(table.validation["end_frame_worst_deg"]) + 1e-9
    assert np.degrees(np.linalg.norm(fe.end_frame, axis=-1)).max() > 10.0  # the face turns: a real test
    np.testing.assert_allclose(chain.twist, fe.twist, atol=max(table.validation["end_frame_worst_deg"]) + 1e-9,
                               rtol=0)
    planar_view = ChainModel(replace(table, end_space=np.zeros((0, 0, 3))), 15).evaluate(fe.orientation)
    assert planar_view.end_frame is None
    assert np.abs(chain.curl - fe.curl).max() < np.abs(planar_view.curl - fe.curl).max()

"""Each unit's frame in a full-width response: kept per level, through the cache's JSON, turned by the unit's own
bend; a turned-over sideways unit's frame is its mirror image; planar half-model responses keep none."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.models.factory import make_model
from pneumorph.models.response import Response


@pytest.fixture(scope="module")
def sideways() -> dict[str, Response]:
    """One sideways unit as built and turned over, full model, 20 kPa."""
    return {d: make_model(1, {"fidelity": "3d", "library": "spatial", "pressure_kpa": 20}).evaluate(d)
            for d in ("l", "L")}


def test_a_sideways_unit_turns_about_the_vertical_axis(sideways: dict[str, Response]) -> None:
    """`l` bends towards +z about y; its frame turns about y (by more than a degree at 20 kPa), not about x or z
    (the section is symmetric about its mid-height plane); `L` is its mirror image z -> -z."""
    lo, up = sideways["l"].frames, sideways["L"].frames
    assert lo is not None and up is not None and lo.shape == (len(sideways["l"].pressures), 1, 3)
    last = lo[-1, 0]
    assert abs(last[1]) > np.radians(1) and abs(last[0]) < 1e-3 * abs(last[1]) and abs(last[2]) < 1e-3 * abs(last[1])
    assert np.sign(last[1]) == -np.sign(sideways["l"].centres[-1, 0, 2] - sideways["l"].reference_centres[0, 2])
    # a mirror z -> -z takes a rotation vector (a, b, c) to (-a, -b, c)
    assert np.abs(up - lo * np.array([-1.0, -1.0, 1.0])).max() < 1e-9


def test_frames_survive_the_json_the_cache_keeps(sideways: dict[str, Response]) -> None:
    r = sideways["l"]
    back = Response.from_dict(r.to_dict())
    assert back.frames is not None and np.array_equal(back.frames, r.frames)


def test_a_planar_half_model_response_keeps_no_frames() -> None:
    r = make_model(2, {"fidelity": "3d", "pressure_kpa": 10, "unit": {"element_size": 3.0}}).evaluate("01")
    assert r.axes == 2 and r.frames is None and "frames" not in r.to_dict()

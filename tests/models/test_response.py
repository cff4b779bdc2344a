"""Response: shapes, NaN handling, persistence."""

from pathlib import Path

import numpy as np
import pytest

from pneumorph.models import Response


def make() -> Response:
    p = np.linspace(0.0045, 0.045, 10)
    ref = np.column_stack([np.arange(3) * 10.5 + 5.25, np.zeros(3)])
    r = Response.empty("011", p, ref, np.array([31.5, 0.0]), converged=False, reached=0.0225, failure="test")
    r.centres[:5] = ref + np.arange(5)[:, None, None] * 0.1
    r.tip[:5] = [31.5, 1.0]
    r.curl[:5] = np.linspace(1, 5, 5)
    return r


def test_round_trip_keeps_nan_and_values(tmp_path: Path) -> None:
    r = make()
    r.save(tmp_path / "resp")
    back = Response.load(tmp_path / "resp")
    np.testing.assert_array_equal(back.centres, r.centres)  # NaN positions equal too
    assert back.orientation == "011" and not back.converged and back.failure == "test"
    assert back.reached == pytest.approx(0.0225)
    with np.load(tmp_path / "resp.npz") as z:
        np.testing.assert_array_equal(z["curl"], r.curl)


def test_level_lookup_and_centreline() -> None:
    r = make()
    assert r.level_of(0.036) == 7
    with pytest.raises(KeyError, match="not a reported level"):
        r.level_of(0.037)
    line = r.centreline(2)
    assert line.shape == (5, 2)
    np.testing.assert_allclose(r.displacements[2], 0.2)


def test_shape_mismatch_is_rejected() -> None:
    with pytest.raises(ValueError, match="centres has shape"):
        Response("01", np.zeros(2), np.zeros((2, 3, 2)), np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2), np.zeros(2))

"""One centre-line function: the bench's centrelines (plain lists for JSON) are the design figure's
(:func:`pneumorph.design.runs.pathfigure.centrelines`) rounded to 1e-4 mm, on one planar and one spatial response
whose lines are written out here by hand: the base on the undeformed axis, the unit centres, the tip; z from the
mid-plane in space."""

from __future__ import annotations

import json

import numpy as np

from pneumorph.bench.samples import centrelines as bench_centrelines
from pneumorph.design.runs.pathfigure import centrelines as design_centrelines
from pneumorph.models import Response


def _planar() -> Response:
    centres = np.array([[[5.0, 6.0], [15.0, 6.0]], [[4.98766, 6.5], [14.0, 9.123456]]])
    tip = np.array([[20.0, 6.0], [18.5, 12.25]])
    return Response("01", np.array([0.0225, 0.045]), centres, np.array([[5.0, 6.0], [15.0, 6.0]]), tip,
                    np.array([20.0, 6.0]), np.array([0.0, 30.0]))


def _spatial() -> Response:
    centres = np.array([[[5.0, 6.0, 7.5]], [[4.9, 6.7, 8.25]]])
    tip = np.array([[10.0, 6.0, 7.5], [9.5, 7.5, 9.0]])
    return Response("0", np.array([0.0225, 0.045]), centres, np.array([[5.0, 6.0, 7.5]]), tip,
                    np.array([10.0, 6.0, 7.5]), np.array([0.0, 10.0]))


def test_a_planar_response_gives_one_line_both_ways() -> None:
    expected = [[[0.0, 6.0], [5.0, 6.0], [15.0, 6.0], [20.0, 6.0]],
                [[0.0, 6.0], [4.9877, 6.5], [14.0, 9.1235], [18.5, 12.25]]]
    lines = bench_centrelines(_planar())
    assert lines == expected and json.loads(json.dumps(lines)) == expected  # plain lists, as the JSON carries them
    np.testing.assert_allclose(design_centrelines(_planar()), expected, atol=5e-5)
    np.testing.assert_array_equal(np.round(design_centrelines(_planar()), 4), lines)


def test_a_response_in_space_measures_z_from_the_mid_plane_both_ways() -> None:
    expected = [[[0.0, 6.0, 0.0], [5.0, 6.0, 0.0], [10.0, 6.0, 0.0]],
                [[0.0, 6.0, 0.0], [4.9, 6.7, 0.75], [9.5, 7.5, 1.5]]]
    assert bench_centrelines(_spatial()) == expected
    np.testing.assert_allclose(design_centrelines(_spatial()), expected, atol=1e-12)

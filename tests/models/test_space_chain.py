"""A chain in space: tables of per-window chords and frame turns, fitted, composed, saved and restricted.

The law here is a chain in space whose elements are local by construction (each chord and
frame turn a random function of its window, turned over with the window as a half turn of
the actuator about its axis turns it): a table must then reproduce every design exactly,
of any length, from the covering designs alone. Against the FE model:
tests/models/test_space_table.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import ChainTableError
from pneumorph.models.chain.fit import fit_table, training_designs
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import restrict_table
from pneumorph.models.chain.space import rotation_matrices
from pneumorph.models.chain.tablefile import SPACE_FORMAT
from pneumorph.models.chain.validation import heldout_designs
from pneumorph.models.chain.windows import covering_designs
from pneumorph.models.response import Response
from tests.spacelaw import ALPHABET, LEVELS, LIBRARY, W, _law, _response, _source, undeformed_of


@pytest.fixture(scope="module")
def law() -> dict[int, np.ndarray]:
    return _law(7)


@pytest.fixture(scope="module")
def undeformed() -> dict[int, tuple[np.ndarray, np.ndarray]]:
    return undeformed_of()

@pytest.mark.parametrize("far", [False, True])
def test_a_chain_in_space_reproduces_a_local_law_exactly_at_any_length(law, undeformed, far: bool) -> None:
    train = [_response(d, law, undeformed) for d in training_designs(7, W, far, True, ALPHABET)]
    assert {r.n_units for r in train} > {7}  # short designs for the ends, as a build takes them
    table = fit_table(train, W, _source(), library=LIBRARY, far=far)
    assert table.axes == 3 and table.space.shape == (len(table.codes), LEVELS, 6) and table.centre_z == 7.5
    assert table.spread < 1e-9
    for n in (7, 10):
        tests = heldout_designs(n, 6, exclude=[], seed=3, alphabet=ALPHABET)
        model = ChainModel(table, n)
        for design in tests:
            want, got = _response(design, law, undeformed), model.evaluate(design)
            assert got.centres.shape == (LEVELS, n, 3) and got.reference_centres.shape == (n, 3)
            np.testing.assert_allclose(got.centres, want.centres, atol=1e-9, rtol=0)
            np.testing.assert_allclose(got.tip, want.tip, atol=1e-9, rtol=0)
            np.testing.assert_allclose(got.reference_centres, want.reference_centres, atol=1e-12, rtol=0)
    sideways = [d for d in tests if "l" in d.lower()]
    assert sideways and np.abs(_response(sideways[0], law, undeformed).centres[..., 2] - 7.5).max() > 0.1


def test_every_unit_turned_over_turns_the_chain_half_a_turn_about_the_axis(law, undeformed) -> None:
    """The covering designs show one of each mirrored pair of windows; the other is read through the mirror."""
    designs = training_designs(7, W, False, True, ALPHABET)
    assert len(designs) < len(covering_designs(7, W, mirror=False, n_types=2, alphabet=ALPHABET, short=True))
    model = ChainModel(fit_table([_response(d, law, undeformed) for d in designs], W, _source(), library=LIBRARY), 7)
    design = "LalAAlL"
    one, other = model.evaluate(design), model.evaluate(design.swapcase())
    axis = np.array([6.0, 7.5])  # the section's centre (y, z): the end face's
    np.testing.assert_allclose(other.centres[..., 0], one.centres[..., 0], atol=1e-9, rtol=0)
    np.testing.assert_allclose(other.centres[..., 1:], 2 * axis - one.centres[..., 1:], atol=1e-9, rtol=0)
    np.testing.assert_allclose(one.centres, _response(design, law, undeformed).centres, atol=1e-9, rtol=0)


@pytest.mark.parametrize("far", [False, True])
def test_a_chain_in_space_survives_its_file_and_refuses_tampering(law, undeformed, tmp_path: Path, far: bool) -> None:
    train = [_response(d, law, undeformed) for d in training_designs(7, W, far, True, ALPHABET)]
    table = fit_table(train, W, _source(), library=LIBRARY, far=far)
    path = table.save(tmp_path / "space.json")
    data = json.loads(path.read_text())
    assert data["format"] == SPACE_FORMAT and data["layout"] == (3 if far else 2) and data["centre_z_mm"] == 7.5
    again = ChainTable.load(path)
    assert again.fingerprint() == table.fingerprint() and again.axes == 3
    np.testing.assert_array_equal(again.space, table.space)
    bits = table.designs(["alLAa", "LLaal"])
    np.testing.assert_array_equal(again.predict(bits)[0], table.predict(bits)[0])
    key = "terms" if far else "space_turn_rad"
    if far:
        data[key]["chord"][0]["values"][0][-1] += 1e-3  # an element in space of one term
    else:
        data[key][0][0][1] += 1e-3
    path.write_text(json.dumps(data))
    with pytest.raises(ChainTableError, match="fingerprint"):
        ChainTable._read(path)
    del data["layout"]
    path.write_text(json.dumps(data))
    with pytest.raises(ChainTableError, match="unknown layout"):
        ChainTable._read(path)


def test_a_restricted_chain_in_space_predicts_the_first_levels(law, undeformed) -> None:
    train = [_response(d, law, undeformed, ends=True)
             for d in covering_designs(7, W, n_types=2, alphabet=ALPHABET, short=True)]
    source = {**_source(), "description": {"pressure_mpa": 0.03, "steps": {"increments": 3}}}
    from pneumorph.io.provenance import digest

    source["key"] = digest(source["description"])
    table = fit_table(train, W, source, library=LIBRARY)
    short = restrict_table(table, 2)
    bits = table.designs(["alLAalA"])
    np.testing.assert_array_equal(short.predict(bits)[0], table.predict(bits)[0][:, :2])
    np.testing.assert_array_equal(short.end_frames(bits), table.end_frames(bits)[:, :2])
    assert short.space.shape[1] == 2 and short.end_space.shape[1] == 2


def test_planar_and_space_responses_are_not_mixed_in_one_table(law, undeformed) -> None:
    space = _response("alA", law, undeformed)
    planar = Response(space.orientation, space.pressures, space.centres[..., :2], space.reference_centres[:, :2],
                      space.tip[:, :2], space.reference_tip[:2], space.curl)
    with pytest.raises(ChainTableError, match="full width"):
        fit_table([space, planar], W, _source(), library=LIBRARY)


@pytest.mark.parametrize("far", [False, True])
def test_a_chain_in_space_predicts_the_end_face_s_frame_and_twist_of_a_local_law(law, undeformed, far: bool,
                                                                                 tmp_path: Path) -> None:
    """The end face's turn from the last unit's frame, keyed by the last chord's window, composes the end face's frame
    exactly at any length; turned over, the frame turns half a turn about the axis, its twist unchanged; it survives
    the file."""
    train = [_response(d, law, undeformed, ends=True) for d in training_designs(7, W, far, True, ALPHABET)]
    table = fit_table(train, W, _source(), library=LIBRARY, far=far)
    assert table.end_space.shape == (len(table.end_codes), LEVELS, 3) and table.spread < 1e-9
    assert np.abs(table.end_space).max() > 0.01
    for n in (7, 10):
        model = ChainModel(table, n)
        for design in heldout_designs(n, 6, exclude=[], seed=4, alphabet=ALPHABET):
            want, got = _response(design, law, undeformed, ends=True), model.evaluate(design)
            np.testing.assert_allclose(rotation_matrices(got.end_frame), rotation_matrices(want.end_frame),
                                       atol=1e-12, rtol=0)
            np.testing.assert_allclose(got.twist, want.twist, atol=1e-9, rtol=0)
            assert np.abs(want.end_frame).max() > 0.01
            up = rotation_matrices(want.end_frame)[:, :, 1]  # the curl: the face's line up its height in x-y
            np.testing.assert_allclose(got.curl, np.degrees(np.arctan2(-up[:, 0], up[:, 1])), atol=1e-9, rtol=0)
    one, other = model.evaluate("LalAAlLaaL"), model.evaluate("lALaaLlAAl")
    np.testing.assert_allclose(other.end_frame, one.end_frame * [1, -1, -1], atol=1e-12, rtol=0)
    np.testing.assert_allclose(other.twist, one.twist, atol=1e-9, rtol=0)  # a half turn about x keeps a twist about x
    assert np.abs(one.twist).max() > 0.1
    path = table.save(tmp_path / "space.json")
    again = ChainTable.load(path)
    assert again.fingerprint() == table.fingerprint() != fit_table(
        [_response(d, law, undeformed) for d in training_designs(7, W, far, True, ALPHABET)], W, _source(),
        library=LIBRARY, far=far).fingerprint()
    np.testing.assert_array_equal(again.end_space, table.end_space)
    if not far:  # the windows' file holds the end face's turns beside the elements in space
        data = json.loads(path.read_text())
        data["space_end_turn_rad"][0][0][2] += 1e-3
        path.write_text(json.dumps(data))
        with pytest.raises(ChainTableError, match="fingerprint"):
            ChainTable._read(path)


def test_a_table_without_the_end_face_s_turns_predicts_no_end_frame(law, undeformed) -> None:
    table = fit_table([_response(d, law, undeformed) for d in training_designs(7, W, False, True, ALPHABET)], W,
                      _source(), library=LIBRARY)
    assert table.end_space.shape[0] == 0 and ChainModel(table, 7).evaluate("LalAAlL").end_frame is None
    mixed = [_response("alAl", law, undeformed, ends=True), _response("Alal", law, undeformed)]
    with pytest.raises(ChainTableError, match="end face"):
        fit_table(mixed, W, _source(), library=LIBRARY)


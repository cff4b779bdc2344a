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
from pneumorph.geometry.library import builtin_library
from pneumorph.models.chain import ChainModel, ChainTable
from pneumorph.models.chainfit import fit_table, training_designs
from pneumorph.models.chaintable import SPACE_FORMAT
from pneumorph.models.chaintables import restrict_table
from pneumorph.models.response import Response
from pneumorph.models.spacechords import MIRROR_SIGNS, chain_points, rotation_matrices
from pneumorph.models.validation import heldout_designs
from pneumorph.models.windows import covering_designs, design_array, mirror_codes, window_codes

LIBRARY = builtin_library("spatial")
ALPHABET = LIBRARY.alphabet
LEVELS = 3
W = 1
PRESSURES = np.array([0.01, 0.02, 0.03])


def _law(seed: int) -> dict[int, np.ndarray]:
    """Random elements (levels, 6) per window code of +-1, a window's mirror holding its elements turned over."""
    rng = np.random.default_rng(seed)
    law: dict[int, np.ndarray] = {}
    designs = covering_designs(9, W, mirror=False, n_types=2, alphabet=ALPHABET)
    for codes in window_codes(design_array(designs, alphabet=ALPHABET), W, n_types=2):
        for code, mirrored in zip(codes, mirror_codes(codes, W, 2), strict=True):
            if int(code) in law:
                continue
            scale = np.array([0.2, 0.3, 0.3, 0.02, 0.04, 0.04]) * np.linspace(0.5, 1.0, LEVELS)[:, None]
            values = rng.uniform(-1, 1, (LEVELS, 6)) * scale + np.array([10.5, 0, 0, 0, 0, 0])
            law[int(code)] = values
            law[int(mirrored)] = values * MIRROR_SIGNS
    return law


@pytest.fixture(scope="module")
def law() -> dict[int, np.ndarray]:
    return _law(7)


@pytest.fixture(scope="module")
def undeformed() -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per length: the unit centres' x and the tip of the full-width mesh (the same for every design of a length).

    Units of 10.5 mm with their cavities' middles 5.25 mm in, and the end face's centre on the
    axis (the fit checks these against the library's units).
    """
    return {n: (5.25 + 10.5 * np.arange(n), np.array([10.5 * n, 6.0, 7.5])) for n in range(1, 11)}


def _response(design: str, law: dict[int, np.ndarray], undeformed: dict) -> Response:
    """The law's response of ``design``: points composed from its elements, each unit's frame, no curl."""
    codes = design_array(design, alphabet=ALPHABET)
    values = np.stack([law[int(c)] for c in window_codes(codes, W, n_types=2)[0]])  # (n + 1, k, 6)
    values[0, :, 3:] = 0.0  # the base's frame is the actuator's own
    x, tip = undeformed[len(design)]
    heights = {0: 4.5, 1: 7.5, 2: 6.0, 3: 6.0}  # a, A, l, L: the tracked cavity corners' middle
    reference = np.stack([x, [heights[int(c)] for c in codes[0]], np.full(len(x), 7.5)], axis=-1)
    turns = rotation_matrices(values[..., 3:]).transpose(1, 0, 2, 3)  # (k, n + 1, 3, 3)
    start = np.array([0.0, reference[0, 1], 7.5])
    points = chain_points(values[..., :3].transpose(1, 0, 2), turns, start)
    frames = np.stack([np.linalg.multi_dot([np.eye(3), *turns[lev, : j + 2]]) for lev in range(LEVELS)
                       for j in range(len(design))]).reshape(LEVELS, len(design), 3, 3)
    from scipy.spatial.transform import Rotation

    rotvec = Rotation.from_matrix(frames.reshape(-1, 3, 3)).as_rotvec().reshape(LEVELS, len(design), 3)
    return Response(design, PRESSURES, points[:, 1:-1], reference, points[:, -1], tip, np.zeros(LEVELS),
                    frames=rotvec)


def _source() -> dict:
    return {"fidelity": "law", "key": "law", "n_units": 7}


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
    train = [_response(d, law, undeformed) for d in covering_designs(7, W, n_types=2, alphabet=ALPHABET, short=True)]
    source = {**_source(), "description": {"pressure_mpa": 0.03, "steps": {"increments": 3}}}
    from pneumorph.io.provenance import digest

    source["key"] = digest(source["description"])
    table = fit_table(train, W, source, library=LIBRARY)
    short = restrict_table(table, 2)
    bits = table.designs(["alLAalA"])
    np.testing.assert_array_equal(short.predict(bits)[0], table.predict(bits)[0][:, :2])
    assert short.space.shape[1] == 2


def test_planar_and_space_responses_are_not_mixed_in_one_table(law, undeformed) -> None:
    space = _response("alA", law, undeformed)
    planar = Response(space.orientation, space.pressures, space.centres[..., :2], space.reference_centres[:, :2],
                      space.tip[:, :2], space.reference_tip[:2], space.curl)
    with pytest.raises(ChainTableError, match="full width"):
        fit_table([space, planar], W, _source(), library=LIBRARY)

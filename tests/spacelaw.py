"""A chain in space whose elements are local by construction, for the tests of the chain in space and its search.

Each chord and frame turn is a random function of its window (+-1), turned over with the
window as a half turn of the actuator about its axis turns it.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from pneumorph.geometry.library import builtin_library
from pneumorph.models.chain.space import MIRROR_SIGNS, chain_points, rotation_matrices
from pneumorph.models.chain.windows import covering_designs, design_array, mirror_codes, window_codes
from pneumorph.models.response import Response

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


def undeformed_of() -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Per length: the unit centres' x and the tip of the full-width mesh (the same for every design of a length).

    Units of 10.5 mm with their cavities' middles 5.25 mm in, and the end face's centre on the
    axis (the fit checks these against the library's units).
    """
    return {n: (5.25 + 10.5 * np.arange(n), np.array([10.5 * n, 6.0, 7.5])) for n in range(1, 16)}


def end_turn(code: int) -> np.ndarray:
    """The law's end face's turn (levels, 3) from the last unit's frame, of the last chord's window ``code``: random
    per window, turned over with it (the turn's signs of ``MIRROR_SIGNS``)."""
    mirrored = int(mirror_codes(np.array([code]), W, 2)[0])
    values = np.random.default_rng(min(code, mirrored)).uniform(-0.03, 0.03, (LEVELS, 3))
    return values if code <= mirrored else values * MIRROR_SIGNS[3:]


def _response(design: str, law: dict[int, np.ndarray], undeformed: dict, ends: bool = False) -> Response:
    """The law's response of ``design``: points composed from its elements, each unit's frame, no curl; with
    ``ends``, the end face's frame (the last unit's turned by :func:`end_turn`)."""
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
    rotvec = Rotation.from_matrix(frames.reshape(-1, 3, 3)).as_rotvec().reshape(LEVELS, len(design), 3)
    end = None
    if ends:
        last = int(window_codes(codes, W, n_types=2)[0][-1])
        end = Rotation.from_matrix(frames[:, -1] @ rotation_matrices(end_turn(last))).as_rotvec()
    return Response(design, PRESSURES, points[:, 1:-1], reference, points[:, -1], tip, np.zeros(LEVELS),
                    frames=rotvec, end_frame=end)


def _source() -> dict:
    return {"fidelity": "law", "key": "law", "n_units": 7}



"""A chain table's entries as window means: each window's elements averaged over its occurrences in FE responses.

The plain fit of :func:`~pneumorph.models.chain.fit.fit_table` (without far-field terms,
:mod:`pneumorph.models.chain.terms`): every window an actuator shows is solved in the training
designs, and its entry is the mean of its chords (and, turned over, of its mirrored chords);
the last chord's window keys the end turn and, for a chain in space, the end face's turn.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from pneumorph.errors import ChainTableError
from pneumorph.models.chain.terms import chord_spread, chord_values
from pneumorph.models.chain.windows import design_array, mirror_codes, window_codes
from pneumorph.models.response import FloatArray, Response


def check_training(responses: Sequence[Response]) -> tuple[Response, FloatArray]:
    """The longest training response and the pressure levels all share.

    Raises
    ------
    ChainTableError
        No responses, one that did not converge, or responses of different levels.
    """
    if not responses:
        raise ChainTableError("a chain table needs at least one training response")
    longest = max(responses, key=lambda r: r.n_units)
    pressures = responses[0].pressures
    for r in responses:
        if not r.converged or not np.isfinite(r.centres).all():
            raise ChainTableError(f"training design {r.orientation} did not converge; the chain table needs "
                                  "every training design solved to the last level")
        if not np.allclose(r.pressures, pressures, rtol=0, atol=1e-12):
            raise ChainTableError("training responses of different pressure levels")
        if (r.frames is None) != (longest.frames is None):
            where = "in" if r.frames is None else "out of"
            raise ChainTableError(f"training design {r.orientation} was solved {where} the plane and others the other "
                                  "way; a chain in space needs every training design solved on the full width")
        if (r.end_frame is None) != (longest.end_frame is None):
            raise ChainTableError(f"training designs {r.orientation} and {longest.orientation}: one keeps its end "
                                  "face's frame and the other not (an older response): solve them again")
    return longest, pressures


def window_means(responses: Sequence[Response], w: int, mirror: bool, alphabet: tuple[str, ...],
                  symmetric: tuple[int, ...], levels: int) -> dict[str, Any]:
    """Every window's mean turn and length, every end window's mean end turn, and the largest deviation.

    The means are over the window's occurrences in ``responses`` (and, with ``mirror``, over
    the mirrored occurrences with negated turns), per level.

    Returns
    -------
    dict
        :class:`~pneumorph.models.chain.table.ChainTable`'s ``codes``, ``turn``, ``length``,
        ``end_codes``, ``end`` and ``spread``; for a chain in space ``space`` and, from
        responses that keep the end face's frame, ``end_space``.
    """
    k = max(1, len(alphabet))
    all_codes, all_values, e_codes, e_end = [], [], [], []
    for r in responses:
        chords, signs, end, end_signs = chord_values(r)
        codes = window_codes(design_array(r.orientation, alphabet=alphabet, symmetric=symmetric), w, n_types=k)[0]
        variants = [(codes, 1.0)] + ([(mirror_codes(codes, w, k, symmetric), -1.0)] if mirror else [])
        for c, sign in variants:
            all_codes.append(c)
            all_values.append(chords if sign > 0 else chords * signs)
            e_codes.append(c[-1:])
            e_end.append((end if sign > 0 else end * end_signs)[None])
    codes = np.concatenate(all_codes)
    values = np.concatenate(all_values)  # turns, lengths (and the elements in space) per level
    uniq, inv = np.unique(codes, return_inverse=True)
    means = np.zeros((len(uniq), values.shape[1]))
    np.add.at(means, inv, values)
    means /= np.bincount(inv)[:, None]
    spread = chord_spread(values - means[inv], levels)
    euniq, einv = np.unique(np.concatenate(e_codes), return_inverse=True)
    ends = np.concatenate(e_end)
    mean_end = np.zeros((len(euniq), ends.shape[1]))
    np.add.at(mean_end, einv, ends)
    mean_end /= np.bincount(einv)[:, None]
    space = {"space": means[:, 2 * levels:].reshape(len(uniq), levels, 6)} if values.shape[1] > 2 * levels else {}
    if ends.shape[1] > levels:  # the end face's turns of a chain in space
        space["end_space"] = mean_end[:, levels:].reshape(len(euniq), levels, 3)
        spread = max(spread, float(np.abs((ends - mean_end[einv])[:, levels:]).max()))
    return {"codes": uniq, "turn": means[:, :levels], "length": means[:, levels:2 * levels], "end_codes": euniq,
            "end": mean_end[:, :levels], "spread": spread, **space}


__all__ = ["check_training", "window_means"]

"""A chain table's undeformed geometry, read from its training responses and checked against them.

The turns and lengths of a table (:mod:`pneumorph.models.chain.means`, :mod:`pneumorph.models.chain.terms`) say
how the chords move; where they start is the actuator's undeformed geometry: the units' pitch, the heights of
their centres in either orientation, the first centre's offset from the base and the tip's place after the last
centre. A 0/1 table reads them from its training designs (:func:`binary_geometry`); a table over a unit library
takes each type's pitch and cavity middle from the library and checks that the training actuators' undeformed
centres are where the library's units put them (:func:`library_geometry`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from pneumorph.errors import ChainTableError
from pneumorph.geometry.library import UnitLibrary
from pneumorph.models.chain.table import ChainTable
from pneumorph.models.chain.windows import design_array, design_strings
from pneumorph.models.response import Response


def binary_geometry(responses: Sequence[Response], longest: Response, mirror: bool) -> dict[str, Any]:
    """The undeformed geometry of a 0/1 table: pitch, both orientations' centre heights, first centre, tip.

    Parameters
    ----------
    responses : sequence of Response
        The training responses; ``longest`` the longest of them (its centres give the pitch).
    mirror : bool
        Each orientation's centre height mirrored about the tip's gives the other's.

    Raises
    ------
    ChainTableError
        Training designs without both orientations at fixed heights, or unevenly spaced units.

    Examples
    --------
    >>> r = Response.empty("01", np.array([0.01]), np.array([[5.25, 4.5], [15.75, 7.5]]), np.array([21.0, 6.0]))
    >>> binary_geometry([r], r, mirror=True)
    {'pitch': 10.5, 'centre_y': (4.5, 7.5), 'first_offset': 5.25, 'tip_ref': (5.25, 6.0)}
    """
    xs = longest.reference_centres[:, 0]
    pitch = float(np.mean(np.diff(xs)))
    tip_y = float(longest.reference_tip[1])
    heights: dict[int, list[float]] = {0: [], 1: []}
    for r in responses:
        for o, y in zip(r.orientation, r.reference_centres[:, 1], strict=False):
            heights[int(o)].append(float(y))
            if mirror:
                heights[1 - int(o)].append(2 * tip_y - float(y))
    if not heights[0] or not heights[1] or max(np.ptp(heights[0]), np.ptp(heights[1])) > 1e-9:
        raise ChainTableError("the training designs do not show both unit orientations at fixed heights")
    if not np.allclose(np.diff(xs), pitch, atol=1e-9):
        raise ChainTableError("the training actuator's unit centres are not evenly spaced; a chain table "
                              "needs identical units")
    return {"pitch": pitch, "centre_y": (heights[0][0], heights[1][0]), "first_offset": float(xs[0]),
            "tip_ref": (float(longest.reference_tip[0] - xs[-1]), tip_y)}


def library_geometry(responses: Sequence[Response], alphabet: tuple[str, ...], library: UnitLibrary, mirror: bool,
                     table: ChainTable) -> ChainTable:
    """``table`` with the undeformed geometry of its unit types, checked against the training actuators.

    Parameters
    ----------
    responses : sequence of Response
        The training responses, designs over ``alphabet`` (the table's unit types, symbols of ``library``).
    mirror : bool
        A unit's centre height mirrored about the tip's gives its turned-over one's.
    table : ChainTable
        The fitted table; its geometry fields are replaced.

    Raises
    ------
    ChainTableError
        A unit type or orientation that no training design shows, a type's centre at different heights, or
        undeformed centres that are not where the library's units put them.

    Examples
    --------
    >>> from pneumorph.geometry.library import builtin_library
    >>> from pneumorph.models.chain.sources import shipped_path
    >>> r = Response.empty("aa", np.array([0.01]), np.array([[5.25, 4.5], [15.75, 4.5]]), np.array([21.0, 6.0]))
    >>> library_geometry([r], ("a", "e"), builtin_library(), True, ChainTable.load(shipped_path("2d")))
    Traceback (most recent call last):
    ...
    pneumorph.errors.ChainTableError: the training designs do not show the unit(s) e, E; every type and
    orientation must occur
    """
    k = len(alphabet)
    pitch = tuple(float(library[a].pitch) for a in alphabet)
    offset = tuple(float(sum(library[a].cavity[:2]) / 2) for a in alphabet)  # the tracked cavity's middle
    tip_y = float(responses[0].reference_tip[1])
    heights: dict[int, list[float]] = {c: [] for c in range(2 * k)}
    symmetric = set(library.symmetric_types)
    for r in responses:
        codes = design_array(r.orientation, alphabet=alphabet)[0]
        for c, y in zip(codes, r.reference_centres[:, 1], strict=True):
            heights[int(c)].append(float(y))
            if mirror:
                heights[int(c) ^ 1].append(2 * tip_y - float(y))
            if int(c) // 2 in symmetric:  # turned over, the same body: its centre where it was
                heights[int(c) ^ 1].append(float(y))
    missing = [design_strings(np.array([[c]], dtype=np.uint8), alphabet)[0] for c, ys in heights.items() if not ys]
    if missing:
        raise ChainTableError(f"the training designs do not show the unit(s) {', '.join(missing)}; every type and "
                              "orientation must occur")
    if max(np.ptp(ys) for ys in heights.values()) > 1e-9:
        raise ChainTableError("the training designs show a unit type's centre at different heights")
    first = responses[0]
    cap = float(first.reference_tip[0]) - float(np.sum([library[a].pitch for a in
                                                         first_symbols(first.orientation, alphabet)]))
    geometry = {"type_pitch": pitch, "type_offset": offset,
                "type_centre_y": tuple(heights[c][0] for c in range(2 * k))}
    fitted = ChainTable(**{**table.__dict__, "alphabet": alphabet, **geometry, "pitch": pitch[0],
                           "symmetric": library.symmetric,
                           "centre_y": (heights[0][0], heights[1][0]), "first_offset": offset[0],
                           "tip_ref": (cap + pitch[0] - offset[0], tip_y)})
    for r in responses:
        centres, tip = fitted.reference(fitted.designs(r.orientation))
        if not (np.allclose(centres[0], r.reference_centres, atol=1e-9, rtol=0)
                and np.allclose(tip[0], r.reference_tip, atol=1e-9, rtol=0)):
            raise ChainTableError(f"the undeformed centres of training design {r.orientation} are not where the "
                                  "library's units put them (pitch, cavity middle); a table of another library?")
    return fitted


def first_symbols(design: str, alphabet: Sequence[str]) -> str:
    """The type symbol of every unit of a design over ``alphabet`` (lower case; digits: the first type).

    >>> first_symbols("aE1", ("a", "e"))
    'aea'
    """
    return "".join(alphabet[int(c) // 2] for c in design_array(design, alphabet=alphabet)[0])



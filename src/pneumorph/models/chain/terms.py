"""Chain elements as a window's element plus far-field terms (a table of window +-w reaching +-(w + 1)).

A table of window +-w keys each chord's turn and length by the ``2w + 1`` units around it,
and so misses the units just beyond: for the built-in unit's 3D model, window +-2 is off by
0.2 mm at the tip, window +-3 by a hundredth, but a table of window +-3 needs every one of
its windows solved, the ``2^6`` end windows alone on 32 actuators of 6 units. The units
beyond the window act through the ones between (Saint-Venant: the self-equilibrated
stresses of a pressurised cavity decay along the actuator), and the effects of the two sides
add up. So the element of chord ``j`` is written as

    E(j) = A(units j - w .. j + w) + R(units j .. j + w + 1) + L(units j - w - 1 .. j)

with ``A`` the window's term and ``R``, ``L`` the *far-field terms* of the next unit on each
side, read with the units between it and the chord. The three tables are fitted together
to the training chords by backfitting (each in turn the mean of what the others leave,
until they settle), over the mirrored chords too. The sum is then written out as an
ordinary table of window +-(w + 1), one entry per window an actuator can show, so every
reader of chain tables uses it unchanged.

The training needs every key of the three terms: the end windows of +-w (actuators of
``2w`` units, :func:`~pneumorph.models.chain.windows.end_designs`) and the interior windows of
+-(w + 1) on full-length actuators (:func:`far_designs`). Measured on the built-in unit with
a 2.5 mm layer (3D, 15 units, the 20 held-out designs of its table): window +-2 alone is off
by 0.196 mm, with far-field terms 0.0077 mm, the table of window
+-3 by 0.0085 mm, trained on 167 unit solves instead of 327 (docs/chain-model.md).
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import ChainTableError
from pneumorph.models.chain.space import MIRROR_SIGNS, end_turns, space_rows
from pneumorph.models.chain.windows import (
    canonical_codes,
    covering_designs,
    design_array,
    end_designs,
    mirror_symbols,
    possible_codes,
    window_symbols,
)
from pneumorph.models.response import Response, response_elements

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: backfitting rounds at most; they stop earlier once no term moves by more than :data:`SETTLED`
ROUNDS = 200
#: the change (rad, mm) under which the terms count as settled
SETTLED = 1e-12


#: the layouts of a table's terms: ``far`` (the window's term and one far-field term per side) and ``split``
#: (every run of ``2w`` units within +-(w + 1), :func:`far_terms`)
LAYOUTS = ("far", "split")


def term_layout(far: bool | str) -> str:
    """The layout a build's ``far`` names: ``""`` (a plain window), ``"far"`` (``True``) or ``"split"``.

    >>> term_layout(True), term_layout(False), term_layout("split")
    ('far', '', 'split')
    """
    if far is True or far is False:
        return "far" if far else ""
    if far in ("", *LAYOUTS):
        return str(far)
    raise ChainTableError(f"unknown layout of chain terms {far!r}: one of {', '.join(LAYOUTS)}")


def far_terms(window: int, layout: bool | str = "far") -> tuple[tuple[int, int], ...]:
    """The terms of a table of window +-w with far-field terms: unit offsets ``(lo, hi)`` from the chord.

    ``far``: the window's units and, per side, the next unit with those between it and the
    chord. ``split``: every run of ``2w`` units within +-(w + 1); no term reads ``2w + 1``
    units, so the training shows fewer keys (over ``c`` unit codes, ``c^(2w)`` instead of
    ``c^(2w + 1)``), at the price of the interactions of units ``2w`` apart at most.

    >>> far_terms(2)
    ((-2, 2), (0, 3), (-3, 0))
    >>> far_terms(2, "split")
    ((-3, 0), (-2, 1), (-1, 2), (0, 3))
    """
    w = int(window)
    if term_layout(layout) == "split":
        return tuple((lo, lo + 2 * w - 1) for lo in range(-(w + 1), 3 - w))
    return ((-w, w), (0, w + 1), (-(w + 1), 0))


def end_terms(window: int, layout: bool | str = "far") -> tuple[tuple[int, int], ...]:
    """The terms of the last chord's end turn: those of :func:`far_terms`, or with ``split`` one term, the last
    ``2w - 1`` units (the end face turns with the units next to it; one key per run of them).

    >>> end_terms(2, "split")
    ((-2, 3),)
    """
    w = int(window)
    return ((-(2 * w - 2), w + 1),) if term_layout(layout) == "split" else far_terms(w)


def far_designs(n_units: int, window: int, mirror: bool = True, seed: int = 0) -> list[str]:
    """Training designs of a table of window +-w with far-field terms (0/1 designs).

    The end windows of +-w from actuators of ``2w`` units (``w + 2`` for ``w = 1``: the
    last chord's far-field term on the base side reads ``w + 2`` units), and the interior
    windows of +-(w + 1) from actuators of ``n_units``: together they show every key of the
    three terms.

    >>> designs = far_designs(15, 2)
    >>> [len(d) for d in designs].count(4), len(designs) - 8
    (8, 8)
    """
    n, w = int(n_units), int(window)
    interior = [d for d in covering_designs(n, w + 1, mirror, seed, short=True) if len(d) == n]
    return end_designs(w, mirror, units=end_units(w)) + interior


def end_units(w: int) -> int:
    """The units of the end designs of a table of window +-w with far-field terms: ``2w``, and ``w + 2`` for
    ``w = 1`` (the last chord's far-field term on the base side reads ``w + 2`` units)."""
    return max(2 * w, w + 2)


def fit_text(w: int, far: bool | str) -> str:
    """``window +-2 with far-field terms (+-3)``, ``window +-3 from 4-unit terms`` or ``window +-3``.

    >>> fit_text(2, "split")
    'window +-3 from 4-unit terms'
    """
    layout = term_layout(far)
    if layout == "split":
        return f"window +-{w + 1} from {2 * w}-unit terms"
    return f"window +-{w} with far-field terms (+-{w + 1})" if layout else f"window +-{w}"


def chord_values(response: Response) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """What a table averages per chord of ``response``, the levels side by side, and how it turns over.

    Returns
    -------
    values : ndarray, shape (n + 1, 2 k), or (n + 1, 8 k) for a chain in space
        The turns, the lengths, and a full-width response's six elements in space per level
        (:func:`~pneumorph.models.chain.space.space_rows`).
    signs : ndarray, shape (2 k,) or (8 k,)
        What ``values`` are multiplied by when every unit is turned over: the turns change sign,
        the lengths do not, the elements in space take
        :data:`~pneumorph.models.chain.space.MIRROR_SIGNS`.
    end : ndarray, shape (k,), or (4 k,) with the end face's frame
        The end turn, and for a full-width response that keeps the end face's frame, its turn
        from the last unit's frame per level (:func:`~pneumorph.models.chain.space.end_turns`).
    end_signs : ndarray, shape like ``end``
        Turned over, the end turn changes sign and the end face's turn takes the turn's signs
        of :data:`~pneumorph.models.chain.space.MIRROR_SIGNS`.
    """
    turn, length, end = response_elements(response)
    space = space_rows(response)
    k = len(end)
    signs = np.concatenate([-np.ones(k), np.ones(k), *[np.tile(MIRROR_SIGNS, k) for _ in space]])
    face = end_turns(response) if space else None
    ends = [end] if face is None else [end, face.ravel()]
    end_signs = np.concatenate([-np.ones(k), *[np.tile(MIRROR_SIGNS[3:], k) for _ in ends[1:]]])
    return np.concatenate([turn.T, length.T, *space], axis=1), signs, np.concatenate(ends), end_signs


def chord_spread(deviation: FloatArray, levels: int) -> float:
    """The largest deviation from a fit of the chord values that tell a chain (:func:`chord_values`' columns):
    a chain in space's elements in space (its planar columns, the view of its projection, are not local), else all."""
    return float(np.abs(deviation[:, 2 * levels if deviation.shape[1] > 2 * levels else 0:]).max())


def term_codes(symbols: IntArray, width: int, lo: int, hi: int, radix: int) -> IntArray:
    """Codes of the units ``lo .. hi`` from the chord, from symbols of window +-``width``, (..., )."""
    cols = np.arange(lo + width, hi + width + 1)
    return symbols[..., cols] @ (radix ** np.arange(len(cols), dtype=np.int64))


def symbols_of(design: str, width: int, mirror: bool, alphabet: tuple[str, ...],
             symmetric: tuple[int, ...]) -> list[tuple[IntArray, float]]:
    """A design's window symbols of +-``width`` at every chord (and, with ``mirror``, its mirror's), each with the
    sign its turns take (-1 mirrored)."""
    k = max(1, len(alphabet))
    sym = window_symbols(design_array(design, alphabet=alphabet, symmetric=symmetric), width, n_types=k)[0]
    return [(sym, 1.0)] + ([(mirror_symbols(sym, k, symmetric), -1.0)] if mirror else [])


def _observations(responses: Sequence[Response], width: int, mirror: bool, alphabet: tuple[str, ...],
                  symmetric: tuple[int, ...]) -> tuple[IntArray, FloatArray, IntArray, FloatArray]:
    """Symbols of window +-``width`` and elements of every chord (and end), mirrored too.

    Returns chord symbols (N, 2 width + 1), chord values (N, 2 k: turns then lengths; for a
    chain in space, then the six elements in space per level: 8 k), end symbols
    (M, 2 width + 1) and end turns (M, k).
    """
    syms, values, esyms, ends = [], [], [], []
    for r in responses:
        chords, signs, end, end_signs = chord_values(r)
        for s, sign in symbols_of(r.orientation, width, mirror, alphabet, symmetric):
            syms.append(s)
            values.append(chords if sign > 0 else chords * signs)
            esyms.append(s[-1:])
            ends.append((end if sign > 0 else end * end_signs)[None, :])
    return np.concatenate(syms), np.concatenate(values), np.concatenate(esyms), np.concatenate(ends)


def check_far_training(designs: Sequence[str], window: int, mirror: bool, alphabet: tuple[str, ...],
                       symmetric: tuple[int, ...], n_units: int, layout: bool | str = "far") -> None:
    """Refuse, before any solve, training designs that leave a key of a far-field term unseen.

    The keys the designs show (mirrored too) against those an actuator of ``n_units`` units
    needs, as :func:`compile_terms` looks them up after the fit.

    Raises
    ------
    ChainTableError
        Naming a window whose term no training design shows.

    Examples
    --------
    >>> check_far_training(far_designs(9, 1), 1, True, (), (), 9)
    >>> check_far_training([d for d in far_designs(9, 1) if len(d) == 9], 1, True, (), (), 9)
    Traceback (most recent call last):
    ...
    pneumorph.errors.ChainTableError: the training designs show no end of units -2 .. +0 like window [1, 0, 0, 3,
    3]; train on far_designs()
    """
    k = max(1, len(alphabet))
    width, radix = int(window) + 1, 2 * k + 2
    syms = [sym for d in designs for sym, _ in symbols_of(d, width, mirror, alphabet, symmetric)]
    chord = np.concatenate(syms)
    end = np.concatenate([s[-1:] for s in syms])

    def seen(symbols: IntArray, terms: tuple[tuple[int, int], ...]) -> list[tuple[IntArray, FloatArray]]:
        keys = [np.unique(term_codes(symbols, width, lo, hi, radix)) for lo, hi in terms]
        return [(u, np.zeros((len(u), 1))) for u in keys]

    layout = term_layout(layout)
    compile_terms({"window": int(window), "layout": layout, "chord": seen(chord, far_terms(window, layout)),
                   "end": seen(end, end_terms(window, layout))}, n_units, k, symmetric, 1)


def _backfit(keys: list[IntArray], values: FloatArray) -> tuple[list[tuple[IntArray, FloatArray]], FloatArray]:
    """Additive terms, one per key array, fitted by backfitting; returns each term's (sorted keys, values) and the
    fit."""
    parts = [np.zeros_like(values) for _ in keys]
    groups = [np.unique(k, return_inverse=True) for k in keys]
    tables: list[tuple[IntArray, FloatArray]] = []
    for _ in range(ROUNDS if len(keys) > 1 else 1):
        moved = 0.0
        tables = []
        for t, (uniq, inv) in enumerate(groups):
            rest = values - sum(p for s, p in enumerate(parts) if s != t)
            sums = np.zeros((len(uniq), values.shape[1]))
            np.add.at(sums, inv, rest)
            means = sums / np.bincount(inv)[:, None]
            new = means[inv]
            moved = max(moved, float(np.abs(new - parts[t]).max()))
            parts[t] = new
            tables.append((uniq, means))
        if moved <= SETTLED:
            break
    return tables, np.sum(parts, axis=0)


def _compile(tables: list[tuple[IntArray, FloatArray]], terms: Sequence[tuple[int, int]], symbols: IntArray,
             width: int, radix: int, what: str) -> FloatArray:
    """The sum of the terms at every window of ``symbols``; a :class:`ChainTableError` for a key never trained."""
    total = np.zeros((len(symbols), tables[0][1].shape[1]))
    for (keys, means), (lo, hi) in zip(tables, terms, strict=True):
        codes = term_codes(symbols, width, lo, hi, radix)
        rows = np.minimum(np.searchsorted(keys, codes), len(keys) - 1)
        missing = np.flatnonzero(keys[rows] != codes)
        if missing.size:
            raise ChainTableError(f"the training designs show no {what} of units {lo:+d} .. {hi:+d} like window "
                                  f"{symbols[missing[0]].tolist()}; train on far_designs()")
        total += means[rows]
    return total


def fit_terms(responses: Sequence[Response], window: int, mirror: bool, alphabet: tuple[str, ...],
              symmetric: tuple[int, ...], layout: bool | str = "far") -> tuple[dict[str, Any], float]:
    """The far-field terms of a window +-w table, fitted by backfitting, and the fit's spread.

    Returns
    -------
    terms : dict
        ``window`` (w) and, for the chords (``chord``) and the last chords' end turns
        (``end``), one ``(keys, values)`` pair per term of :func:`far_terms`: sorted codes of
        the term's units (radix ``2k + 2``, the first unit least significant) and its values
        (chords: turns then lengths per level; ends: turns).
    spread : float
        The largest deviation of the fit from a training chord or end.
    """
    w = int(window)
    width, radix = w + 1, 2 * max(1, len(alphabet)) + 2
    syms, values, esyms, ends = _observations(responses, width, mirror, alphabet, symmetric)
    layout = term_layout(layout)
    tables, fit = _backfit([term_codes(syms, width, lo, hi, radix) for lo, hi in far_terms(w, layout)], values)
    etables, efit = _backfit([term_codes(esyms, width, lo, hi, radix) for lo, hi in end_terms(w, layout)], ends)
    levels = responses[0].n_levels
    spread = chord_spread(values - fit, levels)
    if values.shape[1] == 2 * levels:  # a planar chain: its end turns tell it too
        spread = max(spread, float(np.abs(ends - efit).max()))
    elif ends.shape[1] > levels:  # a chain in space: its end face's turns
        spread = max(spread, float(np.abs((ends - efit)[:, levels:]).max()))
    return {"window": w, "layout": layout, "chord": tables, "end": etables}, spread


def written_windows(n_units: int, width: int, n_types: int, symmetric: tuple[int, ...]) -> IntArray:
    """The symbols (rows) of every window of +-``width`` that an actuator of at least ``2 width + 1`` units (and of
    ``n_units``) shows, canonical under mirroring, in the order of their codes: the windows a table writes out.

    >>> written_windows(5, 1, 1, ()).shape
    (18, 3)
    """
    radix = 2 * int(n_types) + 2
    codes = possible_codes(max(int(n_units), 2 * width + 1), width, n_types)
    windows = (codes[:, None] // radix ** np.arange(2 * width + 1, dtype=np.int64)) % radix
    return windows[np.all(np.asarray(canonical_codes(windows, symmetric)) == windows, axis=1)]


def compile_terms(terms: dict[str, Any], n_units: int, n_types: int, symmetric: tuple[int, ...],
                  levels: int) -> dict[str, Any]:
    """The table of window +-(w + 1) that far-field ``terms`` (:func:`fit_terms`) write out.

    One entry for every window an actuator of at least ``2w + 3`` units shows (any such length
    shows the same ones), canonical under mirroring; ``codes``, ``turn``, ``length``,
    ``end_codes`` and ``end`` as :class:`~pneumorph.models.chain.table.ChainTable` holds them.

    Raises
    ------
    ChainTableError
        A key of a term that no training design shows.
    """
    w, layout = int(terms["window"]), terms.get("layout", "far")
    width, radix = w + 1, 2 * n_types + 2
    windows = written_windows(n_units, width, n_types, symmetric)
    codes = windows @ radix ** np.arange(2 * width + 1, dtype=np.int64)
    chord = _compile(terms["chord"], far_terms(w, layout), windows, width, radix, "chord")
    # the windows of a last chord n: units n - w - 1 .. n (or the base), then w + 1 tip symbols
    last = np.all(windows[:, width + 1:] == radix - 1, axis=1) & (windows[:, width] < radix - 2)
    end = _compile(terms["end"], end_terms(w, layout), windows[last], width, radix, "end")
    out = {"codes": codes, "turn": chord[:, :levels], "length": chord[:, levels:2 * levels], "end_codes": codes[last],
           "end": end[:, :levels]}
    if chord.shape[1] > 2 * levels:  # a chain in space: its elements per level after the planar ones
        out["space"] = chord[:, 2 * levels:].reshape(len(codes), levels, 6)
    if end.shape[1] > levels:  # and the end face's turns
        out["end_space"] = end[:, levels:].reshape(len(end), levels, 3)
    return out


def far_means(responses: Sequence[Response], window: int, mirror: bool, alphabet: tuple[str, ...],
              symmetric: tuple[int, ...], levels: int, n_units: int, layout: bool | str = "far") -> dict[str, Any]:
    """:func:`~pneumorph.models.chain.fit.fit_table`'s entries of a window +-w table with far-field terms.

    Fitted at window +-w (:func:`fit_terms`) and written out at window +-(w + 1)
    (:func:`compile_terms`).

    Returns
    -------
    dict
        ``codes``, ``turn``, ``length``, ``end_codes``, ``end`` (window +-(w + 1)), ``spread``
        (the largest deviation of the fit from a training chord) and ``terms`` (the fitted
        terms, which the table's file holds instead of the windows).

    Raises
    ------
    ChainTableError
        A key of a term that no training design shows.
    """
    terms, spread = fit_terms(responses, window, mirror, alphabet, symmetric, layout)
    table = compile_terms(terms, n_units, max(1, len(alphabet)), symmetric, levels)
    return {**table, "spread": spread, "terms": {**terms, "digest": entries_digest(table), "n_units": int(n_units)}}


def entries_digest(entries: dict[str, Any]) -> str:
    """A hash of a table's entries (``codes``, ``turn``, ``length``, ``end_codes``, ``end``): whether terms still
    write out the table that holds them."""
    h = hashlib.sha256()
    for key in ("codes", "turn", "length", "end_codes", "end"):
        h.update(np.ascontiguousarray(entries[key]).tobytes())
    for key in ("space", "end_space"):  # a chain in space, with the end face's turns
        if len(entries.get(key, ())):
            h.update(np.ascontiguousarray(entries[key]).tobytes())
    return h.hexdigest()[:16]


def terms_to_dict(terms: dict[str, Any]) -> dict[str, Any]:
    """JSON-ready form of :func:`fit_terms`'s terms (with their ``digest`` and ``n_units``)."""
    w, layout = int(terms["window"]), terms.get("layout", "far")
    offsets = {"chord": far_terms(w, layout), "end": end_terms(w, layout)}
    return {"window": w, **({"layout": layout} if layout != "far" else {}), "n_units": int(terms["n_units"]),
            "digest": terms["digest"],
            **{part: [{"units": list(units), "keys": keys.tolist(), "values": values.tolist()}
                      for (keys, values), units in zip(terms[part], offsets[part], strict=True)]
               for part in ("chord", "end")}}


def terms_from_dict(data: dict[str, Any]) -> dict[str, Any]:
    """:func:`terms_to_dict`'s form back as arrays; a :class:`ChainTableError` if the terms are not those of
    :func:`far_terms`."""
    w, layout = int(data["window"]), term_layout(data.get("layout", "far"))
    out: dict[str, Any] = {"window": w, "layout": layout, "n_units": int(data["n_units"]),
                           "digest": str(data["digest"])}
    offsets = {"chord": far_terms(w, layout), "end": end_terms(w, layout)}
    for part in ("chord", "end"):
        if [tuple(t["units"]) for t in data[part]] != list(offsets[part]):
            raise ChainTableError(f"far-field terms of units {[t['units'] for t in data[part]]}, not those of "
                                  f"window +-{w}")
        out[part] = [(np.asarray(t["keys"], dtype=np.int64), np.asarray(t["values"], dtype=float))
                     for t in data[part]]
        if any(len(k) != len(v) or np.any(np.diff(k) <= 0) for k, v in out[part]):
            raise ChainTableError("far-field terms: keys not sorted or not one per value")
    return out


__all__ = ["LAYOUTS", "ROUNDS", "SETTLED", "chord_spread", "chord_values", "compile_terms", "end_terms",
           "end_units", "entries_digest", "far_designs", "far_means", "far_terms", "fit_terms", "fit_text",
           "symbols_of", "term_codes", "term_layout", "terms_from_dict", "terms_to_dict",
           "written_windows"]

"""The chain table's file layouts: its format numbers and the reading of its unit types and entries.

:class:`~pneumorph.models.chain.table.ChainTable` writes and reads its JSON file
(``to_dict``, ``from_dict``); the layouts differ by what the table holds: one unit type
(:data:`TABLE_FORMAT`), several (:data:`ALPHABET_FORMAT`), far-field terms instead of windows
(:data:`TERMS_FORMAT`), and a chain in space (:data:`SPACE_FORMAT`, any of the others plus its
elements in space).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import ChainTableError
from pneumorph.models.chain.terms import compile_terms, terms_from_dict
from pneumorph.models.chain.windows import window_code

IntArray = NDArray[np.int64]

#: format of the table file (bumped when its layout changes); a table over several unit types
#: is written in :data:`ALPHABET_FORMAT` (older readers refuse it instead of misreading it)
TABLE_FORMAT = 1

ALPHABET_FORMAT = 2

#: a table with far-field terms whose file holds the terms, not the windows they write out
TERMS_FORMAT = 3

#: a chain in space (:attr:`ChainTable.space`): any of the layouts above plus its elements in space
SPACE_FORMAT = 4


def types_of(data: dict[str, Any], fmt: Any, where: str) -> tuple[tuple[str, ...], tuple[str, ...], dict[str, Any]]:
    """The alphabet, the symmetric types and the per-type geometry of a table file (empty for one unit type)."""
    if not (fmt == ALPHABET_FORMAT or (fmt == TERMS_FORMAT and "alphabet" in data)):
        return (), (), {}
    from pneumorph.geometry.library import check_symbol

    alphabet = tuple(check_symbol(a, where) for a in data["alphabet"])
    if len(alphabet) < 2 or len(set(alphabet)) != len(alphabet):
        raise ChainTableError(f"{where}: a table over unit types needs two or more distinct symbols, "
                              f"got {list(alphabet)}")
    types = data["types"]
    symmetric = tuple(check_symbol(a, where) for a in data.get("symmetric", []))
    geometry = {
        "type_pitch": tuple(float(types[a]["pitch_mm"]) for a in alphabet),
        "type_offset": tuple(float(types[a]["centre_offset_mm"]) for a in alphabet),
        "type_centre_y": tuple(float(y) for a in alphabet for y in types[a]["centre_y_mm"][:2]),
    }
    return alphabet, symmetric, geometry


def entries_of(data: dict[str, Any], fmt: Any, w: int, alphabet: tuple[str, ...], symmetric: tuple[str, ...],
                levels: int, where: str, space: bool = False) -> dict[str, Any]:
    """A table file's entries (``codes`` .. ``end``, and ``space`` for a chain in space), from its windows or written
    out from its far-field terms (then with ``terms``)."""
    if fmt == TERMS_FORMAT:
        terms = terms_from_dict(data["terms"])
        if int(terms["window"]) + 1 != w:
            raise ChainTableError(f"far-field terms of window +-{terms['window']} in a table of +-{w}")
        sym = tuple(alphabet.index(s) for s in symmetric)
        entries = compile_terms(terms, terms["n_units"], max(1, len(alphabet)), sym, levels)
        if space != ("space" in entries):
            raise ChainTableError(f"{where}: far-field terms {'without' if space else 'with'} elements in space")
        return {**entries, "terms": terms}

    def codes_of(texts: list[str]) -> IntArray:
        out = []
        for t in texts:
            if not isinstance(t, str) or len(t) != 2 * w + 1:
                raise ChainTableError(f"{where}: bad window {t!r}")
            out.append(window_code(t, alphabet))
        return np.array(out, dtype=np.int64)

    out = {"codes": codes_of(data["windows"]), "turn": np.array(data["turn_rad"], dtype=float),
           "length": np.array(data["length_mm"], dtype=float), "end_codes": codes_of(data["end_windows"]),
           "end": np.array(data["end_turn_rad"], dtype=float)}
    if space:
        out["space"] = np.concatenate([np.array(data["space_chord_mm"], dtype=float),
                                       np.array(data["space_turn_rad"], dtype=float)], axis=-1)
        if "space_end_turn_rad" in data:  # the end face's turns (tables fitted before them have none)
            out["end_space"] = np.array(data["space_end_turn_rad"], dtype=float)
    return out


def check_entries(table: Any, where: str) -> None:
    """Refuse a table read from a file whose arrays do not fit together (shapes, window order, finite values).

    Raises
    ------
    ChainTableError
        Naming ``where`` and what is damaged.
    """
    k, K, E = table.n_levels, len(table.codes), len(table.end_codes)
    shapes_ok = (table.turn.shape == (K, k) and table.length.shape == (K, k) and table.end.shape == (E, k))
    if not shapes_ok or not (np.all(np.diff(table.codes) > 0) and np.all(np.diff(table.end_codes) > 0)):
        raise ChainTableError(f"{where}: damaged chain table (array shapes or window order do not match)")
    if set(table.symmetric) - set(table.alphabet):
        raise ChainTableError(f"{where}: symmetric unit types {list(table.symmetric)} outside the alphabet")
    if table.alphabet and len(table.type_centre_y) != 2 * len(table.alphabet):
        raise ChainTableError(f"{where}: damaged chain table (a centre height per type and orientation)")
    if (len(table.space) and table.space.shape != (K, k, 6)) or (
            len(table.end_space) and (table.end_space.shape != (E, k, 3) or not len(table.space))):
        raise ChainTableError(f"{where}: damaged chain table (elements in space of another shape)")
    if not all(np.isfinite(a).all() for a in (table.turn, table.length, table.end, table.pressures, table.space,
                                              table.end_space)):
        raise ChainTableError(f"{where}: damaged chain table (non-finite entries)")


__all__ = ["ALPHABET_FORMAT", "SPACE_FORMAT", "TABLE_FORMAT", "TERMS_FORMAT", "check_entries", "entries_of", "types_of"]

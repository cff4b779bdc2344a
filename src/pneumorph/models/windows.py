"""Windows of an actuator design and covering sets of designs, for the chain model.

A design is a row of 0/1 unit orientations. Element ``j`` of the chain model (chord ``j``,
which starts at point ``j``: the base for ``j = 0``, the centre of unit ``j`` otherwise)
sees the *window* of units ``j - w .. j + w`` (1-based); positions before the first unit
read as the base symbol ``B`` (2), after the last as the tip symbol ``T`` (3). A window is
stored as one integer, base 4, first unit least significant. Exchanging 0 and 1 mirrors a
window (:func:`mirror_codes`). A *covering set* is a small set of designs in which every
window of an actuator occurs (:func:`covering_designs`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import ChainTableError
from pneumorph.geometry.orientation import parse_orientation

IntArray = NDArray[np.int64]

#: symbols of a window besides the two orientations: the base and the tip
BASE, TIP = 2, 3


def design_array(designs: Sequence[str] | str, n_units: int | None = None) -> NDArray[np.uint8]:
    """Designs as a (m, n) array of 0/1 (one row per design).

    >>> design_array(["010", "110"]).tolist()
    [[0, 1, 0], [1, 1, 0]]
    """
    if isinstance(designs, str):
        designs = [designs]
    rows = [parse_orientation(d, n_units) for d in designs]
    if not rows:
        return np.zeros((0, n_units or 0), dtype=np.uint8)
    n = len(rows[0])
    if any(len(r) != n for r in rows):
        raise ChainTableError("designs of different lengths cannot be scored together")
    return (np.frombuffer("".join(rows).encode(), dtype=np.uint8) - ord("0")).reshape(len(rows), n)


def design_numbers(bits: NDArray[np.integer]) -> IntArray:
    """Each design (a row of 0/1, base first) as the integer its digits spell, base most significant.

    >>> design_numbers(np.array([[0, 1, 1], [1, 0, 0]])).tolist()
    [3, 4]
    """
    bits = np.atleast_2d(np.asarray(bits))
    n = bits.shape[1]
    return bits.astype(np.int64) @ (np.int64(1) << np.arange(n - 1, -1, -1, dtype=np.int64))


def design_strings(bits: NDArray[np.integer]) -> list[str]:
    """The inverse of :func:`design_array`.

    >>> design_strings(np.array([[0, 1, 1]]))
    ['011']
    """
    bits = np.asarray(bits, dtype=np.uint8)
    if bits.ndim == 1:
        bits = bits[None]
    text = (bits + ord("0")).astype(np.uint8).tobytes().decode()
    n = bits.shape[1]
    return [text[i * n : (i + 1) * n] for i in range(bits.shape[0])]


def window_symbols(bits: NDArray[np.integer], window: int, chords: Sequence[int] | None = None) -> NDArray[np.int64]:
    """The windows of the elements (chords) of every design, shape (m, chords, 2w + 1).

    Element ``j`` sees the units ``j - w .. j + w`` (1-based); outside the actuator the
    base symbol 2 and the tip symbol 3 stand in. ``chords`` picks elements (default all
    ``n + 1``); for the first ``p`` units of longer designs, the elements ``j <= p - w``
    are those of the whole designs.

    >>> window_symbols(np.array([[0, 1]]), 1)[0].tolist()
    [[2, 2, 0], [2, 0, 1], [0, 1, 3]]
    """
    bits = np.asarray(bits)
    n = bits.shape[1]
    w = int(window)
    elements = np.arange(n + 1) if chords is None else np.asarray(chords, dtype=np.int64)
    # element j (0..n) sees units j - w .. j + w (1-based), i.e. columns j - w - 1 .. j + w - 1 of bits
    units = elements[:, None] + np.arange(-w - 1, w)[None, :]
    lo, hi = int(units.min()), int(units.max())
    span = np.arange(lo, hi + 1)
    seen = bits[:, np.clip(span, 0, n - 1)].astype(np.int64)  # only the columns the elements see
    seen[:, span < 0] = BASE
    seen[:, span >= n] = TIP
    return seen[:, units - lo]


def window_codes(bits: NDArray[np.integer], window: int, chords: Sequence[int] | None = None) -> IntArray:
    """Integer codes (base 4, first unit least significant) of the elements' windows, (m, chords).

    ``chords`` as for :func:`window_symbols`.
    """
    sym = window_symbols(bits, window, chords)
    weights = 4 ** np.arange(sym.shape[-1], dtype=np.int64)
    return sym @ weights


def mirror_codes(codes: IntArray, window: int) -> IntArray:
    """Codes of the mirrored windows (0 and 1 exchanged; base and tip kept)."""
    codes = np.asarray(codes, dtype=np.int64)
    out = np.zeros_like(codes)
    for t in range(2 * window + 1):
        s = (codes // 4**t) % 4
        s = np.where(s < 2, 1 - s, s)
        out += s * 4**t
    return out


def window_text(code: int, window: int) -> str:
    """A window code as text, e.g. ``'BB01'``.

    >>> window_text(int(window_codes(np.array([[0, 1]]), 1)[0, 0]), 1)
    'BB0'
    """
    return "".join("01BT"[(int(code) // 4**t) % 4] for t in range(2 * window + 1))


def possible_codes(n_units: int, window: int) -> IntArray:
    """Every window code that occurs in some design of ``n_units`` units, sorted."""
    n, w = int(n_units), int(window)
    width = 2 * w + 1
    found: set[int] = set()
    for j in range(n + 1):
        units = [j - w + t for t in range(width)]  # 1-based unit numbers
        inside = [t for t, u in enumerate(units) if 1 <= u <= n]
        fixed = sum((BASE if u < 1 else TIP) * 4**t for t, u in enumerate(units) if not 1 <= u <= n)
        for k in range(2 ** len(inside)):
            found.add(fixed + sum(((k >> i) & 1) * 4**t for i, t in enumerate(inside)))
    return np.array(sorted(found), dtype=np.int64)


def covering_designs(n_units: int, window: int, mirror: bool = True, seed: int = 0) -> list[str]:
    """A small set of designs in which every window of ``n_units`` units occurs.

    Greedy set cover: each pick is the design that shows the most windows not yet seen
    (counting a window's mirror as seen when ``mirror``); ties go to the first design of a
    seeded random pool, so the set is reproducible.

    Parameters
    ----------
    n_units : int
        Units of the training designs.
    window : int
        Half-width ``w`` of the windows.
    mirror : bool
        A design also teaches its mirror's windows (valid for a mirror-symmetric model).
    seed : int
        Seed of the candidate pool (all designs up to 16 units, else 20,000 random ones).

    Examples
    --------
    >>> designs = covering_designs(6, 1)
    >>> len(designs)
    2
    """
    n, w = int(n_units), int(window)
    if n < 1 or w < 0:
        raise ChainTableError(f"a covering set needs at least 1 unit and a window >= 0, got {n} and {w}")
    rng = np.random.default_rng(seed)
    if n <= 16:
        pool = ((np.arange(2**n)[:, None] >> np.arange(n)[None, ::-1]) & 1).astype(np.uint8)
        pool = pool[rng.permutation(len(pool))]
    else:
        pool = rng.integers(0, 2, size=(20000, n), dtype=np.uint8)
    codes = window_codes(pool, w)
    canon = np.minimum(codes, mirror_codes(codes, w)) if mirror else codes
    needed = np.unique(canon)
    index = np.searchsorted(needed, canon)
    seen = np.zeros(len(needed), dtype=bool)
    chosen: list[int] = []
    while not seen.all():
        counts = _distinct_counts(index, ~seen[index], len(needed))
        best = int(np.argmax(counts))
        if counts[best] == 0:  # pragma: no cover - a random pool that misses a window
            raise ChainTableError(f"no design of the pool shows the remaining windows of {n} units")
        chosen.append(best)
        seen[index[best]] = True
    return design_strings(pool[chosen])


def _distinct_counts(index: IntArray, new: NDArray[np.bool_], n_keys: int) -> IntArray:
    """Per row, the number of distinct values of ``index`` where ``new`` is set."""
    rows = np.repeat(np.arange(index.shape[0]), index.shape[1])
    flat = rows * n_keys + index.ravel()
    mask = new.ravel()
    unique = np.unique(flat[mask])
    return np.bincount(unique // n_keys, minlength=index.shape[0])

"""Windows of an actuator design and covering sets of designs, for the chain model.

A design is a row of unit codes. For one unit type (the built-in unit's actuators) the codes are the
0/1 orientations. Over a unit library of ``k`` types (an *alphabet*, the types' symbols in
the library's order, :mod:`pneumorph.geometry.alphabet`) unit type ``t`` in orientation
``o`` is code ``2 t + o``: ``a`` 0, ``A`` 1, ``e`` 2, ``E`` 3, ... (so a one-type design's
codes are its 0/1 digits). Element ``j`` of the chain model (chord ``j``, which starts at
point ``j``: the base for ``j = 0``, the centre of unit ``j`` otherwise) sees the *window*
of units ``j - w .. j + w`` (1-based); positions before the first unit read as the base
symbol ``B`` (code ``2k``), after the last as the tip symbol ``T`` (``2k + 1``). A window is
stored as one integer in base ``2k + 2``, first unit least significant: base 4 with ``B`` = 2
and ``T`` = 3 for one type, as always. Turning every unit over (``2t <-> 2t + 1``) mirrors a
window (:func:`mirror_codes`). A *covering set* is a small set of designs in which every
window of an actuator occurs (:func:`covering_designs`).

Examples
--------
>>> codes = design_array(["aEr", "AAs"], alphabet=("a", "e", "r", "s"))
>>> codes.tolist(), design_strings(codes, ("a", "e", "r", "s"))
([[0, 3, 4], [1, 1, 6]], ['aEr', 'AAs'])
>>> window_text(int(window_codes(codes[:1], 1, n_types=4)[0, 0]), 1, ("a", "e", "r", "s"))
'<<a'
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import ChainTableError
from pneumorph.geometry.orientation import parse_orientation

IntArray = NDArray[np.int64]

#: symbols of a window besides the two orientations of one unit type: the base and the tip
BASE, TIP = 2, 3
#: characters of the base and the tip in the window text of a table over several unit types
#: (``B`` and ``T`` would read as units ``b`` and ``t`` turned over)
BASE_CHAR, TIP_CHAR = "<", ">"


def ends(n_types: int = 1) -> tuple[int, int]:
    """The codes of the base and the tip symbols for ``n_types`` unit types: ``2k`` and ``2k + 1``.

    >>> ends(), ends(4)
    ((2, 3), (8, 9))
    """
    return 2 * int(n_types), 2 * int(n_types) + 1


def unit_codes(n_types: int = 1, symmetric: Sequence[int] = ()) -> NDArray[np.uint8]:
    """The unit codes a design may hold: ``2t + o``, one code (``2t``) for a symmetric type ``t``.

    A type whose unit turned over is the same body (``symmetric``: type indices) has one
    orientation, written in lower case.

    >>> unit_codes(2).tolist(), unit_codes(4, symmetric=(1,)).tolist()
    ([0, 1, 2, 3], [0, 1, 2, 4, 5, 6, 7])
    """
    sym = set(int(t) for t in symmetric)
    return np.array([c for c in range(2 * int(n_types)) if not (c % 2 and c // 2 in sym)], dtype=np.uint8)


def canonical_codes(codes: NDArray[np.integer], symmetric: Sequence[int] = ()) -> NDArray[np.integer]:
    """Unit codes with every turned-over symmetric unit (``2t + 1``, ``t`` in ``symmetric``) written as ``2t``.

    Base and tip symbols (``2k``, ``2k + 1``) and the codes of other types are kept.

    >>> canonical_codes(np.array([[0, 3, 1, 2]]), symmetric=(1,)).tolist()
    [[0, 2, 1, 2]]
    """
    if not len(symmetric):
        return codes
    codes = np.asarray(codes)
    flip = np.isin(codes // 2, np.asarray(symmetric, dtype=np.int64)) & (codes % 2 == 1)
    return np.where(flip, codes - 1, codes).astype(codes.dtype)


def symbol_chars(alphabet: Sequence[str] = ()) -> str:
    """The character of every window symbol, by code: ``"01BT"`` for one type, else ``"aAeE...<>"``.

    >>> symbol_chars(), symbol_chars(("a", "r"))
    ('01BT', 'aArR<>')
    """
    if len(alphabet) <= 1:
        return "01BT"
    return "".join(s + s.upper() for s in alphabet) + BASE_CHAR + TIP_CHAR


def _parse_alphabet(design: str, alphabet: Sequence[str], n_units: int | None) -> str:
    """``design`` checked against the types of a table: the canonical letters (digits: the first type)."""
    from pneumorph.errors import OrientationError

    text = "".join(ch for ch in design if ch not in " ,_\t")
    bad = sorted({ch for ch in text if ch not in "01" and ch.lower() not in alphabet})
    if bad:
        letters = [b for b in bad if b.isalpha()]
        if letters:
            which = ", ".join(repr(b.lower()) for b in dict.fromkeys(letters))
            raise ChainTableError(
                f"unit type {which} has no table: the chain table covers the unit types "
                f"{', '.join(alphabet)} (design {design!r}); build a table over a library with "
                f"{'that type' if len(letters) == 1 else 'those types'} (`pneumorph chain build --library`)")
        raise OrientationError(f"design {design!r} contains {', '.join(repr(b) for b in bad)}; allowed: the unit "
                               f"types {', '.join(alphabet)} (upper case: turned over) and 0/1 for {alphabet[0]}")
    if not text:
        raise OrientationError("empty design: give one symbol per unit")
    if n_units is not None and len(text) != n_units:
        raise OrientationError(f"design {text!r} has {len(text)} units, expected {n_units}")
    first = alphabet[0]
    return "".join(first if ch == "0" else first.upper() if ch == "1" else ch for ch in text)


def design_array(designs: Sequence[str] | str, n_units: int | None = None,
                 alphabet: Sequence[str] = (), symmetric: Sequence[int] = ()) -> NDArray[np.uint8]:
    """Designs as a (m, n) array of unit codes (one row per design): 0/1 for one unit type.

    ``alphabet`` names the unit types of a table over several (module docstring); a design
    with a letter of another type raises a :class:`ChainTableError` ("unit type 'x' has no
    table"). The turned-over units of ``symmetric`` types (indices) are read as the unit itself.

    >>> design_array(["010", "110"]).tolist()
    [[0, 1, 0], [1, 1, 0]]
    >>> design_array("a1R", alphabet=("a", "r")).tolist()
    [[0, 1, 3]]
    >>> design_array("aEa", alphabet=("a", "r"))
    Traceback (most recent call last):
    ...
    pneumorph.errors.ChainTableError: unit type 'e' has no table: the chain table covers the unit types a, r
    (design 'aEa'); build a table over a library with that type (`pneumorph chain build --library`)
    """
    if isinstance(designs, str):
        designs = [designs]
    if len(alphabet) > 1:
        chars = symbol_chars(alphabet)
        texts = [_parse_alphabet(d, alphabet, n_units) for d in designs]
        if not texts:
            return np.zeros((0, n_units or 0), dtype=np.uint8)
        if any(len(t) != len(texts[0]) for t in texts):
            raise ChainTableError("designs of different lengths cannot be scored together")
        lookup = np.zeros(128, dtype=np.uint8)
        lookup[[ord(c) for c in chars[:-2]]] = np.arange(len(chars) - 2, dtype=np.uint8)
        out = lookup[np.frombuffer("".join(texts).encode(), dtype=np.uint8)].reshape(len(texts), -1)
        return np.asarray(canonical_codes(out, symmetric), dtype=np.uint8)
    for d in designs:
        if isinstance(d, str) and any(ch.isalpha() for ch in d):
            letters = sorted({ch.lower() for ch in d if ch.isalpha()})
            raise ChainTableError(
                f"unit type {', '.join(repr(x) for x in letters)} has no table: the chain table is of one unit "
                f"type, written 0/1 (design {d!r}); build a table over a library with "
                f"{'that type' if len(letters) == 1 else 'those types'} (`pneumorph chain build --library`)")
    rows = [parse_orientation(d, n_units) for d in designs]
    if not rows:
        return np.zeros((0, n_units or 0), dtype=np.uint8)
    n = len(rows[0])
    if any(len(r) != n for r in rows):
        raise ChainTableError("designs of different lengths cannot be scored together")
    return (np.frombuffer("".join(rows).encode(), dtype=np.uint8) - ord("0")).reshape(len(rows), n)


def design_numbers(bits: NDArray[np.integer], choices: int = 2) -> IntArray:
    """Each design (a row of unit codes, base first) as the integer its digits spell in base ``choices``.

    The base is most significant; ``choices`` is 2 for 0/1 designs, ``2k`` over ``k`` unit types.

    >>> design_numbers(np.array([[0, 1, 1], [1, 0, 0]])).tolist()
    [3, 4]
    >>> design_numbers(np.array([[0, 3, 1]]), choices=4).tolist()
    [13]
    """
    bits = np.atleast_2d(np.asarray(bits))
    n = bits.shape[1]
    if choices == 2:
        return bits.astype(np.int64) @ (np.int64(1) << np.arange(n - 1, -1, -1, dtype=np.int64))
    weights = np.array([int(choices) ** i for i in range(n - 1, -1, -1)], dtype=np.int64)
    return np.asarray(bits.astype(np.int64) @ weights, dtype=np.int64)


def design_strings(bits: NDArray[np.integer], alphabet: Sequence[str] = ()) -> list[str]:
    """The inverse of :func:`design_array`: canonical texts (letters for several unit types).

    >>> design_strings(np.array([[0, 1, 1]])), design_strings(np.array([[0, 3]]), ("a", "r"))
    (['011'], ['aR'])
    """
    bits = np.asarray(bits, dtype=np.uint8)
    if bits.ndim == 1:
        bits = bits[None]
    if len(alphabet) > 1:
        chars = np.frombuffer(symbol_chars(alphabet).encode(), dtype=np.uint8)
        text = chars[bits].astype(np.uint8).tobytes().decode()
    else:
        text = (bits + ord("0")).astype(np.uint8).tobytes().decode()
    n = bits.shape[1]
    return [text[i * n : (i + 1) * n] for i in range(bits.shape[0])]


def window_symbols(bits: NDArray[np.integer], window: int, chords: Sequence[int] | None = None,
                   n_types: int = 1) -> NDArray[np.int64]:
    """The windows of the elements (chords) of every design, shape (m, chords, 2w + 1).

    Element ``j`` sees the units ``j - w .. j + w`` (1-based); outside the actuator the
    base symbol (2, or ``2k`` for ``n_types = k``) and the tip symbol (3, ``2k + 1``) stand
    in. ``chords`` picks elements (default all ``n + 1``); for the first ``p`` units of
    longer designs, the elements ``j <= p - w`` are those of the whole designs.

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
    base, tip = ends(n_types)
    seen[:, span < 0] = base
    seen[:, span >= n] = tip
    return seen[:, units - lo]


def window_codes(bits: NDArray[np.integer], window: int, chords: Sequence[int] | None = None,
                 n_types: int = 1) -> IntArray:
    """Integer codes (base ``2k + 2``: 4 for one type; first unit least significant) of the windows, (m, chords).

    ``chords`` as for :func:`window_symbols`.
    """
    sym = window_symbols(bits, window, chords, n_types)
    weights = (2 * int(n_types) + 2) ** np.arange(sym.shape[-1], dtype=np.int64)
    return sym @ weights


def mirror_symbols(symbols: NDArray[np.integer], n_types: int = 1, symmetric: Sequence[int] = ()) -> IntArray:
    """Symbols with every unit turned over (``2t <-> 2t + 1``; base and tip kept; a ``symmetric`` type stays ``2t``).

    >>> mirror_symbols(np.array([2, 0, 1, 3])).tolist()
    [2, 1, 0, 3]
    """
    s = np.asarray(symbols, dtype=np.int64)
    return np.asarray(canonical_codes(np.where(s < 2 * int(n_types), s ^ 1, s), symmetric), dtype=np.int64)


def mirror_codes(codes: IntArray, window: int, n_types: int = 1, symmetric: Sequence[int] = ()) -> IntArray:
    """Codes of the mirrored windows (every unit turned over: ``2t <-> 2t + 1``; base and tip kept).

    A unit of a ``symmetric`` type turned over is itself (code ``2t``).
    """
    codes = np.asarray(codes, dtype=np.int64)
    radix = 2 * int(n_types) + 2
    out = np.zeros_like(codes)
    for t in range(2 * window + 1):
        out += mirror_symbols((codes // radix**t) % radix, n_types, symmetric) * radix**t
    return out


def window_text(code: int, window: int, alphabet: Sequence[str] = ()) -> str:
    """A window code as text, e.g. ``'BB01'`` (one unit type) or ``'<aE'`` (a table over ``alphabet``).

    >>> window_text(int(window_codes(np.array([[0, 1]]), 1)[0, 0]), 1)
    'BB0'
    """
    chars = symbol_chars(alphabet)
    radix = len(chars)
    return "".join(chars[(int(code) // radix**t) % radix] for t in range(2 * window + 1))


def window_code(text: str, alphabet: Sequence[str] = ()) -> int:
    """The inverse of :func:`window_text`; a :class:`ChainTableError` for a character of no symbol.

    >>> window_code("<aE", ("a", "e")), window_code("BB0")
    (112, 10)
    """
    chars = symbol_chars(alphabet)
    if set(text) - set(chars):
        raise ChainTableError(f"bad window {text!r}: its characters must be among {chars!r}")
    return sum(chars.index(ch) * len(chars) ** i for i, ch in enumerate(text))


def possible_codes(n_units: int, window: int, n_types: int = 1) -> IntArray:
    """Every window code that occurs in some design of ``n_units`` units, sorted.

    >>> possible_codes(3, 1).tolist()[:4]
    [0, 1, 2, 4]
    """
    n, w, k2 = int(n_units), int(window), 2 * int(n_types)
    radix = k2 + 2
    base, tip = ends(n_types)
    width = 2 * w + 1
    found, seen = [], set()
    for j in range(n + 1):
        units = np.arange(j - w, j - w + width)  # 1-based unit numbers
        pattern = tuple(np.sign(units - 1).clip(-1, 0) + (units > n))  # -1 base, 0 a unit, 1 tip: one set each
        if pattern in seen:
            continue
        seen.add(pattern)
        inside = np.flatnonzero((units >= 1) & (units <= n))
        outside = np.flatnonzero((units < 1) | (units > n))
        fixed = int(sum((base if units[t] < 1 else tip) * radix ** int(t) for t in outside))
        choice = np.arange(k2 ** len(inside), dtype=np.int64)
        digits = (choice[:, None] // k2 ** np.arange(len(inside), dtype=np.int64)) % k2
        found.append(fixed + digits @ (radix ** inside.astype(np.int64)))
    return np.unique(np.concatenate(found))


def random_designs(count: int, n_units: int, rng: np.random.Generator, n_types: int = 1,
                   symmetric: Sequence[int] = ()) -> NDArray[np.uint8]:
    """``count`` random designs of ``n_units`` unit codes (0/1 for one type, ``0 .. 2k - 1`` for ``k``).

    With ``symmetric`` types, each unit is one of :func:`unit_codes` (equally likely).
    """
    if len(symmetric):
        allowed = unit_codes(n_types, symmetric)
        return allowed[rng.integers(0, len(allowed), size=(count, n_units))]
    return rng.integers(0, 2 * int(n_types), size=(count, n_units), dtype=np.uint8)


#: greedy covers tried with seeded random ties after the first (ties to the first design); the smallest is kept
COVER_RESTARTS = 32
#: ... as many as fit in this work: a greedy cover's picks times the pool's designs times their windows
COVER_RESTART_WORK = 20_000_000


def covering_designs(n_units: int, window: int, mirror: bool = True, seed: int = 0, n_types: int = 1,
                     alphabet: Sequence[str] = (), symmetric: Sequence[int] = (), short: bool = False,
                     end_units: int | None = None) -> list[str]:
    """A small set of designs in which every window of ``n_units`` units occurs.

    Greedy set cover: each pick is the design that shows the most windows not yet seen
    (counting a window's mirror as seen when ``mirror``); ties go to the first design of a
    seeded random pool. Then up to :data:`COVER_RESTARTS` greedy covers with ties broken at
    random (seeded) are tried on small pools, and the first smallest is kept, so the set is
    reproducible: the 64 interior windows of window +-3 on 15 units (9 a design) take 8
    designs instead of the first greedy cover's 9.

    Parameters
    ----------
    n_units : int
        Units of the training designs.
    window : int
        Half-width ``w`` of the windows.
    mirror : bool
        A design also teaches its mirror's windows (valid for a mirror-symmetric model).
    seed : int
        Seed of the candidate pool (all designs up to 16 units, else 20,000 random ones; over
        ``k > 1`` types all designs up to 2^16 of them, else ``max(20000, 8 K / n)`` random
        ones for ``K`` windows).
    n_types : int
        Unit types ``k`` (codes ``0 .. 2k - 1`` per unit); 1: the 0/1 designs of one type.
    alphabet : sequence of str
        The types' symbols, for the designs' text (letters) when ``n_types > 1``.
    symmetric : sequence of int
        Types whose unit turned over is the same body: one orientation (:func:`unit_codes`).
    short : bool
        Cover the windows that hold the base or the tip with the designs of :func:`end_designs`
        (``2w`` units each, every end window of ``n_units`` units in one of them), and only the
        interior windows with designs of ``n_units`` units; first the short designs.
    end_units : int, optional
        With ``short``, the end designs' units instead of ``2w`` (far-field terms of ``w = 1``
        read ``w + 2`` units at an end).

    Examples
    --------
    >>> designs = covering_designs(6, 1)
    >>> len(designs)
    2
    >>> designs = covering_designs(6, 1, n_types=2, alphabet=("a", "r"))
    >>> len(designs) >= 8, designs[0]   # at least one design per base window "<<u1u2", up to the mirror
    (True, ...)
    >>> short = covering_designs(15, 3, short=True)
    >>> [len(d) for d in short].count(6), len(short) - 32   # 2^6 / 2 end designs, then 15-unit ones
    (32, 8)
    """
    n, w, k = int(n_units), int(window), int(n_types)
    if n < 1 or w < 0:
        raise ChainTableError(f"a covering set needs at least 1 unit and a window >= 0, got {n} and {w}")
    if k > 1 and len(alphabet) != k:
        raise ChainTableError(f"a covering set over {k} unit types needs their {k} symbols, got {alphabet!r}")
    rng = np.random.default_rng(seed)
    pool = design_pool(n, k, symmetric, rng, len(possible_codes(n, w, k)) if k > 1 else 0)
    ends_first: list[str] = []
    codes = window_codes(pool, w, n_types=k)
    if short and n > 2 * w:
        ends_first, codes = end_designs(w, mirror, k, alphabet, symmetric, units=end_units), codes[:, w + 1 : n - w + 1]
    canon = np.minimum(codes, mirror_codes(codes, w, k, symmetric)) if mirror else codes
    return ends_first + design_strings(pool[cover_rows(canon, rng)], alphabet if k > 1 else ())


def design_pool(n_units: int, n_types: int, symmetric: Sequence[int], rng: np.random.Generator,
                n_keys: int = 0) -> NDArray[np.uint8]:
    """The candidate designs of a covering set: every design up to 2^16 of them (shuffled), else random ones
    (20,000 of one type; over several, ``max(20000, 8 K / n)`` for ``K`` keys to cover)."""
    n, k = int(n_units), int(n_types)
    if len(allowed := unit_codes(k, symmetric)) ** n <= 2**16:
        pool = every_design(n, allowed)
        return pool[rng.permutation(len(pool))]
    if k == 1:
        return rng.integers(0, 2, size=(20000, n), dtype=np.uint8)
    return random_designs(max(20000, 8 * int(n_keys) // max(n, 1)), n, rng, k, symmetric)


def cover_rows(keys: IntArray, rng: np.random.Generator) -> list[int]:
    """The rows of a small set in which every key of ``keys`` (rows: candidate designs) occurs.

    Greedy set cover, then up to :data:`COVER_RESTARTS` greedy covers with seeded random
    ties, as many as :data:`COVER_RESTART_WORK` allows; the first smallest is kept.
    """
    needed = np.unique(keys)
    index = np.searchsorted(needed, keys)
    chosen = _greedy_cover(index, len(needed), None)
    restarts = min(COVER_RESTARTS, COVER_RESTART_WORK // (len(chosen) * index.size))
    fewest = _fewest_cover(index) if restarts else 0
    for _ in range(restarts):
        if len(chosen) <= fewest:
            break
        other = _greedy_cover(index, len(needed), rng)
        chosen = other if len(other) < len(chosen) else chosen
    return chosen


def _fewest_cover(index: IntArray) -> int:
    """A lower bound on any cover's size: the windows per design, and the windows only one chord shows."""
    n_keys = int(index.max()) + 1
    columns = np.zeros((n_keys, index.shape[1]), dtype=bool)
    columns[index, np.arange(index.shape[1])[None, :]] = True
    only = columns.sum(axis=1) == 1
    exclusive = max(int(np.count_nonzero(only & columns[:, c])) for c in range(index.shape[1]))
    return max(exclusive, -(-n_keys // index.shape[1]))


def _greedy_cover(index: IntArray, n_keys: int, rng: np.random.Generator | None) -> list[int]:
    """Greedy set cover of the keys by the rows of ``index``: ties to the first row, or to a random one of ``rng``."""
    seen = np.zeros(n_keys, dtype=bool)
    chosen: list[int] = []
    while not seen.all():
        counts = _distinct_counts(index, ~seen[index], n_keys)
        if counts.max() == 0:  # pragma: no cover - a random pool that misses a window
            raise ChainTableError("no design of the pool shows the remaining windows")
        ties = np.flatnonzero(counts == counts.max())
        best = int(ties[0] if rng is None else rng.choice(ties))
        chosen.append(best)
        seen[index[best]] = True
    return chosen


def every_design(n_units: int, codes: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Every design of ``n_units`` units over the unit ``codes``, counting up with the first unit most significant.

    >>> every_design(2, np.array([0, 1], dtype=np.uint8)).tolist()
    [[0, 0], [0, 1], [1, 0], [1, 1]]
    """
    c, n = len(codes), int(n_units)
    return np.asarray(codes, dtype=np.uint8)[np.arange(c**n)[:, None] // c ** np.arange(n - 1, -1, -1)[None, :] % c]


def end_designs(window: int, mirror: bool = True, n_types: int = 1, alphabet: Sequence[str] = (),
                symmetric: Sequence[int] = (), units: int | None = None) -> list[str]:
    """Designs of ``2w`` units (or ``units``) that together show every window holding the base or the tip.

    Chord ``w`` of a ``2w``-unit design sees the base and all its units, chord ``w + 1`` all its
    units and the tip; the chords before and after see fewer units. Every sequence of ``2w``
    unit codes (up to the mirror) therefore shows every end window of any longer actuator: by
    locality a window's element does not depend on what lies beyond it.

    >>> end_designs(1), len(end_designs(3))
    (['00', '01'], 32)
    """
    w, k = int(window), int(n_types)
    every = every_design(2 * w if units is None else int(units), unit_codes(k, symmetric))
    if mirror:
        flipped = np.asarray(canonical_codes(every ^ 1, symmetric))
        keys, mirrored = design_numbers(every, 2 * k), design_numbers(flipped, 2 * k)
        every = every[keys <= mirrored]
    return design_strings(every, alphabet if k > 1 else ())


def _distinct_counts(index: IntArray, new: NDArray[np.bool_], n_keys: int) -> IntArray:
    """Per row, the number of distinct values of ``index`` where ``new`` is set."""
    rows = np.repeat(np.arange(index.shape[0]), index.shape[1])
    flat = rows * n_keys + index.ravel()
    mask = new.ravel()
    unique = np.unique(flat[mask])
    return np.bincount(unique // n_keys, minlength=index.shape[0])

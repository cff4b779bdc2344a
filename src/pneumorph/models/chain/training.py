"""The training designs of a chain table: covering designs of its windows, or of its terms' keys.

A table of window +-w learns each window from the chords that show it, so a covering set (every
window in some training design, :func:`~pneumorph.models.chain.windows.covering_designs`) is all it
needs. A table of *terms* (:mod:`pneumorph.models.chain.terms`) sums several overlapping terms
per chord, and a covering set shows each term's key but not always enough chords to tell the
terms apart: the ``split`` layout's four terms of ``2w`` units hold four values per run of units,
and a chord's value is the sum of four of them. Its designs are therefore the cover of its keys,
then random designs (seeded) until the training chords fix the sum at *every* window the table
writes out. That is checked without a solve (:func:`unfixed_error`): a random additive truth is
fitted from the training chords (least squares, minimum norm) and compared with the truth at
every window; the difference is zero, to rounding, exactly when every window's sum is fixed.

Measured over the built-in library (``a``, ``e``, ``r``, ``s``; 2D, 30 kPa): the cover of the
split terms' keys alone (183 designs) leaves windows unfixed and predicts held-out designs
78 mm off; with 600 random designs more, 0.016 mm (docs/chain-model.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from scipy import sparse
from scipy.sparse.linalg import lsqr

from pneumorph.errors import LocalityError
from pneumorph.models.chain.terms import (
    end_terms,
    end_units,
    far_designs,
    far_terms,
    symbols_of,
    term_codes,
    term_layout,
    written_windows,
)
from pneumorph.models.chain.windows import (
    cover_rows,
    covering_designs,
    design_pool,
    design_strings,
    end_designs,
    mirror_symbols,
    random_designs,
    window_symbols,
)

IntArray = NDArray[np.int64]

#: the largest difference from the random truth (its values of order 1) that counts as a fixed sum
FIXED = 1e-6
#: random designs added at a time to a split cover, as a fraction of the cover (at least 8)
BATCH_FRACTION = 0.25
#: random designs at most added to a split cover, as a multiple of the cover
MAX_ADDED = 8


def training_designs(n: int, w: int, far: bool | str, short: bool, alphabet: tuple[str, ...] = (),
                     symmetric: tuple[int, ...] = ()) -> list[str]:
    """The covering designs of window +-w (:func:`~pneumorph.models.chain.windows.covering_designs`), or with
    far-field terms :func:`~pneumorph.models.chain.terms.far_designs` (one unit type; over several, the
    covering designs of +-w show every key of the far-field terms many times, and short end designs have
    ``max(2w, w + 2)`` units, as :func:`far_designs`'s: a far-field term at an end reads ``w + 2`` units),
    or with ``split`` terms :func:`split_designs`.

    >>> [len(d) for d in training_designs(7, 1, True, True, ("a", "r"))][:3]
    [3, 3, 3]
    """
    layout = term_layout(far)
    if layout == "split":
        return split_designs(n, w, alphabet, symmetric, short)
    if layout and not alphabet:
        return far_designs(n, w)
    return covering_designs(n, w, n_types=max(1, len(alphabet)), alphabet=alphabet, symmetric=symmetric, short=short,
                            end_units=end_units(w) if layout else None)


@lru_cache(maxsize=8)  # a build's plan and the build itself ask for the same designs
def split_designs(n_units: int, window: int, alphabet: tuple[str, ...] = (), symmetric: tuple[int, ...] = (),
                  short: bool = False, seed: int = 0) -> list[str]:
    """Training designs of a table of window +-w with ``split`` terms.

    First a cover of every key of its terms (mirrored too) by designs of ``n_units`` units
    (greedy set cover, :func:`~pneumorph.models.chain.windows.cover_rows`); with ``short``, every run
    of ``2w - 1`` units is one actuator (:func:`~pneumorph.models.chain.windows.end_designs`: it shows
    the keys at the base and at the tip) and the long designs cover the interior keys only.
    Then random designs of ``n_units`` units (seeded), in batches, until the training chords
    fix every window's sum (:func:`unfixed_error`); the fewest batches that do are found by
    doubling and halving.

    >>> designs = split_designs(15, 2)
    >>> len(designs), unfixed_error(designs, 2, (), (), 15) < FIXED
    (4, True)
    >>> [len(d) for d in split_designs(15, 2, short=True)]
    [3, 3, 3, 3, 15, 15, 15, 15, 15, 15, 15, 15, 15]
    """
    n, w, k = int(n_units), int(window), max(1, len(alphabet))
    rng = np.random.default_rng(seed)
    pool = design_pool(n, k, symmetric, rng, (2 * k) ** (2 * w))
    keys = _split_keys(pool, w, k, symmetric, short)
    ends = end_designs(w, True, k, alphabet, symmetric, units=2 * w - 1) if short else []
    cover = ends + design_strings(pool[cover_rows(keys, rng)], alphabet if k > 1 else ())
    batch = max(8, int(BATCH_FRACTION * len(cover)))
    extra = design_strings(random_designs(MAX_ADDED * len(cover), n, rng, k, symmetric), alphabet if k > 1 else ())

    def fixed(batches: int) -> bool:
        return unfixed_error(cover + extra[: batches * batch], w, alphabet, symmetric, n) < FIXED

    if fixed(0):
        return cover
    hi = 1
    while not fixed(hi):
        if hi * batch >= len(extra):
            return cover + extra  # the fit's check refuses what stays unfixed, naming a window
        hi *= 2
    lo = hi // 2  # not fixed (0 was tried first)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if fixed(mid) else (mid, hi)
    return cover + extra[: hi * batch]


def _split_keys(pool: NDArray[np.uint8], w: int, k: int, symmetric: tuple[int, ...], short: bool) -> IntArray:
    """The canonical keys (mirror: the smaller code) of every split term and end term of the pool's designs, one
    column per chord and term, each term in its own range; with ``short``, -1 for keys with the base or the tip."""
    width, radix = w + 1, 2 * k + 2
    sym = window_symbols(pool, width, n_types=k)
    both = (sym, mirror_symbols(sym, k, symmetric))
    last = (sym[:, -1:], both[1][:, -1:])
    spans = [(lo, hi, both) for lo, hi in far_terms(w, "split")] + [(lo, hi, last) for lo, hi in end_terms(w, "split")]
    span = radix ** (2 * width + 1)
    columns = []
    for t, (lo, hi, syms) in enumerate(spans):
        key = np.minimum(*(term_codes(s, width, lo, hi, radix) for s in syms)) + t * span
        if short:  # the end designs show every key with the base or the tip
            key = np.where(np.all(syms[0][..., lo + width:hi + width + 1] < 2 * k, axis=-1), key, -1)
        columns.append(key)
    return np.concatenate(columns, axis=1)


def unfixed_error(designs: Sequence[str], window: int, alphabet: tuple[str, ...], symmetric: tuple[int, ...],
                  n_units: int, seed: int = 0) -> float:
    """How far the chords of ``designs`` leave a ``split`` table's windows unfixed: 0 (to rounding) when they fix
    the sum of the terms at every window the table writes out.

    A random additive truth (one value per key of each term, seeded) gives every training
    chord (mirrored too) its value; the least-squares fit of minimum norm to them
    (:func:`scipy.sparse.linalg.lsqr`) is compared with the truth at every window an actuator
    of ``n_units`` units shows. A window whose sum the chords do not fix differs by about the
    truth's own size (order 1), and a key no design shows counts as unfixed (infinite).

    >>> unfixed_error(["aAea", "rRsS"], 2, ("a", "e", "r", "s"), (1,), 15)
    inf
    """
    w, k = int(window), max(1, len(alphabet))
    width, radix = w + 1, 2 * k + 2
    terms = far_terms(w, "split")
    rows = np.concatenate([s for d in designs for s, _ in symbols_of(d, width, True, alphabet, symmetric)])
    windows = written_windows(n_units, width, k, symmetric)
    cols, keys, offset = [], [], 0
    for lo, hi in terms:
        seen, inverse = np.unique(term_codes(rows, width, lo, hi, radix), return_inverse=True)
        wanted = term_codes(windows, width, lo, hi, radix)
        at = np.searchsorted(seen, wanted)
        if np.any(seen[np.minimum(at, len(seen) - 1)] != wanted):
            return float("inf")
        cols.append(inverse.ravel() + offset)
        keys.append(at + offset)
        offset += len(seen)
    a = sparse.csr_matrix((np.ones(len(rows) * len(terms)), (np.repeat(np.arange(len(rows)), len(terms)),
                                                               np.stack(cols, axis=1).ravel())), (len(rows), offset))
    truth = np.random.default_rng(seed).standard_normal(offset)
    fit = lsqr(a, a @ truth, atol=1e-14, btol=1e-14, iter_lim=20 * offset)[0]
    at = np.stack(keys, axis=1)
    return float(np.abs(fit[at].sum(axis=1) - truth[at].sum(axis=1)).max())


#: most covering designs a table over several unit types may ask for (the base windows alone need
#: ``(2k)^(w+1) / 2``: 256 for 4 types at window +-2)
MAX_TRAINING = 200


def check_training_size(n_types: int, window: int, symmetric: int = 0, n_units: int | None = None) -> None:
    """Refuse, before any solve, a window whose covering designs must be more than :data:`MAX_TRAINING`.

    Two lower bounds count them: the base windows alone need ``(2k)^(w+1) / 2`` designs (one
    each), and with ``n_units`` given, the interior windows ``(2k)^(2w+1) / 2`` patterns of
    ``2w + 1`` units, ``n_units - 2w`` of them in each design (``2k - s`` for ``k`` types,
    ``s`` of them symmetric; mirrored designs count once).

    >>> check_training_size(2, 2)
    >>> check_training_size(4, 2)
    Traceback (most recent call last):
    ...
    pneumorph.errors.LocalityError: a chain table over 4 unit types at window +-2 needs at least 256 FE solves for
    its base windows alone (at most 200, MAX_TRAINING); use a window of +-1 or at most 3 unit types
    >>> check_training_size(26, 1)
    Traceback (most recent call last):
    ...
    pneumorph.errors.LocalityError: a chain table over 26 unit types at window +-1 needs at least 1352 FE solves for
    its base windows alone (at most 200, MAX_TRAINING); use at most 10 unit types
    >>> check_training_size(4, 2, 1, n_units=15)
    Traceback (most recent call last):
    ...
    pneumorph.errors.LocalityError: a chain table over 4 unit types at window +-2 needs at least 764 FE solves of
    15-unit designs for its interior windows (at most 200, MAX_TRAINING); use a window of +-1 or at most 3 unit types
    """
    def base(types: int, w: int) -> int:
        return (2 * types - min(int(symmetric), types)) ** (w + 1) // 2

    def interior(types: int, w: int) -> int:
        if n_units is None or int(n_units) <= 2 * w:
            return 0
        return -(-((2 * types - min(int(symmetric), types)) ** (2 * w + 1) // 2) // (int(n_units) - 2 * w))

    def need(types: int, w: int) -> int:
        return max(base(types, w), interior(types, w))

    n, w = int(n_types), int(window)
    if n > 1 and need(n, w) > MAX_TRAINING:
        most = max((t for t in range(1, n) if need(t, w) <= MAX_TRAINING), default=1)
        advice = f"at most {most} unit types"
        if w > 1 and need(n, 1) <= MAX_TRAINING:
            advice = f"a window of +-1 or {advice}"
        what = (f"{base(n, w)} FE solves for its base windows alone" if base(n, w) > MAX_TRAINING else
                f"{interior(n, w)} FE solves of {n_units}-unit designs for its interior windows")
        raise LocalityError(f"a chain table over {n} unit types at window +-{w} needs at least {what} (at most "
                            f"{MAX_TRAINING}, MAX_TRAINING); use {advice}")


__all__ = ["BATCH_FRACTION", "FIXED", "MAX_ADDED", "MAX_TRAINING", "check_training_size", "split_designs",
           "training_designs", "unfixed_error"]

"""The random designs of a calibration: one per run, and held-out ones for validation.

Both are drawn from seeded generators of their own, so the calibration designs do not
depend on how many held-out designs are asked for, and the held-out ones exclude them.

Examples
--------
>>> calibration_designs(4, 2, seed=0)
['0111', '0011']
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from pneumorph.errors import SearchConfigError


def _random_design(rng: np.random.Generator, n_units: int) -> str:
    return "".join(map(str, rng.integers(0, 2, n_units)))


def calibration_designs(n_units: int, runs: int, seed: int = 0) -> list[str]:
    """The random design of each calibration run (one 3D solve each).

    Examples
    --------
    >>> calibration_designs(6, 2, seed=0)
    ['011100', '110010']
    """
    rng = np.random.default_rng(seed + 1)
    return [_random_design(rng, n_units) for _ in range(runs)]


def holdout_designs(n_units: int, count: int, seed: int = 0, exclude: Sequence[str] = ()) -> list[str]:
    """Distinct random designs for validation, none of them in ``exclude``.

    Pass the calibration designs as ``exclude`` so that the validation is held out.

    Raises
    ------
    SearchConfigError
        If the design space has fewer than ``count`` designs outside ``exclude``.

    Examples
    --------
    >>> held = holdout_designs(15, 10, exclude=calibration_designs(15, 3))
    >>> len(held), len(set(held)), len(held[0])
    (10, 10, 15)
    """
    excluded = set(exclude)
    free = 2**n_units - len(excluded)
    if count > free:
        raise SearchConfigError(f"{n_units} units have only {free} designs outside the {len(excluded)} excluded ones; "
                         f"{count} held-out designs were asked for")
    rng = np.random.default_rng(seed + 10_000)
    out: list[str] = []
    while len(out) < count:
        d = _random_design(rng, n_units)
        if d not in excluded and d not in out:
            out.append(d)
    return out

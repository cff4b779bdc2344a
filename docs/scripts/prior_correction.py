"""Is a 3D chain table the 2D table plus a local correction? Measured on the two tables of one library.

Reads a 3D table (its training and held-out designs) and the evaluation cache its build
solved them into, and a 2D table of the same library and ramp (the prior). Fits a
correction of window +-w to the 3D training chords' differences from the prior's
prediction (the mean over the chords of each window of +-w, mirrored chords included),
adds it to every window of the prior, and prints the worst and mean held-out centre error
of the result at the last level, for several training sizes. No FE solve.

    python docs/scripts/prior_correction.py --table3d T3.json --cache3d C3.sqlite --table2d T2.json \\
        --library LIBRARY.toml

For the `a`, `r` library: T3 is `examples/libraries/chain-3d-bending-rigid-far.json` with the
cache of its build (BENCHMARKS.md), T2 the 2D table with far-field terms,
`pneumorph chain build --model 2d --library examples/libraries/units-bending-rigid.toml
--window 2 --far-terms --all-heldout` (the same levels, 4.5-45 kPa).

Measured with the `a`, `r` tables (docs/unit-library.md): the 2D table is 16 mm off 3D; a
correction of +-1 leaves 3.0-3.9 mm, of +-2 from all 130 training designs 0.135 mm.
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np
from far_terms import errors, responses

from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.models.chain.model import ChainTable
from pneumorph.models.chain.terms import _observations, term_codes
from pneumorph.models.response import Response


def _means(keys: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    uniq, inverse = np.unique(keys, return_inverse=True)
    sums = np.zeros((len(uniq), values.shape[1]))
    np.add.at(sums, inverse, values)
    return uniq, sums / np.bincount(inverse)[:, None]


def _lookup(uniq: np.ndarray, means: np.ndarray, keys: np.ndarray) -> tuple[np.ndarray, int]:
    rows = np.clip(np.searchsorted(uniq, keys), 0, len(uniq) - 1)
    missing = uniq[rows] != keys
    return np.where(missing[:, None], 0.0, means[rows]), int(missing.sum())


def corrected(prior: ChainTable, train: list[Response], w: int, library: UnitLibrary) -> tuple[ChainTable, int]:
    """The prior plus the correction of window +-w fitted to ``train``; and how many prior windows it lacks."""
    width, radix = prior.window, 2 * prior.n_types + 2
    syms, values, esyms, ends = _observations(train, width, True, library.alphabet, library.symmetric_types)
    weights = radix ** np.arange(2 * width + 1)
    rows, ok = prior.find(syms @ weights)
    erows, eok = prior.find(esyms @ weights, end=True)
    assert ok.all() and eok.all(), "the prior lacks a window of the training designs"
    chord = _means(term_codes(syms, width, -w, w, radix),
                   values - np.concatenate([prior.turn[rows], prior.length[rows]], axis=1))
    end = _means(term_codes(esyms, width, -w, w, radix), ends - prior.end[erows])
    digits = (prior.codes[:, None] // weights) % radix
    d, missing = _lookup(*chord, term_codes(digits, width, -w, w, radix))
    edigits = (prior.end_codes[:, None] // weights) % radix
    de, _ = _lookup(*end, term_codes(edigits, width, -w, w, radix))
    k = prior.n_levels
    return replace(prior, turn=prior.turn + d[:, :k], length=prior.length + d[:, k:], end=prior.end + de), missing


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table3d", required=True)
    parser.add_argument("--cache3d", required=True)
    parser.add_argument("--table2d", required=True)
    parser.add_argument("--library", required=True, help="the library TOML file (or 'builtin')")
    args = parser.parse_args()
    library = builtin_library() if args.library == "builtin" else UnitLibrary.from_toml(args.library)
    table3d, prior = ChainTable.load(args.table3d), ChainTable.load(args.table2d)
    assert np.allclose(table3d.pressures, prior.pressures), "the two tables' levels differ"
    found = responses(args.cache3d, list(table3d.training) + list(table3d.validation["designs"]))
    train = [found[d] for d in table3d.training]
    held = [found[d] for d in table3d.validation["designs"]]
    print(f"3D table: worst {errors(table3d, held)[0]:.4f} mm; 2D prior on 3D: worst {errors(prior, held)[0]:.3f} mm")
    for n in (10, 40, len(train)):
        for w in (1, 2):
            table, missing = corrected(prior, train[:n], w, library)
            worst, mean = errors(table, held)
            print(f"  {n} training designs, correction +-{w}: worst {worst:.3f} mm, mean {mean:.3f} mm "
                  f"({missing} prior windows without a correction)")


if __name__ == "__main__":
    main()

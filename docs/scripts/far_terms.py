"""Refit a chain table with far-field terms from the solves of its build, and compare on its held-out designs.

Reads a table file (its training and held-out designs, its window and unit types) and the
evaluation cache its build solved them into; fits the table again from the same training
responses, plainly and with far-field terms (``pneumorph.models.chain.terms``), and prints
the worst and mean held-out centre error of both at the last level. No FE solve.

    python docs/scripts/far_terms.py --table TABLE.json --cache CACHE.sqlite [--library FILE]

``--library`` is the unit library of a table over several unit types (``builtin`` for the
built-in one).
"""

from __future__ import annotations

import argparse
import json
import sqlite3

import numpy as np

from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.models.chain.fit import fit_table
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.response import Response


def responses(cache: str, designs: list[str]) -> dict[str, Response]:
    """The cached responses of ``designs`` (of the fingerprint that holds most of them)."""
    rows = sqlite3.connect(cache).execute("select fingerprint, design, response from evaluations "
                                          "where status = 'ok'").fetchall()
    by: dict[str, dict[str, str]] = {}
    for fingerprint, design, text in rows:
        by.setdefault(fingerprint, {})[design] = text
    wanted = set(designs)
    return {d: Response.from_dict(json.loads(t)) for fp in by for d, t in by[fp].items() if d in wanted}


def errors(table: ChainTable, held: list[Response]) -> tuple[float, float]:
    """Worst and mean unit-centre error (mm) at the last level over the held-out designs."""
    e = np.concatenate([np.linalg.norm(ChainModel(table, r.n_units).evaluate(r.orientation).centres[-1]
                                       - r.centres[-1], axis=-1) for r in held])
    return float(e.max()), float(e.mean())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", required=True)
    parser.add_argument("--cache", required=True)
    parser.add_argument("--library", help="the unit library of a table over several types (a file or 'builtin')")
    args = parser.parse_args()
    table = ChainTable.load(args.table)
    library = None
    if args.library:
        library = builtin_library(args.library) if args.library == "builtin" else UnitLibrary.from_toml(args.library)
    held_designs = list(table.validation["designs"])
    found = responses(args.cache, list(table.training) + held_designs)
    train = [found[d] for d in table.training]
    held = [found[d] for d in held_designs if d in found]
    source = dict(table.source)
    units = sum(r.n_units for r in train)
    print(f"{args.table}: {len(train)} training designs ({units} unit solves), {len(held)} held-out designs")
    for name, far in (("plain", False), ("far-field terms", True)):
        fitted = fit_table(train, table.window, source, library=library, far=far)
        worst, mean = errors(fitted, held)
        print(f"  window +-{table.window} {name} (a table of +-{fitted.window}, {len(fitted.codes)} windows): "
              f"worst {worst:.4f} mm, mean {mean:.4f} mm at {table.pressures[-1] * 1e3:g} kPa")


if __name__ == "__main__":
    main()

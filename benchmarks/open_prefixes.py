"""How the certified search's open prefixes grow with a loose chain table, and what they cost.

Scores the designs of an actuator of ``--units`` units on a shipped table (``--table``: the 2D one, the 3D one, or
the 3D one of the ``spatial`` library, a chain in space over 4 letters) for the sine (A = 10 mm) with the chain's
bound multiplied by each ``--margin`` (as a loose table's would be), and prints the designs kept, the most open
prefixes at one depth (the last run's), the children of a prefix, the levels, the CPU time and the process's peak
memory so far:

    OMP_NUM_THREADS=1 nice python benchmarks/open_prefixes.py --units 22 --margin 1 2 4 8 16 32 64

The memory a kept prefix costs: one margin and one cap per process (the peak memory is the process's):

    OMP_NUM_THREADS=1 nice python benchmarks/open_prefixes.py --units 22 --margin 64 --max-open 50000
    OMP_NUM_THREADS=1 nice python benchmarks/open_prefixes.py --units 22 --margin 64 --max-open 200000
    OMP_NUM_THREADS=1 nice python benchmarks/open_prefixes.py --table spatial --units 14 --margin 64 --max-open 20000
"""

from __future__ import annotations

import argparse
import resource
import time

from pneumorph.design.certified.branching import MAX_NODES, OpenWatch, watching
from pneumorph.design.certified.planegrowth import chain_scores
from pneumorph.design.objectives.targets import make_objective
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import find_table
from pneumorph.models.factory import make_model

#: the shipped tables by their name here: the model settings they are fitted to
TABLES = {"2d": {"fidelity": "2d"}, "3d": {"fidelity": "3d"}, "spatial": {"fidelity": "3d", "library": "spatial"}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", choices=sorted(TABLES), default="2d")
    parser.add_argument("--units", type=int, default=22)
    parser.add_argument("--margin", type=float, nargs="+", default=[1.0])
    parser.add_argument("--max-open", type=int, default=MAX_NODES)
    args = parser.parse_args()
    chain = ChainModel(find_table(make_model(args.units, TABLES[args.table])), args.units)
    choices, levels = 2 * max(1, len(chain.table.alphabet)), len(chain.pressures())
    objective = make_objective("sin", 10.0, length=chain.length)
    chain_scores(chain, objective)  # warm-up: imports, the table's caches
    for margin in args.margin:
        t = time.process_time()
        with watching(OpenWatch(lambda text: None, cap=args.max_open)) as watch:
            scores = chain_scores(chain, objective, margin, max_nodes=args.max_open)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3
        print(f"{args.table} table, {args.units} units ({choices} children a prefix, {levels} levels), margin "
              f"{margin:g}, cap {args.max_open:,}: {len(scores.bits):,} designs kept, "
              f"most open at a depth {watch.peak:,}{' (the cap)' if watch.reached else ''}, "
              f"{time.process_time() - t:.2f} s CPU, peak memory {peak:.0f} MB", flush=True)


if __name__ == "__main__":
    main()

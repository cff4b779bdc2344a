"""How the certified search's open prefixes grow with a loose chain table, and what they cost.

Scores the designs of an actuator of ``--units`` units on the shipped 2D table for the sine (A = 10 mm) with the
chain's bound multiplied by each ``--margin`` (as a loose table's would be), and prints the designs kept, the most
open prefixes at one depth (the last run's), the CPU time and the process's peak memory so far:

    OMP_NUM_THREADS=1 nice python benchmarks/open_prefixes.py --units 22 --margin 1 2 4 8 16 32 64

The memory a kept prefix costs: one margin and one cap per process (the peak memory is the process's):

    OMP_NUM_THREADS=1 nice python benchmarks/open_prefixes.py --units 22 --margin 64 --max-open 50000
    OMP_NUM_THREADS=1 nice python benchmarks/open_prefixes.py --units 22 --margin 64 --max-open 200000
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, default=22)
    parser.add_argument("--margin", type=float, nargs="+", default=[1.0])
    parser.add_argument("--max-open", type=int, default=MAX_NODES)
    args = parser.parse_args()
    chain = ChainModel(find_table(make_model(args.units, {"fidelity": "2d"})), args.units)
    objective = make_objective("sin", 10.0, length=chain.length)
    chain_scores(chain, objective)  # warm-up: imports, the table's caches
    for margin in args.margin:
        t = time.process_time()
        with watching(OpenWatch(lambda text: None, cap=args.max_open)) as watch:
            scores = chain_scores(chain, objective, margin, max_nodes=args.max_open)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3
        print(f"{args.units} units, margin {margin:g}, cap {args.max_open:,}: {len(scores.bits):,} designs kept, "
              f"most open at a depth {watch.peak:,}{' (the cap)' if watch.reached else ''}, "
              f"{time.process_time() - t:.2f} s CPU, peak memory {peak:.0f} MB", flush=True)


if __name__ == "__main__":
    main()

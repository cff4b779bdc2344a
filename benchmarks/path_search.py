"""Wall time of the certified search's chain part for paths (targets of any shape), 15 units, no FE solve.

Every path preset on the shipped 3D tables: the default unit (2^15 designs, all scored), the
built-in four-type library (8^15, beam then branch-and-bound) and, for the presets in space,
the spatial library (4^15). Prints the chain's winner, its value and RMS per centre, whether
the listing is complete or its floor, and the wall time. Run on one core:

    OMP_NUM_THREADS=1 python benchmarks/path_search.py [--repeat 3] [--preset hook ...]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

from pneumorph.design.certified.planegrowth import chain_scores
from pneumorph.design.objectives.paths import PATH_PRESETS, preset_path
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import find_table
from pneumorph.models.factory import make_model

LIBRARIES = {"one type (2^15)": None, "builtin (8^15)": "builtin", "spatial (4^15)": "spatial"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--preset", action="append", choices=sorted(PATH_PRESETS))
    parser.add_argument("--library", action="append", choices=sorted(LIBRARIES))
    args = parser.parse_args()
    print(f"{platform.node()}: {os.cpu_count()} cores, OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS')}")
    for label in args.library or LIBRARIES:
        library = LIBRARIES[label]
        settings = {"fidelity": "3d", **({"library": library} if library else {})}
        chain = ChainModel(find_table(make_model(15, settings)), 15)
        for name in args.preset or PATH_PRESETS:
            objective = preset_path(name)
            if (objective.spatial and library != "spatial") or (library == "spatial" and not objective.spatial
                                                                 and name not in ("hook", "letter-l")):
                continue  # a path in space needs sideways units; over them, two planar paths for comparison
            times = []
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                scores = chain_scores(chain, objective)
                times.append(time.perf_counter() - t0)
            best = scores.order()[0]
            design = chain.table.texts(scores.bits[best:best + 1])[0]
            value = float(scores.cost[best])
            state = "complete" if scores.complete else f"{len(scores.bits):,} listed, floor {scores.floor:.3f}"
            runs = ", ".join(f"{t:.2f}" for t in times)
            kpa = chain.table.pressures[scores.level[best]] * 1e3
            print(f"{label:16s} {name:9s} median {statistics.median(times):6.2f} s ({runs}): {design} {value:.3f} mm "
                  f"({value / np.sqrt(15):.3f} mm RMS per centre) at {kpa:g} kPa; {state}")


if __name__ == "__main__":
    main()

"""Wall time of the certified search's chain part over a chain in space (the spatial library, 15 units).

Scores the designs of ``a`` and ``l`` (4 choices a unit: 4^15 = 1.1e9 designs) for space
targets with the spatial library's 3D table, no FE solve: the beam, then branch-and-bound
(:func:`pneumorph.design.certified.spacegrowth.space_scores`), and the same over the planar codes only
(the certificate's best design that stays in the plane). Run on one core:

    OMP_NUM_THREADS=1 python benchmarks/space_search.py [--table FILE] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

from pneumorph.design.certified.spacegrowth import space_scores
from pneumorph.design.objectives.targets import make_objective, tip_goal
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import shipped_path

TARGETS = {
    "helix, A = 25 mm": lambda length: make_objective("helix", 25.0, length=length),
    "space S: y = 10 sin(2 pi x/L), z = 6 sin(pi x/L)": lambda length: make_objective(
        "y = 10*sin(2*pi*x/L), z = 6*sin(pi*x/L)", length=length),
    "sin, A = 10 mm (planar)": lambda length: make_objective("sin", 10.0, length=length),
    "reach (100, 40, 40) mm": lambda length: tip_goal("reach", (100.0, 40.0, 40.0)),
    "max-x": lambda length: tip_goal("max-x"),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", default=str(shipped_path("3d", "spatial")))
    parser.add_argument("--units", type=int, default=15)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"{platform.node()}: {os.cpu_count()} cores, OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS')}")
    chain = ChainModel(ChainTable.load(args.table), args.units)
    print(f"table {args.table}: window +-{chain.table.window}, {len(chain.table.codes)} windows, "
          f"{len(chain.table.unit_codes) ** args.units:.3g} designs of {args.units} units")
    planar = np.array([0, 1], dtype=np.uint8)
    for name, make in TARGETS.items():
        objective = make(chain.length)
        for label, codes in (("a, l", None), ("a only", planar)):
            times = []
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                scores = space_scores(chain, objective, codes=codes)
                times.append(time.perf_counter() - t0)
            best = scores.order()[0]
            design = chain.table.texts(scores.bits[best:best + 1])[0]
            runs = ", ".join(f"{t:.2f}" for t in times)
            value = scores.per_level[best, scores.level[best]]
            state = "complete" if scores.complete else f"floor {scores.floor:.3f}"
            print(f"{name:52s} {label:7s} median {statistics.median(times):6.2f} s ({runs}): best {design} "
                  f"{value:.3f}, {len(scores.bits):,} listed, {state}", flush=True)


if __name__ == "__main__":
    main()

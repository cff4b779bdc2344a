"""Scoring every design of a 15-unit actuator with the chain model: first and repeated queries.

    OMP_NUM_THREADS=1 python benchmarks/chain_scores.py

The first query of a chain model grows the prefix tree and keeps its geometry
(:func:`pneumorph.design.certified.search.chain_geometry`); later queries only evaluate the
objective per prefix. Prints the median of 20 repeated queries for several objectives on
the shipped 3D and 2D tables.
"""

from __future__ import annotations

import os
import platform
import time

import numpy as np

from pneumorph.design.certified.search import chain_scores
from pneumorph.design.objectives.targets import make_objective
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import find_table
from pneumorph.models.factory import make_model


def main() -> None:
    print(f"machine: {platform.node()} {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS')}")
    for fidelity in ("3d", "2d"):
        chain = ChainModel(find_table(make_model(15, {"fidelity": fidelity})), 15)
        first = None
        for spec in ("sin", "cos", "y = 0.3*x", "r = 60 - 2*theta", "max-x", "reach"):
            profile = "=" in spec or spec in ("sin", "cos")
            obj = make_objective(spec, 10.0, point=(60.0, 40.0) if spec == "reach" else None,
                                 length=chain.length if profile else None)
            t = time.perf_counter()
            chain_scores(chain, obj)
            if first is None:
                first = time.perf_counter() - t
            times = []
            for _ in range(20):
                t = time.perf_counter()
                chain_scores(chain, obj)
                times.append(time.perf_counter() - t)
            print(f"{fidelity} {spec:<18} median {1e3 * np.median(times):6.1f} ms")
        print(f"{fidelity} first query (geometry grown and kept): {1e3 * first:.0f} ms")


if __name__ == "__main__":
    main()

"""Robustness to mould tolerances by the chain model: one design, and every design of 15 units.

    OMP_NUM_THREADS=1 python benchmarks/robustness.py

Times, on the shipped 2D and 3D tables and tolerance tables (+-0.1 mm): moving the chain
table to one sample of the class, the winner's spread over 30 samples (what every certified
design run adds), and every design's worst error over 30 samples at its most robust level
(what ``--robust worst`` adds).
"""

from __future__ import annotations

import os
import platform
import time

import numpy as np

from pneumorph.design.objectives.targets import make_objective
from pneumorph.design.runs.robustness import design_robustness
from pneumorph.models.chain.model import ChainTable, design_array
from pneumorph.models.chain.sources import shipped_path
from pneumorph.sensitivity.robust import shipped_tolerance_tables


def main() -> None:
    print(f"machine: {platform.node()} {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS')}")
    objective = make_objective("sin", 10.0, 1.0, length=157.5)
    every = ((np.arange(2**15)[:, None] >> np.arange(14, -1, -1)) & 1).astype(np.uint8)
    for fidelity in ("3d", "2d"):
        table = ChainTable.load(shipped_path(fidelity))
        tables = shipped_tolerance_tables(fidelity)
        offsets = tables.tolerance.samples(20, seed=0)
        t = time.perf_counter()
        for o in offsets:
            tables.perturbed(table, o)
        move = (time.perf_counter() - t) / len(offsets)
        t = time.perf_counter()
        design_robustness(table, tables, objective, design_array("001111010001001"), level=np.array([9]), samples=30)
        one = time.perf_counter() - t
        t = time.perf_counter()
        design_robustness(table, tables, objective, every, samples=30, choose="worst")
        all_designs = time.perf_counter() - t
        print(f"{fidelity}: perturbed table {move * 1e3:.1f} ms; one design x 30 samples {one:.3f} s; "
              f"all 32,768 designs x 30 samples {all_designs:.1f} s")


if __name__ == "__main__":
    main()

"""One residual and one tangent of the fast 3D system, at a solved state of a 15-unit design.

Solves the design's ramp (the half model, 45 kPa, 10 levels) up to the end of a level, then
times the system's ``residual`` and ``tangent_data`` there, in the single precision the kept
tangents are assembled in and in double precision (CPU, best of a few rounds). One thread:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/assembly.py -o 011100110010010

Run it from two checkouts back to back (``PYTHONPATH=.../src``) to compare their assembly.
"""

from __future__ import annotations

import argparse
import time

import numpy as np


class Reached(Exception):
    """Raised to leave the ramp at the level asked for."""


def best(function, repeats: int, rounds: int = 3) -> float:
    """The best mean CPU time (ms) of ``repeats`` calls over ``rounds`` rounds."""
    times = []
    for _ in range(rounds):
        start = time.process_time()
        for _ in range(repeats):
            function()
        times.append((time.process_time() - start) / repeats * 1e3)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--orientation", default="011100110010010")
    parser.add_argument("--level", type=int, default=3, help="the level whose solved state is timed")
    args = parser.parse_args()

    from pneumorph.fem.fast.newton import FastSubstep
    from pneumorph.models.fe import Full3D

    reached: dict[str, object] = {}
    original = FastSubstep.__call__

    def traced(self, fields, settings, border=None):
        out = original(self, fields, settings, border)
        reached["calls"] = int(reached.get("calls", 0)) + 1
        if reached["calls"] == args.level:  # one substep per level unless one is cut back
            reached["system"], reached["u"] = self.system, fields[0].values.ravel().copy()
            raise Reached
        return out

    FastSubstep.__call__ = traced
    try:
        Full3D(len(args.orientation)).solve(args.orientation)
    except Reached:
        pass
    finally:
        FastSubstep.__call__ = original
    system, u = reached["system"], reached["u"]
    cells = sum(s.cells.shape[0] for s in system.solids)
    print(f"{args.orientation}, level {args.level}: {cells} cells, {system.dof1.size} unknowns, "
          f"{system.nnz} stored entries")
    residual = best(lambda: system.residual(u), 10)
    timings = {}
    for dtype in (np.float32, np.float64):
        system.tangent_dtype = dtype
        timings[np.dtype(dtype).name] = best(system.tangent_data, 4)
    print(f"residual {residual:.1f} ms, tangent {timings['float32']:.1f} ms (single precision), "
          f"{timings['float64']:.1f} ms (double), CPU")


if __name__ == "__main__":
    main()

"""Wall time of one actuator evaluation (the cost of one design in the search).

Solves a 15-unit design (random, seeded) with the 2D reduced-order or the 3D model, 10
reported increments to the final pressure, and reports the median wall time over the
repeats, Newton iterations and cut-backs. Run on one core as a search worker would:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/evaluate.py --model 2d --repeat 5
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/evaluate.py --model 3d --repeat 1

Targets: 2D <= 2 s median (goal 0.25 s); 3D <= 120 s (goal 30 s); the dissertation
needed 45 s and 590 s. The 3D model's PARDISO factorisation uses ``MKL_NUM_THREADS`` threads
(a search runs one process per core with 1); for two, keep ``OMP_NUM_THREADS=1``
(threaded OpenBLAS slows the many small matrix products of the assembly):

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=2 python benchmarks/evaluate.py --model 3d --repeat 1
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", choices=["2d", "3d"], default="2d")
    parser.add_argument("--units", type=int, default=15)
    parser.add_argument("--pressure", type=float, default=45.0, help="kPa")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--unit", help="unit TOML file (default: the built-in unit)")
    parser.add_argument("--design", help="orientation digits (default: random, seed 0)")
    parser.add_argument("--backend", help="assembly and Newton method (default: the model's, 2D: fast)")
    args = parser.parse_args()
    unit = UnitSpec.from_toml(args.unit) if args.unit else UnitSpec()
    cls = Reduced2D if args.model == "2d" else Full3D
    # the model's default ramp (one substep per level before any cut-back), 10 reported levels
    ramp = RampSpec(pressure=args.pressure / 1e3, steps=cls.default_steps)
    model = cls(args.units, unit, ramp, backend=args.backend)
    design = args.design or "".join(map(str, np.random.default_rng(0).integers(0, 2, args.units)))
    threads = os.environ.get("MKL_NUM_THREADS", "unset")
    print(f"{args.model} model ({model.backend}), design {design}, {args.pressure:g} kPa; {platform.machine()}, "
          f"Python {platform.python_version()}, MKL_NUM_THREADS={threads}")
    if args.model == "2d":
        model.evaluate(design[::-1])  # warm-up: imports, MKL, caches (another design)
    else:  # the same on a 1-unit model: a second 15-unit 3D solve would double the run
        cls(1, unit, RampSpec(pressure=0.005, steps=cls.default_steps), backend=args.backend).evaluate("0")
    times = []
    for i in range(args.repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        r = model.evaluate(design)
        times.append(time.perf_counter() - t0)
        cpu = time.process_time() - c0
        m = r.metadata
        print(f"  run {i + 1}: {times[-1]:.3f} s wall, {cpu:.3f} s CPU, {m['newton_iterations']} Newton iterations "
              f"({m['factorisations']} factorisations), {m['substeps']} substeps, {m['cutbacks']} cut-backs, "
              f"{m['dofs']} dofs, curl {r.curl[-1]:.4f} deg")
    print(f"median {statistics.median(times):.3f} s over {len(times)} runs")


if __name__ == "__main__":
    main()

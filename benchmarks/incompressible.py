"""A nearly incompressible body silicone: the answers and the cost of the u-p-J form against the displacement form.

One design in 3D at 45 kPa, the body's bulk modulus scaled (``body_bulk_scale``: 1, the library's; 10; 550, a
Poisson's ratio of 0.499 for Mold Star 15) in the form the model chooses (u-p-J from a Poisson's ratio of 0.45)
and, at 550, the displacement form forced. For each: tip and curl at 36 and 45 kPa, the cavities' enclosed volume
change (the half model's), Newton iterations, cut-backs, CPU and wall time of the solve. Run on one core:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/incompressible.py                   # 15 units
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/incompressible.py --design 00111    # 5 units
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import numpy as np

from pneumorph.models.factory import make_model

CASES = (("library K", {}), ("K x10", {"body_bulk_scale": 10.0}), ("K x550", {"body_bulk_scale": 550.0}),
         ("K x550, displacement", {"body_bulk_scale": 550.0, "formulation": "displacement"}))


def measure(design: str, settings: dict) -> dict:
    """One solve of ``design`` and what it gives and costs."""
    model = make_model(len(design), {"fidelity": "3d", "pressure_kpa": 45, **settings})
    wall, cpu = time.perf_counter(), time.process_time()
    solution = model.solve(design)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    r = solution.response
    _, body, _ = model.build(design)
    _, monitor = body.stepper("fast", model.tangent_reuse, model.anderson_depth)
    body.displacement[...] = 0.0
    v0 = monitor()
    volumes = []
    for u in solution.displacements:
        body.displacement[...] = u
        volumes.append(monitor())
    at = {kpa: int(np.argmin(abs(r.pressures - kpa / 1e3))) for kpa in (36, 45)}
    return {"form": "u-p-J" if model.element_volume(model.body) else "displacement",
            "bulk_kpa": model.body.bulk_modulus.value * 1e3,
            **{f"tip_{kpa}": [round(float(x), 3) for x in r.tip[k]] for kpa, k in at.items()},
            **{f"curl_{kpa}": round(float(r.curl[k]), 3) for kpa, k in at.items()},
            **{f"volume_{kpa}_pct": round(100 * (volumes[k] / v0 - 1), 2) for kpa, k in at.items()},
            "iterations": r.metadata["newton_iterations"], "cutbacks": r.metadata["cutbacks"],
            "cpu_s": round(cpu, 1), "wall_s": round(wall, 1)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--design", default="001111010001001")
    args = parser.parse_args()
    threads = os.environ.get("OMP_NUM_THREADS")
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, OMP_NUM_THREADS={threads}")
    for label, settings in CASES:
        print(json.dumps({"case": label, "design": args.design, **measure(args.design, settings)}), flush=True)


if __name__ == "__main__":
    main()

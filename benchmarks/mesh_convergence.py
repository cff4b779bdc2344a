"""Cost of refined 3D solves: wall time, peak memory and factorisation precision per element size.

Each solve runs in a fresh process (its peak resident memory is its own), one thread:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/mesh_convergence.py \\
        --design 001111010001001 --design 001111010001000 --size 1.5 --size 1.0 [--json out.json]

The convergence itself (observed order, Richardson limits) is ``pneumorph sensitivity mesh``
(docs/mesh-convergence.md); this script measures what each mesh costs.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import platform
import resource
import time


def _solve(design: str, size: float, queue: mp.Queue) -> None:  # type: ignore[type-arg]
    from pneumorph.geometry.meshsize import estimate_mesh
    from pneumorph.geometry.unit import UnitSpec
    from pneumorph.models.fe import Full3D

    model = Full3D(len(design), UnitSpec(element_size=size))
    t0 = time.perf_counter()
    try:
        r = model.evaluate(design)
        row = {"design": design, "element_size_mm": size, "dofs": r.metadata["dofs"],
               "precision": r.metadata["precision"], "newton_iterations": r.metadata["newton_iterations"],
               "factorisations": r.metadata["factorisations"], "cutbacks": r.metadata["cutbacks"],
               "curl_deg": float(r.curl[-1]), "tip_mm": r.tip[-1].tolist()}
    except Exception as exc:  # report and go on with the next case
        row = {"design": design, "element_size_mm": size, "failed": str(exc)}
    row["wall_time_s"] = time.perf_counter() - t0
    row["peak_rss_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
    row["estimated_gb"] = estimate_mesh(model.unit, model.n_units, 3).bytes / 1e9
    queue.put(row)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--design", action="append", help="design, base first (repeat)")
    parser.add_argument("--size", type=float, action="append", help="element size, mm (repeat)")
    parser.add_argument("--json", help="write the rows to this file")
    args = parser.parse_args()
    designs = args.design or ["001111010001001"]
    sizes = args.size or [1.5, 1.0]
    ctx = mp.get_context("spawn")
    rows = []
    for size in sizes:
        for design in designs:
            queue = ctx.Queue()
            proc = ctx.Process(target=_solve, args=(design, size, queue))
            proc.start()
            row = queue.get()
            proc.join()
            rows.append(row)
            print(json.dumps(row), flush=True)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"machine": platform.node(), "cpus": mp.cpu_count(), "rows": rows}, fh, indent=1)


if __name__ == "__main__":
    main()

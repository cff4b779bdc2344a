"""A 3D identification from two synthetic scans of two 15-unit designs.

    OMP_NUM_THREADS=1 python benchmarks/identify.py                  # 2 workers, a fresh cache
    OMP_NUM_THREADS=1 python benchmarks/identify.py --workers 2 --cache /tmp/id.sqlite --out /tmp/id

The "cast" actuators are the 3D model with a known change (the body's bulk modulus x1.06
and the Mold Star wall +0.08 mm, meshed as the identification meshes them), inflated to
36 kPa; each scan is 3000 of their outer surface nodes, moved by a known rotation and
translation, with 0.05 mm Gaussian noise (as docs/scripts/correlation_check.py makes them).
The identification fits all five parameters through the process pool behind the given
cache (default: a fresh one, so the first run's cost is measured), then runs again from the
cache. Prints the truth, the fit, the standard errors and correlations, the residuals,
the solves, the wall times and the machine. With ``--out`` it writes the identified model
(``identified.toml``) and the true one (``truth.toml``, a ``[model]`` table) there, for
``benchmarks/design_again.py``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from pneumorph.correlation import Scan, Transform, model_shape
from pneumorph.design.config import to_toml
from pneumorph.execution import CachedEvaluator, EvaluationCache, make_evaluator
from pneumorph.geometry.unit import UnitSpec
from pneumorph.identify import NAMES, Observation, ParameterSet, ScanSpec, identify, write_identified
from pneumorph.models.factory import make_model

DESIGNS = ("001111010001001", "000011110000111")
PRESSURE = 36.0
SIGMA = 0.05
CHANGE = np.array([0.06, 0.0, 0.0, 0.08, 0.0])  # bulk x1.06, wall +0.08 mm


def synthetic(params: ParameterSet, truth: np.ndarray, seed: int,
              pressures: tuple[float, ...] = (PRESSURE,)) -> list[Observation]:
    rng = np.random.default_rng(seed)
    out = []
    for pressure in pressures:
        for k, design in enumerate(DESIGNS):
            model = make_model(len(design), params.settings(truth, {"fidelity": "3d", "pressure_kpa": pressure}))
            shape = model_shape(model.solve(design))
            points = shape.surface[rng.choice(len(shape.surface), 3000, replace=False)]
            turn = Rotation.from_rotvec([0.3, -0.2, 0.5 + 0.1 * k]).as_matrix()
            moved = Transform(turn, np.array([5.0, -3.0, 7.0]))
            scan = Scan(moved(points) + rng.normal(scale=SIGMA, size=points.shape), None,
                        f"synthetic scan of {design} at {pressure:g} kPa")
            out.append(Observation(ScanSpec(f"synthetic-{design}-{pressure:g}kPa.stl", design, pressure), scan))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cache", type=Path)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, help="write identified.toml and truth.toml here")
    parser.add_argument("--change", type=float, nargs=5, default=CHANGE.tolist(), metavar="D",
                        help="the truth's change from nominal: bulk scale, shear scale (added to 1), side wall, "
                             "wall, layer (mm); default 0.06 0 0 0.08 0")
    parser.add_argument("--pressures", type=float, nargs="+", default=[PRESSURE],
                        help="scan each design at these pressures, kPa (default: 36)")
    args = parser.parse_args()
    params = ParameterSet(UnitSpec())
    truth = params.nominal + np.asarray(args.change)
    t0 = time.perf_counter()
    observations = synthetic(params, truth, args.seed, tuple(args.pressures))
    making = time.perf_counter() - t0
    print(f"{len(observations)} synthetic scans made ({making:.0f} s, {len(observations)} solves of the true model)",
          flush=True)
    cache = args.cache or Path(tempfile.mkdtemp()) / "identify.sqlite"
    runs = []
    for run in ("first", "again from the cache"):
        evaluator = CachedEvaluator(make_evaluator("processes", args.workers), EvaluationCache(cache))
        t0 = time.perf_counter()
        try:
            result = identify(observations, params, evaluator, {"fidelity": "3d"}, seed=args.seed,
                              on_progress=lambda text: print(f"  {text}", flush=True))
        finally:
            evaluator.close()
        runs.append(time.perf_counter() - t0)
        print(f"{run}: {runs[-1]:.1f} s, {result.solves} solves asked", flush=True)
    if args.out is not None:
        write_identified(result, args.out)
        truth_model = params.settings(truth, {"fidelity": "3d"})
        (args.out / "truth.toml").write_text(to_toml({"model": truth_model}), encoding="utf-8")
    print(json.dumps({
        "truth": dict(zip(NAMES, truth.tolist(), strict=True)),
        "fit": {n: {"value": p["value"], "standard_error": p["standard_error"], "identified": p["identified"],
                    "error": p["value"] - t, "note": p["note"]}
                for (n, p), t in zip(result.parameters().items(), truth, strict=True)},
        "correlation": {"parameters": list(result.free), "matrix": np.round(result.correlation, 3).tolist()},
        "rms_before_mm": result.rms_before.tolist(), "rms_after_mm": result.rms_after.tolist(),
        "fit_residual_after_mm": result.residual_after.tolist(), "iterations": result.iterations,
        "solves": result.solves, "element_size_mm": params.element_size,
        "wall_time_s": {"scans": making, "first": runs[0], "cached": runs[1]},
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "workers": args.workers,
                    "omp_num_threads": os.environ.get("OMP_NUM_THREADS")},
    }, indent=1))


if __name__ == "__main__":
    main()

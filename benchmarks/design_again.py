"""Design again with an identified model, then judge both designs on the true model (3D FE).

    OMP_NUM_THREADS=1 python benchmarks/design_again.py /tmp/again --workers 2

Reads ``identified.toml`` and ``truth.toml`` from the folder (``benchmarks/identify.py --out``
writes them: the model identified from two synthetic scans, and the model the scans were
made from). Runs ``pneumorph design --model-file identified.toml --json`` (the default
target, sin with amplitude 10 mm over 15 units, certified on the identified 3D model; its
chain table is built on first use into the cache's folder) whose comparison names the
nominal model's optimum. Then solves both designs on the true model and prints their Eq 4.1
errors (best level), with the wall times and the machine.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

from pneumorph.design import DesignConfig, score
from pneumorph.execution import CachedEvaluator, EvaluationCache, make_evaluator
from pneumorph.models.factory import make_model, read_model_file


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", type=Path, help="holds identified.toml and truth.toml")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cache", type=Path, help="evaluation cache (default: FOLDER/cache/evaluations.sqlite)")
    args = parser.parse_args()
    cache = args.cache or args.folder / "cache" / "evaluations.sqlite"
    cache.parent.mkdir(parents=True, exist_ok=True)
    command = [sys.executable, "-m", "pneumorph", "design", "--model-file", str(args.folder / "identified.toml"),
               "--workers", str(args.workers), "--cache", str(cache), "--out", str(args.folder / "run"),
               "--tolerance", "0", "--json"]
    t0 = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    designing = time.perf_counter() - t0
    sys.stderr.write(done.stderr)
    if done.returncode != 0:
        raise SystemExit(f"design failed ({done.returncode})")
    run = json.loads(done.stdout)
    comparison = run["comparison"]
    designs = {"nominal": comparison["reference_design"], "identified": comparison["winner_design"]}
    truth = make_model(15, read_model_file(args.folder / "truth.toml"))
    objective = DesignConfig().make_objective()
    evaluator = CachedEvaluator(make_evaluator("processes", args.workers), EvaluationCache(cache))
    t0 = time.perf_counter()
    try:
        outcomes = evaluator.evaluate_many(truth, list(dict.fromkeys(designs.values())))
    finally:
        evaluator.close()
    judging = time.perf_counter() - t0
    on_truth = {o.design: score(o.response, objective) for o in outcomes}
    print(json.dumps({
        "target": objective.label,
        "designs": designs,
        "on_identified_model_mm": {"nominal": comparison["reference_on_model"],
                                   "identified": comparison["winner_value"]},
        "on_nominal_model_mm": comparison["reference_value"],
        "on_true_model_mm": {k: on_truth[d].value for k, d in designs.items()},
        "true_model_level_kpa": {k: on_truth[d].pressure * 1e3 for k, d in designs.items()},
        "certified": run["certificate"]["certified"], "search_note": run["search_note"],
        "wall_time_s": {"design (table build, search, comparison)": designing, "true-model solves": judging},
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "workers": args.workers,
                    "omp_num_threads": os.environ.get("OMP_NUM_THREADS")},
    }, indent=1))


if __name__ == "__main__":
    main()

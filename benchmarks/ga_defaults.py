"""The GA with its default operators against random search and the exhaustive optimum.

The certified search is the default; the GA is the fallback where no chain table serves
(gravity). This measures whether its default operators (``GAConfig()`` but for the
population, generations and seed) find optima on small designs, where the exhaustive search
knows the answer: for 6-10 units, five targets and several seeds, a GA of population 12 and
6 generations (with ``--budget``: as many generations as a budget of distinct designs
allows), and random search over as many distinct designs as that GA run evaluated (drawn
without replacement, seeded alike). ``--set`` compares other settings. A run *finds* the optimum when its best value
equals the exhaustive optimum within 1e-9 (relative; mirror designs of a symmetric objective
tie). The designs are scored by the 2D model through its shipped chain table (2D FE within
0.01 mm at 6 units, ``docs/chain-model.md``), or with ``--fe`` by 2D FE solves (cached).

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/ga_defaults.py [--units 6 7 8 9 10] [--seeds 20]
        [--budget N] [--set KEY=VALUE ...] [--fe --cache F] [--json F]
"""

from __future__ import annotations

import argparse
import ast
import json
import math
import os
import platform
import time
from dataclasses import asdict, replace

import numpy as np

from pneumorph.design import GAConfig, make_objective, run_exhaustive, run_ga
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
from pneumorph.models import ChainModel, ChainTable, Reduced2D
from pneumorph.models.chain.sources import shipped_path

#: the five targets, chosen before any run: two profiles and three tip goals
TARGETS = {"sin A=10": ("sin", {"amplitude": 10.0}), "cos A=10": ("cos", {"amplitude": 10.0}),
           "max-y": ("max-y", {}), "min-x": ("min-x", {}), "min-distance": ("min-distance", {})}


def found(value: float, optimum: float) -> bool:
    """Whether a search's best value is the optimum (within the tolerance of a mirror tie)."""
    return abs(value - optimum) <= 1e-9 * max(1.0, abs(optimum))


def random_search(values: dict[str, float], sense: str, draws: int, seed: int) -> float:
    """The best of ``draws`` distinct designs drawn at random (without replacement)."""
    designs = sorted(values)
    picked = np.random.default_rng(seed).choice(len(designs), size=min(draws, len(designs)), replace=False)
    chosen = [values[designs[i]] for i in picked]
    return min(chosen) if sense == "min" else max(chosen)


def chance(values: dict[str, float], optimum: float, draws: int) -> float:
    """Probability that ``draws`` distinct random designs hold an optimum (several tie for it)."""
    total, best = len(values), sum(found(v, optimum) for v in values.values())
    return 1.0 - math.comb(total - best, draws) / math.comb(total, draws) if draws <= total else 1.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--units", type=int, nargs="+", default=[6, 7, 8, 9, 10])
    parser.add_argument("--seeds", type=int, default=20, help="seeds 0 .. N-1 (the bar counts 0-4)")
    parser.add_argument("--population", type=int, default=12)
    parser.add_argument("--generations", type=int, default=6)
    parser.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE",
                        help="other GA settings than the defaults, as Python literals (mutpb=0.2 distinct=False)")
    parser.add_argument("--budget", type=int, help="stop at this many distinct designs instead of after "
                        "--generations (then up to 1000 generations): the search per solve")
    parser.add_argument("--fe", action="store_true", help="2D FE solves instead of the 2D chain table")
    parser.add_argument("--cache", default=":memory:", help="evaluation cache of the FE solves (SQLite file)")
    parser.add_argument("--json", help="write the results to this file")
    args = parser.parse_args()
    settings = {k: ast.literal_eval(v) for k, v in (item.split("=", 1) for item in args.set)}
    if args.budget is not None:
        settings.update(budget=args.budget, generations=1000)
    defaults = GAConfig(**{"population": args.population, "generations": args.generations, **settings})
    print(f"GA defaults {asdict(defaults)}; {platform.machine()}, {os.cpu_count()} cores; "
          f"{'2D FE' if args.fe else '2D chain table'}", flush=True)
    table = None if args.fe else ChainTable.load(shipped_path("2d"))
    rows = []
    for n in args.units:
        model = Reduced2D(n) if args.fe else ChainModel(table, n)
        evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(args.cache))
        for label, (spec, kw) in TARGETS.items():
            objective = make_objective(spec, **kw)
            start = time.perf_counter()
            exhaustive = run_exhaustive(model, objective, evaluator)
            values = {d: s.value for d, s in exhaustive.scores.items()}
            optimum = exhaustive.best.value
            ga_found, random_found, expected, looked = [], [], [], []
            for seed in range(args.seeds):
                ga = run_ga(model, objective, replace(defaults, seed=seed), evaluator)
                looked.append(len(ga.scores))
                ga_found.append(found(ga.best.value, optimum))
                random_found.append(found(random_search(values, objective.sense, len(ga.scores), seed), optimum))
                expected.append(chance(values, optimum, len(ga.scores)))
            row = {"units": n, "target": label, "optimum": exhaustive.best.design, "value": optimum,
                   "ga_found_first5": sum(ga_found[:5]), "ga_found": sum(ga_found),
                   "random_found_first5": sum(random_found[:5]), "random_found": sum(random_found),
                   "random_expected": float(np.sum(expected)), "seeds": args.seeds,
                   "distinct_designs_mean": float(np.mean(looked)), "designs": 2**n,
                   "wall_s": time.perf_counter() - start}
            rows.append(row)
            print(f"{n:2d} units  {label:13s} optimum {row['optimum']} {optimum:9.3f}  "
                  f"GA {row['ga_found_first5']}/5 seeds 0-4, {row['ga_found']}/{args.seeds}  "
                  f"random {row['random_found']}/{args.seeds} (expected {row['random_expected']:.1f})  "
                  f"distinct designs {row['distinct_designs_mean']:.1f} of {2**n}  {row['wall_s']:.1f} s", flush=True)
        evaluator.close()
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"ga": asdict(defaults), "fe": args.fe, "rows": rows}, fh, indent=1)


if __name__ == "__main__":
    main()

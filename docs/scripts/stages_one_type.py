"""The best design of one unit type for a staged target, by the chain of a library's table (docs/stages.md).

Scores every design whose letters are all of one type (both orientations: 2^n designs) with the
chain model of a library's table, and solves the best one by 3D FE (through the evaluation
cache): what a one-type actuator can do against the same stages as the library's certified
winner.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python docs/scripts/stages_one_type.py \\
        --library examples/libraries/units-bending-bimodal.toml \\
        --table examples/libraries/chain-3d-bending-bimodal-40kpa-far.json \\
        --stage "16:y = 0.0015*x**2" --stage "40:y = -0.002*x**2" --type a
"""

from __future__ import annotations

import argparse
import itertools
import time

import numpy as np

from pneumorph.design.objectives.fitness import score, stage_values
from pneumorph.design.objectives.targets import make_objective, staged_target
from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator, default_cache_path
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.factory import make_model


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", required=True)
    parser.add_argument("--table", required=True)
    parser.add_argument("--stage", action="append", required=True, help="KPA:PROFILE, e.g. '16:y = 0.001*x**2'")
    parser.add_argument("--type", default="a", help="the one unit type's symbol")
    parser.add_argument("--units", type=int, default=15)
    parser.add_argument("--cache", default=str(default_cache_path()))
    args = parser.parse_args()
    table = ChainTable.load(args.table)
    chain = ChainModel(table, args.units)
    stages = []
    for text in args.stage:
        kpa, _, target = text.partition(":")
        stages.append((float(kpa) / 1e3, make_objective(target.strip())))
    staged = staged_target(stages)
    levels = staged.levels(table.pressures)
    t0 = time.perf_counter()
    best = (np.inf, "")
    for letters in itertools.product((args.type, args.type.upper()), repeat=args.units):
        design = "".join(letters)
        value = score(chain.evaluate(design), staged).values[max(levels)]
        if value < best[0]:
            best = (value, design)
    print(f"{2 ** args.units} designs of type {args.type!r} scored by the chain in {time.perf_counter() - t0:.1f} s: "
          f"best {best[1]} at {best[0]:.3f} mm")
    pressure_kpa = float(table.pressures[-1]) * 1e3
    model = make_model(args.units, {"fidelity": "3d", "pressure_kpa": pressure_kpa,
                                    "library": args.library})
    evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(args.cache))
    (outcome,) = evaluator.evaluate_many(model, [best[1]])
    evaluator.close()
    fe = stage_values(outcome.response, staged)
    print(f"3D FE of {best[1]}: stages {', '.join(f'{v:.3f}' for v in fe)} mm, cost "
          f"{score(outcome.response, staged).values[max(levels)]:.3f} mm ({outcome.wall_time:.1f} s)")


if __name__ == "__main__":
    main()

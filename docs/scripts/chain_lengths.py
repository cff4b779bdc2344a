"""How well a shipped chain table (fitted on 15-unit designs) predicts actuators of other lengths.

Solves random designs (seeded) of each length with the FE model and compares the unit
centres, tip and curl with the chain's prediction at every level; prints a markdown table.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python docs/scripts/chain_lengths.py --model 2d --lengths 6 8 25 30
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python docs/scripts/chain_lengths.py --model 3d --lengths 8 25 --designs 2
"""

from __future__ import annotations

import argparse

from pneumorph.execution import CachedEvaluator, EvaluationCache, ProcessPoolEvaluator, default_cache_path
from pneumorph.models.chain.fit import heldout_designs, prediction_errors
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import shipped_path
from pneumorph.models.factory import make_model


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", choices=["2d", "3d"], default="2d")
    parser.add_argument("--lengths", type=int, nargs="+", default=[6, 8, 25, 30])
    parser.add_argument("--designs", type=int, default=4)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--cache", default=str(default_cache_path()))
    args = parser.parse_args()
    table = ChainTable.load(shipped_path(args.model))
    evaluator = CachedEvaluator(ProcessPoolEvaluator(workers=2), EvaluationCache(args.cache))
    print("| units | designs | worst centre error, 45 kPa | mean centre error, 45 kPa | worst tip | worst curl |")
    print("|---|---|---|---|---|---|")
    for n in args.lengths:
        model = make_model(n, {"fidelity": args.model})
        ChainModel(table, n)  # refuses lengths the table cannot serve
        designs = heldout_designs(n, args.designs, seed=args.seed)
        responses = [o.response for o in evaluator.evaluate_many(model, designs) if o.ok]
        v = prediction_errors(table, responses)
        print(f"| {n} | {len(responses)} | {v['centre_worst_mm'][-1]:.3f} mm | {v['centre_mean_mm'][-1]:.3f} mm | "
              f"{v['tip_worst_mm'][-1]:.3f} mm | {v['curl_worst_deg'][-1]:.3f} deg |", flush=True)
    evaluator.close()


if __name__ == "__main__":
    main()

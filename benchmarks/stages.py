"""Staged targets in 3D: a design given back from curves through its own centres, and the wall time.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/stages.py [--design 001111010001001] [--workers 2]
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/stages.py --design aRRAArRRrararra \
        --library examples/libraries/units-bending-rigid.toml --table examples/libraries/chain-3d-bending-rigid-far.json

Solves the design by 3D FE, draws a curve through its unit centres at 18 and 45 kPa, and runs
the certified search over the two stages with the shipped 3D table (or a library's, with
``--library`` and ``--table``) and FE verification on a fresh in-memory cache, so the
search's wall time includes its verifications: the answer sought is the design back, or one
within 0.15 mm of both curves by FE.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

from pneumorph.design.certified.search import certified_search
from pneumorph.design.objectives.fitness import stage_values
from pneumorph.design.objectives.targets import make_objective, staged_target
from pneumorph.execution import CachedEvaluator, EvaluationCache, ProcessPoolEvaluator
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import shipped_path
from pneumorph.models.factory import make_model


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--design", default="001111010001001")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--library", help="a unit library file (the design over its symbols)")
    parser.add_argument("--table", help="the library's chain table (with --library)")
    args = parser.parse_args()
    print(f"# {platform.node()} {platform.machine()} python {platform.python_version()} numpy {np.__version__}")
    settings = {"fidelity": "3d", **({"library": args.library} if args.library else {})}
    model = make_model(len(args.design), settings)
    chain = ChainModel(ChainTable.load(args.table or shipped_path("3d")), len(args.design))
    with ProcessPoolEvaluator(workers=args.workers) as pool:
        t0 = time.perf_counter()
        (outcome,) = CachedEvaluator(pool, EvaluationCache(":memory:")).evaluate_many(model, [args.design])
        r = outcome.response
        print(f"{args.design} solved in {time.perf_counter() - t0:.1f} s")

        def through(k: int):  # type: ignore[no-untyped-def]
            pts = np.column_stack([r.centres[k, :, 0], r.centres[k, :, 1] - r.reference_centres[:, 1]])
            return make_objective("curve", curve=np.vstack([[0.0, 0.0], pts]))

        probe = staged_target([(0.018, make_objective("sin")), (0.045, make_objective("sin"))])
        staged = staged_target([(r.pressures[k], through(k)) for k in probe.levels(r.pressures)])
        t0 = time.perf_counter()
        result = certified_search(model, chain, staged, CachedEvaluator(pool, EvaluationCache(":memory:")),
                                  certify=True)
        wall = time.perf_counter() - t0
    c = result.certificate
    each = stage_values(result.winner.response, staged)
    print(f"certified search over 2 stages: {wall:.1f} s wall, winner {result.winner.design} "
          f"(given back: {result.winner.design == args.design}), FE cost {result.winner.value:.4f} mm, stages "
          f"{', '.join(f'{v:.4f}' for v in each)} mm, certified {c['certified']}, {len(c['verified'])} verified "
          f"by FE, bound {c['bound']:.4f} mm")


if __name__ == "__main__":
    main()

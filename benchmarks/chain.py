"""Speed of the chain model and the certified search.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/chain.py score      # all 2^n designs, n = 15, 20
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/chain.py search     # chain part of the search, n = 15, 30
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/chain.py search --table T.json --units 15  # a library's table
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/chain.py build      # 2D table from a fresh cache
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/chain.py search30   # n = 30 with 2D FE verification
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/chain.py stages     # two stages, n = 15 (every design) and 30

``score`` times scoring every design with the shipped 3D table (best of 5, CPU time);
``search`` the part of the certified search before FE verification (enumeration or
branch-and-bound and the bounds) for the targets of chapter 6; ``build`` fits and validates
the 2D table of the built-in unit from a fresh in-memory cache (two worker processes);
``search30`` runs a whole certified search of a 30-unit actuator on the 2D model (table of
15-unit designs, FE verification of the winner, serial). Targets: scoring 2^15 designs
<= 0.1 s; certified search for 30 units <= 10 s.
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np

from pneumorph.design import make_objective
from pneumorph.design.certified.search import certified_search, chain_errors, chain_scores, grow_designs
from pneumorph.errors import SearchConfigError
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import shipped_path

TARGETS = [("sin", 10.0), ("sin", 20.0), ("cos", 40.0), ("max-x", 10.0), ("max-y", 10.0), ("min-distance", 10.0)]


def best_of(fn, repeat: int = 5) -> float:  # type: ignore[no-untyped-def]
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return min(times)


def score() -> None:
    table = ChainTable.load(shipped_path("3d"))
    for n in (15, 20):
        chain = ChainModel(table, n)
        for spec, a in TARGETS[:1] + TARGETS[3:5]:
            objective = make_objective(spec, amplitude=a)
            errors = chain_errors(chain)
            t = best_of(lambda c=chain, o=objective, e=errors: grow_designs(c, o, e), 5 if n == 15 else 2)
            print(f"score all 2^{n} = {2**n:,} designs, {spec}: {t:.3f} s CPU")


def search(tables: list[str], units: list[int]) -> None:
    for src in tables or ["3d", "2d"]:
        table = ChainTable.load(shipped_path(src) if src in ("2d", "3d") else src)
        name = src if src in ("2d", "3d") else "+".join(table.alphabet) or src
        for n in units:
            chain = ChainModel(table, n)
            for spec, a in TARGETS:
                objective = make_objective(spec, amplitude=a, length=chain.length if spec in ("sin", "cos") else None)
                t0 = time.process_time()
                try:
                    s = chain_scores(chain, objective)
                except SearchConfigError as exc:
                    print(f"{name} n = {n}, {spec} A = {a:g}: refused after {time.process_time() - t0:.1f} s CPU: "
                          f"{exc}", flush=True)
                    continue
                t = time.process_time() - t0
                best = table.texts(s.bits[s.order()[:1]])[0]
                print(f"{name} n = {n}, {spec} A = {a:g}: {t:.2f} s CPU, {len(s.cost):,} designs kept"
                      f"{'' if s.complete else ' (branch-and-bound)'}, best {best} {abs(float(s.cost.min())):.4g}",
                      flush=True)


def build() -> None:
    from pneumorph.execution import CachedEvaluator, EvaluationCache, ProcessPoolEvaluator
    from pneumorph.models.chain.fit import build_table
    from pneumorph.models.fe import Reduced2D

    evaluator = CachedEvaluator(ProcessPoolEvaluator(workers=2), EvaluationCache(":memory:"))
    t0 = time.perf_counter()
    table = build_table(Reduced2D(15), evaluator)
    print(f"2D table: window +-{table.window}, {evaluator.solves} FE solves, {time.perf_counter() - t0:.1f} s wall, "
          f"worst held-out centre error {max(table.validation['centre_worst_mm']):.4f} mm")
    evaluator.close()


def search30() -> None:
    from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
    from pneumorph.models.fe import Reduced2D

    table = ChainTable.load(shipped_path("2d"))
    for spec, a in (("sin", 10.0), ("cos", 20.0)):
        evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
        t0 = time.perf_counter()
        r = certified_search(Reduced2D(30), ChainModel(table, 30), make_objective(spec, amplitude=a), evaluator,
                             certify=True)
        c = r.certificate
        print(f"n = 30, {spec} A = {a:g}: {time.perf_counter() - t0:.1f} s wall, {c['designs_scored']:,} designs kept, "
              f"winner {r.winner.design} {r.winner.value:.3f} mm (chain {r.hall_of_fame[0].value:.3f}), "
              f"{len(c['verified'])} verified, certified {c['certified']}, gap {c['gap']:.3f}")


def stages() -> None:
    from pneumorph.design.objectives.targets import staged_target

    for n in (15, 30):
        for src in ("3d", "2d"):
            chain = ChainModel(ChainTable.load(shipped_path(src)), n)
            staged = staged_target([(0.018, make_objective("curve", curve=[[0, 0], [80, 2], [160, 5]])),
                                    (0.045, make_objective("sin", amplitude=10.0, length=chain.length))])
            t = best_of(lambda c=chain, o=staged: chain_scores(c, o), 3)
            s = chain_scores(chain, staged)
            o = s.order()
            beats = int((s.optimistic < s.cost[o[0]]).sum()) - 1
            print(f"{src} n = {n}, stages (curve at 18 kPa, sin A = 10 at 45 kPa): {t:.2f} s CPU, {len(s.cost):,} "
                  f"designs kept{'' if s.complete else ' (branch-and-bound)'}, best "
                  f"{chain.table.texts(s.bits[o[:1]])[0]} {s.cost[o[0]]:.4g} mm, bound {s.bound[o[0]]:.3g} mm, "
                  f"{beats} other design(s) within it")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=["score", "search", "build", "search30", "stages"])
    parser.add_argument("--table", action="append", default=[], help="search: a table file or 2d/3d (repeatable)")
    parser.add_argument("--units", type=int, nargs="+", default=[15, 30], help="search: actuator lengths")
    args = parser.parse_args()
    print(f"# {platform.node()} {platform.machine()} python {platform.python_version()} numpy {np.__version__}")
    if args.what == "search":
        search(args.table, args.units)
    else:
        {"score": score, "build": build, "search30": search30, "stages": stages}[args.what]()


if __name__ == "__main__":
    main()

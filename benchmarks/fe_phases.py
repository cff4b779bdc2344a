"""Where one ``pneumorph simulate --model 3d`` process spends its time, phase by phase.

Runs the command in this process (as the console script does) and splits its CPU time into
the imports of the command line, the model's set-up (mesh, FE objects, the fast system's
pattern, up to the first Newton iteration; with the first imports of FElupe and MKL), the
solve of every reported level (Newton iterations, factorisations, residual evaluations, cut-backs, CPU) and the
writing (response, VTK series, shape figure). One thread, as a search worker runs:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/fe_phases.py -o 011100110010010
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/fe_phases.py -o 000000000000000 --no-write

CPU times (``time.process_time``) are given beside wall times: on a shared machine they are
the better measure. ``--repeat N`` solves the design N times in the process (the second and
later solves show what the set-up caches save).
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import tempfile
import time

T0 = (time.perf_counter(), time.process_time())


def clocks() -> tuple[float, float]:
    return time.perf_counter(), time.process_time()


def since(start: tuple[float, float]) -> str:
    wall, cpu = clocks()
    return f"{cpu - start[1]:6.2f} s CPU ({wall - start[0]:6.2f} s wall)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--orientation", default="011100110010010")
    parser.add_argument("--pressure", type=float, default=45.0, help="kPa")
    parser.add_argument("--repeat", type=int, default=1, help="solves of the design in this process")
    parser.add_argument("--no-write", action="store_true", help="solve only (no response, VTK or figure)")
    args = parser.parse_args()

    start = clocks()
    from pneumorph.cli import main as cli_main  # noqa: F401  (the console script's import)
    command = importlib.import_module("pneumorph.cli.simulate")

    print(f"imports of the command line: {since(start)}")
    from pneumorph.fem.fast.newton import FastSubstep
    from pneumorph.fem.fast.system import SolidSystem3D

    # (wall, cpu, iterations, factorisations, failed, residuals so far) per call
    levels: list[tuple[float, float, int, int, int, int]] = []
    starts: list[tuple[float, float]] = []  # the first substep's start
    original = FastSubstep.__call__
    residuals = [0]  # residual evaluations of the 3D system
    residual = SolidSystem3D.residual

    def counted(self, *a, **k):
        residuals[0] += 1
        return residual(self, *a, **k)

    def traced(self, fields, settings, border=None):
        if not starts:
            starts.append(clocks())
            residuals[0] = 0
        iterations, cause = original(self, fields, settings, border)
        wall, cpu = clocks()
        levels.append((wall, cpu, iterations, self.factorisations, int(cause is not None), residuals[0]))
        return iterations, cause

    SolidSystem3D.residual = counted
    FastSubstep.__call__ = traced
    writers: dict[str, float] = {}

    def timed(module: object, name: str) -> None:
        function = getattr(module, name)

        def wrapper(*a, **k):
            c0 = time.process_time()
            try:
                return function(*a, **k)
            finally:
                writers[name] = writers.get(name, 0.0) + time.process_time() - c0

        setattr(module, name, wrapper)

    import pneumorph.io
    import pneumorph.plot.shape

    timed(pneumorph.io, "write_vtk_series")
    timed(pneumorph.plot.shape, "plot_shape")
    from pneumorph.models.fe.base import FEModel

    solve = FEModel.solve
    marks: list[tuple[float, float]] = []

    def solve_traced(self, design, on_level=None):
        marks.append(clocks())
        levels.clear()
        starts.clear()
        levels_at: list[tuple[int, tuple[float, float]]] = []

        def seen(k: int, p: float) -> None:
            levels_at.append((len(levels), clocks()))
            if on_level is not None:
                on_level(k, p)

        solution = solve(self, design, on_level=seen)
        begin = starts[0] if starts else marks[-1]
        print(f"  set-up (mesh, FE objects, fast system): {begin[1] - marks[-1][1]:.2f} s CPU "
              f"({begin[0] - marks[-1][0]:.2f} s wall)")
        report(begin, levels, levels_at)
        return solution

    FEModel.solve = solve_traced
    print(f"threads: OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}, "
          f"MKL_NUM_THREADS={os.environ.get('MKL_NUM_THREADS', 'unset')}; load {os.getloadavg()[0]:.2f}")
    for run in range(args.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            argv = ["-o", args.orientation, "--model", "3d", "--pressure", str(args.pressure)]
            if not args.no_write:
                argv += ["--out", os.path.join(tmp, "out")]
            writers.clear()
            run_start = clocks()
            command.simulate.main(argv, standalone_mode=False)
            print(f"run {run + 1}: the command {since(run_start)}; writing: "
                  + ", ".join(f"{k} {v:.2f} s CPU" for k, v in writers.items()))
    print(f"whole process: {since(T0)} (interpreter start not included)")
    sys.stdout.flush()


def report(begin: tuple[float, float], calls: list[tuple[float, float, int, int, int, int]],
           levels_at: list[tuple[int, tuple[float, float]]]) -> None:
    """The set-up (to the first substep's start) and every level's iterations, factorisations, residual
    evaluations, cut-backs, CPU."""
    print("  level  iterations  factorisations  residuals  cut-backs  CPU (s)  wall (s)")
    previous_calls, previous = 0, begin
    factorised = evaluated = 0
    for k, (ncalls, at) in enumerate(levels_at):
        here = calls[previous_calls:ncalls]
        iterations = sum(c[2] for c in here)
        factors = here[-1][3] - factorised if here else 0
        factorised = here[-1][3] if here else factorised
        count = here[-1][5] - evaluated if here else 0
        evaluated = here[-1][5] if here else evaluated
        cut = sum(c[4] for c in here)
        print(f"  {k + 1:5d}  {iterations:10d}  {factors:14d}  {count:9d}  {cut:9d}  {at[1] - previous[1]:7.2f}  "
              f"{at[0] - previous[0]:8.2f}")
        previous_calls, previous = ncalls, at
    total = sum(c[2] for c in calls)
    print(f"  total  {total:10d}  {factorised:14d}  {evaluated:9d}  {sum(c[4] for c in calls):9d}  "
          f"{previous[1] - begin[1]:7.2f}  {previous[0] - begin[0]:8.2f}  ")


if __name__ == "__main__":
    main()

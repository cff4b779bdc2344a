"""What a volume-controlled ramp (``simulate --volume-change``) costs against the pressure ramp of the same model.

Solves one 2D design in this process with its pressure ramp, then with volume control to each
relative volume change given, for each body material, and prints the CPU time
(``time.process_time``: on a shared machine the better measure), Newton iterations, substeps and
cut-backs of each, and the volume ramp's CPU time over the pressure ramp's. One thread:

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 nice python benchmarks/volume_ramp.py \\
        --material mold_star_15 dragon_skin_10_medium ecoflex_00_30 --volume-change 0.5 1

``--pressure 20 45 --volume-change`` (no volume) times the pressure ramps alone, to each end pressure.

A body much softer than its stiff layer balloons past a pressure maximum, where the volume ramp
needs many cut-backs; the plan of ``simulate --volume-change`` is estimated from these figures
(:func:`pneumorph.models.chain.plan.volume_ramp_factor`); a pressure ramp that creeps to its limit point
costs what :data:`pneumorph.models.chain.plan.LIMIT_POINT` says.
"""

from __future__ import annotations

import argparse
import time

from pneumorph.models import make_model


def solve(design: str, material: str, volume: float | None, pressure: float = 45.0) -> tuple[float, dict]:
    settings: dict = {"fidelity": "2d", "pressure_kpa": pressure, "unit": {"body_material": material}}
    if volume is not None:
        settings["volume_change"] = volume
    model = make_model(len(design), settings)
    start = time.process_time()
    try:
        response = model.evaluate(design)
        meta = dict(response.metadata)
    except Exception as exc:  # a failed ramp is a figure too (the pressure ramp of a ballooning body)
        meta = {"failed": str(exc)[:80]}
    return time.process_time() - start, meta


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--orientation", default="0110")
    parser.add_argument("--material", nargs="+", default=["mold_star_15", "ecoflex_00_30"])
    parser.add_argument("--volume-change", nargs="*", type=float, default=[0.5, 1.0])
    parser.add_argument("--pressure", nargs="+", type=float, default=[45.0],
                        help="end pressures of the pressure ramps (kPa); a soft body stops at its limit point")
    args = parser.parse_args()
    solve(args.orientation, "mold_star_15", None)  # the first solve in a process pays the imports
    base, _ = solve(args.orientation, "mold_star_15", None)  # the built-in unit's pressure ramp: SOLVE_SECONDS's
    print("| body material | ramp | CPU (s) | Newton iterations | substeps | cut-backs | x built-in pressure ramp |")
    print("|---|---|---|---|---|---|---|")
    for material in args.material:
        rows = [(f"{p:g} kPa", *solve(args.orientation, material, None, p)) for p in args.pressure]
        rows += [(f"{v:g} V0", *solve(args.orientation, material, v)) for v in args.volume_change]
        for what, cpu, meta in rows:
            counts = " | ".join(str(meta.get(k, "-")) for k in ("newton_iterations", "substeps", "cutbacks"))
            failed = f" ({meta['failed']})" if "failed" in meta else ""
            print(f"| {material} | {what}{failed} | {cpu:.2f} | {counts} | {cpu / base:.1f} |", flush=True)


if __name__ == "__main__":
    main()

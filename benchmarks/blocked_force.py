"""Blocked force of some designs, and what contact costs against the free solve.

For each design: the free ramp, then the blocked-force ramp (``simulate --blocked``: a wall
normal to the free tip's motion at the first level, through the end face's farthest point,
touching the end face), or with ``--cylinder X,Y[,Z];R`` a cylinder against the whole surface
(``--cylinder "tip;R"``: centred where the free tip ends; ``--cylinder "path:P:D;R"``: in the tip's way, centred
``D`` mm beyond the free tip at ``P`` kPa along the free tip's chord from there to the top pressure, so its
surface is ``D - R`` mm beyond that tip), with Coulomb ``--friction``.
Prints a Markdown table row per design: the wall and CPU times (on a shared machine the CPU time
is what compares), Newton iterations, factorisations and cut-backs of both ramps, and the force on
the obstacle at the middle and last levels.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/blocked_force.py --model 3d --designs 00000,01010,00011
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/blocked_force.py --designs 111000000111111 --cylinder "tip;4"
    OMP_NUM_THREADS=1 python benchmarks/blocked_force.py --designs 000 --cylinder "34,24;4" --friction 0.5
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/blocked_force.py --designs 001111010001001 \
        --cylinder "path:22.5:5;4" --friction 0.5
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from pneumorph.models import make_model
from pneumorph.models.fe.obstacles import blocked_obstacle
from pneumorph.models.response import Response


def cylinder_centre(place: str, free: Response) -> list[float]:
    """The centre of ``--cylinder``'s ``X,Y[,Z]``, ``tip`` (the free tip at the top pressure) or ``path:P:D``
    (``D`` mm beyond the free tip at ``P`` kPa, along its chord to the top pressure)."""
    if place == "tip":
        return [float(v) for v in free.tip[-1]]
    if not place.startswith("path:"):
        return [float(v) for v in place.split(",")]
    _, pressure, distance = place.split(":")
    level = int(np.argmin(np.abs(free.pressures * 1e3 - float(pressure))))
    if not np.isclose(free.pressures[level] * 1e3, float(pressure)):
        raise SystemExit(f"--cylinder path: {pressure} kPa is no level of the ramp "
                         f"({', '.join(f'{p * 1e3:g}' for p in free.pressures)} kPa)")
    way = free.tip[-1] - free.tip[level]
    return [float(v) for v in free.tip[level] + float(distance) * way / np.linalg.norm(way)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="3d", choices=["2d", "3d"])
    parser.add_argument("--designs", default="00000,01010,00011")
    parser.add_argument("--cylinder", default=None, help="X,Y[,Z];R, tip;R or path:P:D;R: a cylinder (along z in "
                        "3D) instead of the wall, centred there, where the free tip ends, or D mm beyond the free tip "
                        "at P kPa on its way to the top pressure")
    parser.add_argument("--friction", type=float, default=0.0, help="Coulomb's coefficient on the obstacle")
    args = parser.parse_args()
    print("| design | free: wall (CPU), iterations, factorisations, cut-backs | with contact: wall (CPU), iterations, "
          "factorisations, cut-backs | force at mid / last level (N) | base reaction at last level (N) |")
    print("|---|---|---|---|---|")
    for design in args.designs.split(","):
        model = make_model(len(design), {"fidelity": args.model})
        t0, c0 = time.perf_counter(), time.process_time()
        free = model.solve(design).response
        t_free, c_free = time.perf_counter() - t0, time.process_time() - c0
        t0, c0 = time.perf_counter(), time.process_time()
        if args.cylinder is None:
            obstacle = blocked_obstacle(model, design)
        else:
            centre, radius = args.cylinder.split(";")
            where = cylinder_centre(centre, free)
            if args.model == "3d" and len(where) == 2:  # across the width, on the half model's mid-plane
                where.append(model.unit.width / 2)
            obstacle = {"kind": "cylinder", "centre": where, "radius": float(radius)}
            if args.model == "3d":
                obstacle["axis"] = [0.0, 0.0, 1.0]
        if args.friction > 0.0:
            obstacle["friction"] = args.friction
        contact = model.variant(obstacles=[obstacle]).solve(design).response
        t_contact, c_contact = time.perf_counter() - t0, time.process_time() - c0
        levels = contact.metadata["contact"]["levels"]
        mid, last = levels[len(levels) // 2 - 1], levels[-1]
        m, f = contact.metadata, free.metadata
        print(f"| `{design}` | {t_free:.1f} s ({c_free:.1f} s CPU), {f['newton_iterations']}, {f['factorisations']}, "
              f"{f['cutbacks']} | {t_contact:.1f} s ({c_contact:.1f} s CPU), {m['newton_iterations']}, "
              f"{m['factorisations']}, {m['cutbacks']} | "
              f"{mid['obstacles'][0]['force_magnitude_n']:.3f} at "
              f"{mid['pressure_kpa']:.1f} kPa / {last['obstacles'][0]['force_magnitude_n']:.3f} | "
              f"{np.linalg.norm(last['base_reaction_n']):.3f} |", flush=True)


if __name__ == "__main__":
    main()

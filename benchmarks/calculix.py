"""pneumorph's 3D model against CalculiX on the same deck: tip difference and time ratio.

    OMP_NUM_THREADS=2 MKL_NUM_THREADS=2 python benchmarks/calculix.py
    python benchmarks/calculix.py --design 0101 --pressure 20 --levels 10 --threads 1

Solves one design (default: the 15-unit benchmark design ``001111010001001`` at 45 kPa in
the model's 10 levels) with :class:`pneumorph.models.fe.Full3D` (fast backend), writes the
same model as a CalculiX deck (:mod:`pneumorph.export.calculix`), runs ``ccx`` on it, and
prints, per level, both tip displacements and their relative difference, then the wall
times and their ratio. If CalculiX stops before the full pressure, the levels it reached
are compared and its time is the time to its stop.

``ccx`` gets ``--threads`` threads (default: the environment's ``OMP_NUM_THREADS``, else
2); pneumorph's solver follows ``OMP_NUM_THREADS`` and ``MKL_NUM_THREADS``, so set them to
the same number. The difference is expected from the volumetric terms (CalculiX's
``(J-1)^2/D1`` against Eq 2.12's ``9/2 K (J^(1/3)-1)^2``): about 5 % at 20 kPa, CalculiX
the stiffer. ``--bulk-factor 100`` multiplies both silicones' bulk moduli in both codes,
so that the two volumetric terms nearly coincide and what remains is any other
difference between the deck and the model.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

from pneumorph.errors import SimulationFailed
from pneumorph.export.calculix import calculix_mesh
from pneumorph.export.ccx import read_dat_displacements, run_calculix, tip_positions
from pneumorph.fem import StepSettings
from pneumorph.models.fe import Full3D, RampSpec


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--design", default="001111010001001")
    parser.add_argument("--pressure", type=float, default=45.0, help="kPa (default 45)")
    parser.add_argument("--levels", type=int, default=10, help="reported levels (default 10)")
    parser.add_argument("--threads", type=int, default=int(os.environ.get("OMP_NUM_THREADS", "2")))
    parser.add_argument("--out", default=None, help="folder for the deck and CalculiX's files (default: temporary)")
    parser.add_argument("--timeout", type=float, default=3600.0, help="seconds allowed for ccx")
    parser.add_argument("--residual-force", type=float, default=1e-4,
                        help="CalculiX's residual criterion in N (default 1e-4, see pneumorph.export.calculix)")
    parser.add_argument("--bulk-factor", type=float, default=1.0,
                        help="multiply both silicones' bulk moduli in both codes (100: the two volumetric terms "
                             "nearly coincide, which isolates the rest of the deck)")
    args = parser.parse_args()

    design = args.design
    steps = StepSettings(increments=args.levels, substeps=1, max_iterations=25)
    model = Full3D(len(design), ramp_spec=RampSpec(pressure=args.pressure / 1e3, steps=steps))
    if args.bulk_factor != 1.0:
        for role in ("body", "layer"):
            material = getattr(model, role)
            bulk = dataclasses.replace(material.bulk_modulus, value=material.bulk_modulus.value * args.bulk_factor)
            setattr(model, role, dataclasses.replace(material, bulk_modulus=bulk))
    mesh = calculix_mesh(model, design)
    print(f"design {design}: {len(design)} units, {len(mesh.points):,} nodes, {len(mesh.cells):,} C3D20 elements, "
          f"{args.pressure:g} kPa in {args.levels} levels, bulk moduli x{args.bulk_factor:g}, CalculiX residual "
          f"{args.residual_force:g} N")
    env = {key: os.environ.get(key) for key in ("OMP_NUM_THREADS", "MKL_NUM_THREADS")}
    print(f"ccx threads {args.threads}, {env}, {platform.node()}, {os.cpu_count()} CPUs")

    t0 = time.perf_counter()
    ours = model.evaluate(design)
    t_ours = time.perf_counter() - t0
    print(f"pneumorph: {t_ours:.1f} s wall, {ours.metadata['newton_iterations']} Newton iterations")

    folder = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="pneumorph-ccx-"))
    t1 = time.perf_counter()
    try:
        theirs = run_calculix(model, design, folder, threads=args.threads, timeout=args.timeout,
                              residual_force=args.residual_force)
        times, tip, t_theirs = theirs.pressures / model.ramp.pressure, theirs.tip, theirs.wall_time_s
        print(f"CalculiX: {t_theirs:.1f} s wall ({theirs.deck})")
    except SimulationFailed as exc:
        # compare the levels it reached (the .dat file holds each converged level)
        t_theirs = time.perf_counter() - t1
        times, tip = tip_positions(read_dat_displacements(folder / f"design_{design}.dat"), mesh)
        print(f"CalculiX stopped after {t_theirs:.1f} s wall: {exc} ({folder})")
        if not times.size:
            raise SystemExit(1) from None
    k = np.rint(times * args.levels).astype(int) - 1  # the levels CalculiX reported
    x0 = mesh.points[mesh.end_points][:, :2].mean(axis=0)
    u_ours, u_theirs = ours.tip[k] - x0, tip - x0
    n_ours, n_theirs = np.linalg.norm(u_ours, axis=1), np.linalg.norm(u_theirs, axis=1)
    print(f"{'kPa':>6} {'|u| pneumorph':>14} {'|u| CalculiX':>13} {'rel. diff':>10} {'|du|/|u|':>9}  (mm, %)")
    for p, a, b, ua, ub in zip(ours.pressures[k] * 1e3, n_ours, n_theirs, u_ours, u_theirs, strict=False):
        print(f"{p:6.1f} {a:14.4f} {b:13.4f} {100 * (b - a) / a:+10.2f} {100 * np.linalg.norm(ub - ua) / a:9.2f}")
    last = ours.pressures[k[-1]] * 1e3
    distance = np.linalg.norm(u_theirs[-1] - u_ours[-1])
    print(f"tip at {last:g} kPa: pneumorph {np.round(ours.tip[k[-1]], 3).tolist()} mm, "
          f"CalculiX {np.round(tip[-1], 3).tolist()} mm, {distance:.3f} mm apart; pneumorph curl "
          f"{ours.curl[k[-1]]:.1f} deg")
    ratio = t_theirs / t_ours
    print(f"time: pneumorph {t_ours:.1f} s (to {ours.pressures[-1] * 1e3:g} kPa), CalculiX {t_theirs:.1f} s "
          f"(to {last:g} kPa), ratio CalculiX/pneumorph {ratio:.1f}")

if __name__ == "__main__":
    main()

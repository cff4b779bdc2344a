"""Build and solve one actuator of the unit-geometry study; print and save the curl.

Examples (from this folder)::

    python solve.py --dim 3 --units 3 --cavity-height 6 --end-wall 3          # screening
    python solve.py --dim 3 --orientation 000000000000000 --cavity-height 6 --end-wall 3 \
        --out results/final_all0.json
    python solve.py --dim 2 --units 15 --cavity-height 6 --end-wall 3 --filler

Writes a JSON file (geometry, solver settings, per-increment pressure / iterations / wall
time / curl / unit rotations / unit centres / ballooning) and, with ``--save-u``, the final
displacement field as ``.npz`` next to it.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from dataclasses import asdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402
import unit_model as um  # noqa: E402


def parse(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dim", type=int, choices=(2, 3), default=3)
    ap.add_argument("--units", type=int, default=15, help="number of units (all orientation 0)")
    ap.add_argument("--orientation", default=None, help="orientation string, e.g. 0101 (overrides --units)")
    ap.add_argument("--pitch", type=float, default=10.5)
    ap.add_argument("--width", type=float, default=15.0)
    ap.add_argument("--wall", type=float, default=1.5)
    ap.add_argument("--layer", type=float, default=3.0)
    ap.add_argument("--cavity-height", type=float, default=6.0)
    ap.add_argument("--end-wall", type=float, default=3.0)
    ap.add_argument("--slit-width", type=float, default=0.0)
    ap.add_argument("--slit-depth", type=float, default=0.0)
    ap.add_argument("--medium", type=float, default=0.0, help="third-medium shear modulus in the slit, MPa")
    ap.add_argument("--tip-cap", type=float, default=0.0)
    ap.add_argument("--element-size", type=float, default=1.5)
    ap.add_argument("--full-width", action="store_true", help="3D: mesh the whole width (no symmetry plane)")
    ap.add_argument("--filler", action="store_true", help="2D: Eq 5.2 filler in the cavities")
    ap.add_argument("--material-model", choices=("ogden", "neohooke"), default="ogden")
    ap.add_argument("--pressure", type=float, default=45.0, help="final pressure, kPa")
    ap.add_argument("--first-step", type=float, default=0.05)
    ap.add_argument("--max-step", type=float, default=0.1)
    ap.add_argument("--out", default=None, help="JSON result file")
    ap.add_argument("--save-u", action="store_true")
    return ap.parse_args(argv)


def main(argv=None):
    a = parse(argv)
    orientation = a.orientation or "0" * a.units
    g = um.UnitGeometry(pitch=a.pitch, width=a.width, wall=a.wall, layer=a.layer,
                        cavity_height=a.cavity_height, end_wall=a.end_wall,
                        slit_width=a.slit_width, slit_depth=a.slit_depth, medium=a.medium,
                        tip_cap=a.tip_cap, element_size=a.element_size)
    t0 = time.perf_counter()
    am = um.build_mesh(g, orientation, dim=a.dim, half=not a.full_width, filler=a.filler)
    model = um.ActuatorModel(am, model=a.material_model)
    t_build = time.perf_counter() - t0
    print(f"orientation={orientation} dim={a.dim} H={g.height} Lc={g.cavity_length} "
          f"cells={am.mesh.ncells} points={am.mesh.npoints} dofs={model.ndof} "
          f"pressure faces={model.walls.mesh.ncells} build={t_build:.1f}s "
          f"solver={'pypardiso' if um.pypardiso else 'scipy spsolve'}", flush=True)
    s = um.SolverSettings(p_max=a.pressure / 1e3, first_step=a.first_step, max_step=a.max_step)
    res = um.solve(model, s)
    last = res.increments[-1] if res.increments else None
    print(f"RESULT converged={res.converged} p={res.pressure_reached_kpa:.2f} kPa "
          f"curl={last.curl_deg if last else float('nan'):.2f} deg "
          f"newton_iterations={res.newton_iterations} cutbacks={res.cutbacks} "
          f"wall={res.wall_time:.1f}s dofs={res.dofs}", flush=True)
    if a.out:
        out = Path(a.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        data = {
            "command": "python " + " ".join([Path(sys.argv[0]).name] + (argv or sys.argv[1:])),
            "geometry": um.geometry_dict(g),
            "orientation": orientation,
            "dim": a.dim,
            "half_width_model": am.half,
            "filler": a.filler,
            "material_model": a.material_model,
            "solver": asdict(s) | {"linear_solver": "pypardiso" if um.pypardiso else "scipy"},
            "mesh": {"cells": int(am.mesh.ncells), "points": int(am.mesh.npoints),
                     "dofs": int(res.dofs), "cell_type": am.mesh.cell_type},
            "converged": res.converged,
            "pressure_reached_kpa": res.pressure_reached_kpa,
            "newton_iterations": res.newton_iterations,
            "cutbacks": res.cutbacks,
            "wall_time_s": res.wall_time,
            "build_time_s": t_build,
            "python": platform.python_version(),
            "increments": [asdict(i) for i in res.increments],
        }
        out.write_text(json.dumps(data, indent=1))
        if a.save_u:
            np.savez_compressed(out.with_suffix(".npz"), u=res.u)
    return 0 if res.converged else 1


if __name__ == "__main__":
    raise SystemExit(main())

"""Mesh refinement of the 3D model (Table 4.1 analogue) and of the 2D filler law (Fig 5.5).

3D: an 8-unit actuator with all units aligned, inflated to the final pressure, with linear
hexahedra of 1.5, 0.75 and 0.5 mm and quadratic hexahedra of 1.5 mm (section 4.6): tip
displacement, curl, unknowns and solve time. 2D (``--filler``): the filler law calibrated
with 1.5 mm and with 0.75 mm quad8 meshes (one run each, fewer levels) against the same 3D
reference on the default 3D mesh, compared.

    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/mesh_refinement.py [--unit U.toml] [--units 8]
    OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 python benchmarks/mesh_refinement.py --filler --units 4

Long: minutes (3D 0.5 mm linear mesh) to hours; results go to docs/ with the machine.
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace

import numpy as np

from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, RampSpec


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--unit", help="unit TOML file (default: the built-in unit)")
    parser.add_argument("--units", type=int, default=8)
    parser.add_argument("--pressure", type=float, default=45.0, help="kPa")
    parser.add_argument("--filler", action="store_true", help="the 2D filler-law study instead")
    parser.add_argument("--json", help="write the results to this file")
    args = parser.parse_args()
    unit = UnitSpec.from_toml(args.unit) if args.unit else UnitSpec()
    rows = []
    if args.filler:
        from pneumorph.calibration import calibrate

        references: dict[str, object] = {}

        def solve_3d(model, design):  # type: ignore[no-untyped-def]
            # the 3D reference keeps the default mesh (hex20, 1.5 mm): only the 2D mesh changes
            if design not in references:
                references[design] = Full3D(model.n_units, unit, model.ramp).evaluate(design)
            return references[design]

        for h in (1.5, 0.75):
            t0 = time.perf_counter()
            cal = calibrate(replace(unit, element_size=h), args.units, (10, 20, 30, 40), runs=1, seed=0,
                            solve_3d=solve_3d)
            fit = cal.quadratic if cal.quadratic.coefficients else cal.linear
            rows.append({"element_size": h, "coefficients": list(fit.coefficients), "r_squared": fit.r_squared,
                         "points": [(p.pressure * 1e3, p.modulus) for p in cal.points],
                         "wall_time_s": time.perf_counter() - t0})
            print(rows[-1], flush=True)
    else:
        ramp = RampSpec(pressure=args.pressure / 1e3)
        for order, h in ((1, 1.5), (2, 1.5), (1, 0.75), (1, 0.5)):
            model = Full3D(args.units, replace(unit, element_order=order, element_size=h), ramp)
            t0 = time.perf_counter()
            try:
                r = model.evaluate("0" * args.units)
                tip = float(np.hypot(*(r.tip[-1] - r.reference_tip)))
                row = {"element": f"{'hex8' if order == 1 else 'hex20'} {h} mm", "dofs": r.metadata["dofs"],
                       "tip_displacement_mm": tip, "curl_deg": float(r.curl[-1]),
                       "newton_iterations": r.metadata["newton_iterations"]}
            except Exception as exc:  # report and go on with the next mesh
                row = {"element": f"{'hex8' if order == 1 else 'hex20'} {h} mm", "failed": str(exc)}
            row["wall_time_s"] = time.perf_counter() - t0
            rows.append(row)
            print(row, flush=True)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()

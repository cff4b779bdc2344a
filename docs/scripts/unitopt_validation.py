"""The unit optimisation's probe (3 aligned units, the 3D model's mesh) against larger and finer models.

For a few units (the built-in one and points of the front) prints Omega, h_b and the strain of
the probe, of a 15-unit actuator (Omega: its middle unit) and of the probe meshed at half the
element size, with the relative errors of the probe (docs/unit-library.md, "Optimised units").

    OMP_NUM_THREADS=1 nice -n 19 python docs/scripts/unitopt_validation.py
"""

from __future__ import annotations

import time
from dataclasses import replace

from pneumorph.geometry.unit import UnitSpec
from pneumorph.unitopt.probe import UnitProbe, measures_of

UNITS = {
    "built-in": UnitSpec(),
    "6.3/3.2/1.2/3.3": UnitSpec(cavity_height=6.3, end_wall=3.2, wall=1.2, layer=3.3),
    "4.6/3.1/2.4/3.8": UnitSpec(cavity_height=4.6, end_wall=3.1, wall=2.4, layer=3.8),
}


def main() -> None:
    print("unit (cavity/end wall/wall/layer)  model  Omega[deg]  h_b[mm]  strain  wall[s]")
    for label, unit in UNITS.items():
        rows = {}
        for name, probe in (("probe", UnitProbe(unit)), ("15 units", UnitProbe(unit, n_units=15)),
                            ("probe h/2", UnitProbe(replace(unit, element_size=unit.element_size / 2)))):
            t = time.perf_counter()
            m = measures_of(probe.evaluate(probe.design))
            rows[name] = m
            print(f"{label:<34} {name:<9} {m.omega_deg:9.2f} {m.balloon_mm:8.3f} {m.strain:7.3f} "
                  f"{time.perf_counter() - t:7.1f}", flush=True)
        p = rows["probe"]
        for name in ("15 units", "probe h/2"):
            r = rows[name]
            print(f"{'':<34} probe vs {name}: Omega {100 * (p.omega_deg / r.omega_deg - 1):+.1f} %, h_b "
                  f"{100 * (p.balloon_mm / r.balloon_mm - 1):+.1f} %, strain {100 * (p.strain / r.strain - 1):+.1f} %",
                  flush=True)


if __name__ == "__main__":
    main()

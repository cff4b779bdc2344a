"""Measure whether the chain's elements carry over to space: sideways designs solved by the full 3D model.

1. Twist: a planar unit bends about its frame's z axis only, wherever the frame points. After
   sideways units have turned the actuator out of the plane, the planar units' chords should
   still turn about z alone (no turn about y) if the frame transported without twist
   (:mod:`pneumorph.models.spacechords`) is the units' own frame.
2. Locality: a chord's twist-free turns and length, in two designs that share the units
   around it (+-2) and differ farther away, differ by what the chain would err.

Full 3D model, ``spatial`` library (a, l), 36 kPa; writes docs/figures/space-chords.json.

    OMP_NUM_THREADS=1 .venv/bin/python docs/scripts/space_chords.py
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from pneumorph.models.factory import make_model
from pneumorph.models.spacechords import space_elements

OUT = Path(__file__).resolve().parents[1] / "figures" / "space-chords.json"
PRESSURE = 36.0
# twist: sideways units first, then planar ones (both ways), against the planar design alone
TWIST = ("aaaaaaa", "lllaaaa", "LLLaaaa", "lLlaAaa", "aaaaAaa")
# locality: the same units around chord 4 (units 2-6 of 7), different units 1 and 7
PAIRS = (("aalAlaa", "lalAlaL"), ("aaLaaaa", "LaLaaal"), ("llaAall", "aLaAalA"))


def solve(design: str) -> tuple[np.ndarray, np.ndarray, float]:
    model = make_model(len(design), {"fidelity": "3d", "library": "spatial", "pressure_kpa": PRESSURE})
    t = time.perf_counter()
    r = model.solve(design).response
    points = r.centreline(-1)
    turns, lengths = space_elements(points)
    return turns, lengths, time.perf_counter() - t


def main() -> None:
    out: dict = {"pressure_kpa": PRESSURE, "twist": {}, "pairs": []}
    for design in TWIST:
        turns, lengths, seconds = solve(design)
        planar = [j for j in range(1, len(design)) if design[j - 1].lower() == "a" and design[j].lower() == "a"
                  and (j + 1 >= len(design) or design[j + 1].lower() == "a")]
        about_y = np.abs(turns[planar, 0]).max() if planar else float("nan")
        about_z = np.abs(turns[planar, 1]).max() if planar else float("nan")
        out["twist"][design] = {"turns_deg": np.degrees(turns).tolist(), "lengths_mm": lengths.tolist(),
                                "planar_chords": planar, "max_about_y_deg": float(np.degrees(about_y)),
                                "max_about_z_deg": float(np.degrees(about_z)), "seconds": seconds}
        print(f"{design}: planar chords {planar}: largest turn about y {np.degrees(about_y):.4f} deg, about z "
              f"{np.degrees(about_z):.3f} deg ({seconds:.0f} s)", flush=True)
    for a, b in PAIRS:
        (ta, la, _), (tb, lb, _) = solve(a), solve(b)
        j = 4  # chord 4 starts at unit 4's centre: units 2-6 around it
        d_turn = np.degrees(np.abs(ta[j] - tb[j])).tolist()
        d_len = float(abs(la[j] - lb[j]))
        out["pairs"].append({"designs": [a, b], "chord": j, "turn_difference_deg": d_turn,
                             "length_difference_mm": d_len, "turns_deg": [np.degrees(ta[j]).tolist(),
                                                                        np.degrees(tb[j]).tolist()]})
        print(f"{a} / {b}: chord {j} turns differ by {d_turn[0]:.4f}, {d_turn[1]:.4f} deg, length by {d_len:.4f} mm",
              flush=True)
    OUT.write_text(json.dumps({"command": "python docs/scripts/space_chords.py", **out}, indent=1))


if __name__ == "__main__":
    main()

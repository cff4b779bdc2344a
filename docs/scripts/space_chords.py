"""Measure whether the chain's elements carry over to space: sideways designs solved by the full 3D model.

1. Twist: a planar unit bends about its frame's z axis only, wherever the frame points. After
   sideways units have turned the actuator out of the plane, the planar units' chords should
   still turn about z alone (no turn about y) if the frame transported without twist
   (:mod:`pneumorph.models.chain.space`) is the units' own frame.
2. Locality: a chord's twist-free turns and length, in two designs that share the units
   around it (+-2) and differ farther away, differ by what the chain would err.

3. The units' own frames: each unit's rotation (the best fit of the motion of its nodes on
   the mid-width plane, Kabsch)
   against the frame transported along the chords: the twist about the chord at each unit.

Full 3D model, ``spatial`` library (a, l), 36 kPa; writes docs/figures/space-chords.json.

    OMP_NUM_THREADS=1 .venv/bin/python docs/scripts/space_chords.py
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from pneumorph.geometry.assembly import unit_starts
from pneumorph.models.chain.space import space_elements
from pneumorph.models.factory import make_model

OUT = Path(__file__).resolve().parents[1] / "figures" / "space-chords.json"
PRESSURE = 36.0
# twist: sideways units first, then planar ones (both ways), against the planar design alone
TWIST = ("aaaaaaa", "lllaaaa", "LLLaaaa", "lLlaAaa", "aaaaAaa")
# locality: the same units around chord 4 (units 2-6 of 7), different units 1 and 7
PAIRS = (("aalAlaa", "lalAlaL"), ("aaLaaaa", "LaLaaal"), ("llaAall", "alaAalA"))


def solve(design: str) -> tuple[np.ndarray, np.ndarray, float]:
    model = make_model(len(design), {"fidelity": "3d", "library": "spatial", "pressure_kpa": PRESSURE})
    t = time.perf_counter()
    r = model.solve(design).response
    points = r.centreline(-1)
    turns, lengths = space_elements(points)
    return turns, lengths, time.perf_counter() - t


def twists(design: str) -> list[float]:
    """Per unit, its frame's twist about the chord from it (deg): its rotated y axis against the transported one.

    The unit's rotation is the best fit of its nodes on the mid-width plane (the half model's symmetry plane; the
    side walls balloon, and a half model has one of them only)."""
    model = make_model(len(design), {"fidelity": "3d", "library": "spatial", "pressure_kpa": PRESSURE})
    solution = model.solve(design)
    mesh, u = solution.mesh, solution.displacements[-1]
    turns, _ = space_elements(solution.response.centreline(-1))
    frames = [np.eye(3)]
    for t in turns:  # the transported frame of each chord
        frames.append(frames[-1] @ Rotation.from_rotvec([0.0, *t]).as_matrix())
    starts = unit_starts(mesh.units)
    mid = np.isclose(mesh.points[:, 2], mesh.spec.width / 2)  # the mid-width plane: in the half model too
    out = []
    for i in range(len(design)):
        inside = (mesh.points[:, 0] >= starts[i]) & (mesh.points[:, 0] <= starts[i + 1]) & mid
        p = mesh.points[inside]
        q = p + u[inside]
        rotation, _ = Rotation.align_vectors(q - q.mean(axis=0), p - p.mean(axis=0))
        frame = frames[i + 2]  # chord i + 1 starts at unit i's centre (chord 0 at the base)
        y = rotation.as_matrix()[:, 1]
        y -= (y @ frame[:, 0]) * frame[:, 0]
        out.append(float(np.degrees(np.arctan2(y @ frame[:, 2], y @ frame[:, 1]))))
    return out


def main() -> None:
    out: dict = {"pressure_kpa": PRESSURE, "twist": {}, "pairs": []}
    for design in TWIST:
        turns, lengths, seconds = solve(design)
        # chord j (from unit j's centre, 1-based) turns with units j-2 .. j+2: all planar, far from a sideways one
        planar = [j for j in range(1, len(design) + 1) if all(c in "aA" for c in design[max(j - 3, 0):j + 2])]
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
    out["unit_twist_deg"] = {}
    for design in ("aaaaAaa", "lllaaaa", "aalAlaa", "lalAlaL"):
        out["unit_twist_deg"][design] = twists(design)
        print(f"{design}: twist of each unit's frame about its chord "
              f"{', '.join(f'{v:.2f}' for v in out['unit_twist_deg'][design])} deg", flush=True)
    OUT.write_text(json.dumps({"command": "python docs/scripts/space_chords.py", **out}, indent=1))


if __name__ == "__main__":
    main()

"""Measure whether the chain's elements in the units' own frames are local for sideways designs.

The twist-free elements are not (docs/scripts/space_chords.py: 0.3-0.4 deg about y from
units beyond +-2). Here each chord is written in the frame of the unit it starts from and
each unit's frame in the one before (:func:`pneumorph.models.chain.space.frame_elements`,
the frames from the full model's responses), for the same pairs of designs that share the
units +-2 around chord 4 and differ farther away. Writes docs/figures/space-frames.json.

    OMP_NUM_THREADS=1 .venv/bin/python docs/scripts/space_frames.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from pneumorph.models.chain.space import frame_elements, space_elements
from pneumorph.models.factory import make_model

OUT = Path(__file__).resolve().parents[1] / "figures" / "space-frames.json"
PRESSURE = 36.0
PAIRS = (("aalAlaa", "lalAlaL"), ("aaLaaaa", "LaLaaal"), ("llaAall", "alaAalA"))
CHORD = 4  # from unit 4's centre (1-based): units 2-6 around it are shared


def elements(design: str) -> dict[str, np.ndarray]:
    r = make_model(len(design), {"fidelity": "3d", "library": "spatial", "pressure_kpa": PRESSURE}).evaluate(design)
    assert r.frames is not None, "the full model keeps each unit's frame"
    points = r.centreline(-1)
    chords, turns = frame_elements(points, r.frames[-1])
    free, lengths = space_elements(points)
    return {"chord": chords[CHORD], "turn": turns[CHORD - 1], "free": free[CHORD], "length": lengths[CHORD]}


def main() -> None:
    rows = []
    for a, b in PAIRS:
        ea, eb = elements(a), elements(b)
        row = {"designs": [a, b], "chord": CHORD,
               "chord_difference_mm": float(np.abs(ea["chord"] - eb["chord"]).max()),
               "frame_turn_difference_deg": float(np.degrees(np.abs(ea["turn"] - eb["turn"]).max())),
               "twist_free_turn_difference_deg": float(np.degrees(np.abs(ea["free"] - eb["free"]).max())),
               "frame_turn_deg": [np.degrees(ea["turn"]).tolist(), np.degrees(eb["turn"]).tolist()]}
        rows.append(row)
        print(f"{a} / {b}: chord {CHORD} in its unit's frame differs by {row['chord_difference_mm']:.4f} mm, "
              f"the unit's frame in the one before by {row['frame_turn_difference_deg']:.4f} deg (twist-free turns: "
              f"{row['twist_free_turn_difference_deg']:.4f} deg)", flush=True)
    OUT.write_text(json.dumps({"command": "python docs/scripts/space_frames.py", "pressure_kpa": PRESSURE,
                               "pairs": rows}, indent=1))


if __name__ == "__main__":
    main()

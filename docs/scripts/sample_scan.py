"""Write the sample scan the README's `pneumorph correlate` example runs on.

A synthetic 3D scan: the 3D model's inflated surface of design 0110 (4 units) at 30 kPa,
1,500 surface nodes, moved by a known rotation and translation, with 0.05 mm Gaussian
noise, as an XYZ point cloud (mm). Seeded: the same file every time.

    .venv/bin/python docs/scripts/sample_scan.py    # -> examples/data/scan-0110-30kpa.xyz
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from pneumorph.correlation import Transform, model_shape
from pneumorph.models.factory import make_model

OUT = Path(__file__).resolve().parents[2] / "examples" / "data" / "scan-0110-30kpa.xyz"


def main() -> None:
    rng = np.random.default_rng(2026)
    shape = model_shape(make_model(4, {"fidelity": "3d", "pressure_kpa": 30.0}).solve("0110"))
    points = shape.surface[rng.choice(len(shape.surface), min(1500, len(shape.surface)), replace=False)]
    moved = Transform(Rotation.from_rotvec([0.2, -0.1, 0.3]).as_matrix(), np.array([12.0, -4.0, 3.0]))(points)
    noisy = moved + rng.normal(scale=0.05, size=moved.shape)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(OUT, noisy, fmt="%.4f")
    print(f"{OUT}: {len(noisy)} points")


if __name__ == "__main__":
    main()

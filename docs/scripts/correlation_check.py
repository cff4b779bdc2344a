"""Measure how well `pneumorph correlate` recovers a known alignment (docs/correlation.md).

A synthetic scan: the 3D model's own deformed surface (15 units, design 001111010001001,
45 kPa), moved by a known rotation and translation, with 0.05 mm Gaussian noise on 3000
points; and a photo trace of the 2D model's outline at 0.2 mm per pixel with 0.25 px noise
and a scale 3 % off. Prints the errors and draws docs/figures/correlation-synthetic.png.

    .venv/bin/python docs/scripts/correlation_check.py
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from pneumorph.correlation import Scan, Transform, correlate, model_shape, plot_correlation
from pneumorph.models.factory import make_model

DESIGN = "001111010001001"
SIGMA = 0.05
OUT = Path(__file__).resolve().parents[1] / "figures" / "correlation-synthetic.png"


def main() -> None:
    rng = np.random.default_rng(0)
    t0 = time.perf_counter()
    shape = model_shape(make_model(15, {"fidelity": "3d"}).solve(DESIGN))
    print(f"3D solve {time.perf_counter() - t0:.1f} s; surface {len(shape.surface)} nodes, "
          f"extent {shape.extent:.1f} mm")
    true = Transform(Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix(), np.array([5.0, -3.0, 7.0]))
    points = shape.surface[rng.choice(len(shape.surface), 3000, replace=False)]
    scan = Scan(true(points) + rng.normal(scale=SIGMA, size=points.shape), None, "synthetic 3D scan")
    t0 = time.perf_counter()
    result = correlate(scan, shape)
    back = true.then(result.alignment.transform)
    print(f"3D: rotation error {back.angle_deg:.4f} deg, translation error {np.linalg.norm(back.translation):.4f} mm, "
          f"surface RMS {result.surface.rms:.4f} mm (noise sigma*sqrt(3) = {SIGMA * 3 ** 0.5:.4f}), "
          f"outline RMS {result.outline.rms:.3f} max {result.outline.max:.3f} mm, "
          f"centreline RMS {result.centreline.rms:.3f} max {result.centreline.max:.3f} mm, "
          f"{time.perf_counter() - t0:.2f} s")

    flat = model_shape(make_model(15, {"fidelity": "2d"}).solve(DESIGN))
    outline = flat.samples[rng.choice(len(flat.samples), 1500, replace=False)]
    turn = Rotation.from_rotvec([0.0, 0.0, 0.4]).as_matrix()[:2, :2]
    pixels = (outline @ turn.T + [10.0, 4.0]) / 0.2 + rng.normal(scale=0.25, size=outline.shape)
    photo = correlate(Scan(pixels * 0.2 * 1.03, None, "synthetic photo trace"), flat, scale=True)
    t = photo.alignment.transform
    print(f"2D: scale {t.scale:.5f} (true {1 / 1.03:.5f}), angle {t.angle_deg:.4f} deg (true {np.degrees(0.4):.4f}), "
          f"outline RMS {photo.outline.rms:.4f} mm (tracing noise {0.25 * 0.2:.3f} mm per axis)")
    plot_correlation(result, shape, OUT)
    print(f"figure: {OUT}")


if __name__ == "__main__":
    main()

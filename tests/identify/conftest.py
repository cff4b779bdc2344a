"""Synthetic scans of small actuators with known changes (the model's own shape, moved, with noise)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from pneumorph.correlation import Scan, Transform, model_shape
from pneumorph.geometry.unit import UnitSpec
from pneumorph.identify import Observation, ParameterSet, ScanSpec
from pneumorph.models.factory import make_model

SIGMA = 0.05  # mm of noise per axis
PRESSURE = 36.0


def synthetic(params: ParameterSet, truth: np.ndarray, design: str, fidelity: str, seed: int,
              points: int = 1500, pressure_kpa: float = PRESSURE) -> Observation:
    """A scan of the model at ``truth``: its outline (2D) or surface nodes (3D), moved, with noise."""
    rng = np.random.default_rng(seed)
    shape = model_shape(make_model(len(design), params.settings(truth, {"fidelity": fidelity,
                                                                         "pressure_kpa": pressure_kpa})).solve(design))
    cloud = shape.samples if fidelity == "2d" else shape.surface
    chosen = cloud[rng.choice(len(cloud), min(points, len(cloud)), replace=False)]
    if fidelity == "2d":
        moved = Transform(Rotation.from_rotvec([0, 0, 0.4]).as_matrix()[:2, :2], np.array([10.0, 4.0]))
    else:
        moved = Transform(Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix(), np.array([5.0, -3.0, 7.0]))
    scan = Scan(moved(chosen) + rng.normal(scale=SIGMA, size=chosen.shape), None, f"synthetic {design}")
    return Observation(ScanSpec(f"synthetic-{design}.csv", design, pressure_kpa), scan)


@pytest.fixture(scope="session")
def coarse() -> ParameterSet:
    return ParameterSet(UnitSpec(element_size=3.0))

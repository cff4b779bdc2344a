"""Gravity on the actuator models: named test set-ups and acceleration vectors.

The models work in mm, N, tonne and s, so densities are in tonne/mm^3 and accelerations
in mm/s^2. Their axes: x along the actuator from its clamped base, y across its height,
z across its width. Appendix A.2.2 of the dissertation hangs the actuator from its clamped
base so that gravity acts along it ("hanging", +x); "horizontal" lays it out with gravity
across its height (-y).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

#: Standard gravity, mm/s^2.
STANDARD_GRAVITY = 9806.65
#: The largest acceleration a model accepts, mm/s^2 (100 g: far beyond any bench or centrifuge test of a soft actuator).
MAX_GRAVITY = 100 * STANDARD_GRAVITY

#: Unit directions of gravity in the models' axes for the named set-ups.
SETUPS: dict[str, tuple[float, float, float]] = {
    "hanging": (1.0, 0.0, 0.0),
    "horizontal": (0.0, -1.0, 0.0),
}


def gravity_vector(gravity: str | Sequence[float] | None, dim: int) -> tuple[float, ...] | None:
    """The acceleration of gravity (mm/s^2, ``dim`` components) for a set-up or a vector.

    Parameters
    ----------
    gravity : str, sequence of float or None
        A name of :data:`SETUPS` (standard gravity in that direction), an acceleration
        vector in mm/s^2 (2 or 3 components), or None / ``"none"`` for no gravity.
    dim : int
        2 for the plane-strain model (a z component must then be zero), 3 for the 3D one.

    Raises
    ------
    ValueError
        An unknown set-up, a vector of the wrong length or not finite, or a z component
        in a 2D model.

    Examples
    --------
    >>> gravity_vector("hanging", 2)
    (9806.65, 0.0)
    >>> gravity_vector([0.0, 0.0, -9806.65], 3)
    (0.0, 0.0, -9806.65)
    >>> gravity_vector("none", 3) is None
    True
    """
    if gravity is None or (isinstance(gravity, str) and gravity == "none"):
        return None
    if isinstance(gravity, str):
        if gravity not in SETUPS:
            raise ValueError(f"unknown gravity set-up {gravity!r}; choose one of {', '.join(SETUPS)}, 'none', "
                             "or give an acceleration vector in mm/s^2")
        g = STANDARD_GRAVITY * np.asarray(SETUPS[gravity], dtype=float)
    else:
        if any(isinstance(v, (bool, str, bytes)) for v in np.ravel(np.asarray(gravity, dtype=object))):
            raise ValueError(f"gravity must be 2 or 3 numbers in mm/s^2, got {gravity!r}")
        g = np.asarray(gravity, dtype=float).ravel()
        if g.size not in (2, 3) or not np.all(np.isfinite(g)):
            raise ValueError(f"gravity must be 2 or 3 finite components in mm/s^2, got {gravity!r}")
        if math.hypot(*g.tolist()) > MAX_GRAVITY:
            raise ValueError(f"gravity of {math.hypot(*g.tolist()):.4g} mm/s^2 is more than {MAX_GRAVITY:g} "
                             "(MAX_GRAVITY: 100 g)")
    if g.size == 3 and dim == 2:
        if g[2] != 0.0:
            raise ValueError(f"the plane-strain model has no z axis: gravity {g.tolist()} mm/s^2 has a z "
                             "component; use the 3D model")
        g = g[:2]
    if g.size == 2 and dim == 3:
        g = np.append(g, 0.0)
    if not np.any(g):
        return None
    return tuple(float(x) for x in g)

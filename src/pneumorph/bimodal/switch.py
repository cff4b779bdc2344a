"""Where a bimodal actuator reverses its bending direction (pure functions, plain data).

Two pressures describe the reversal of the tip's transverse displacement ``v(p)``:

- the *turning pressure*: the step at which ``|v|`` in the first bending direction is
  largest and after which it falls - from there on every pressure step moves the tip back;
- the *switch pressure*: where ``v`` changes sign, linearly interpolated between the two
  steps around it - above it the actuator bends the other way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class Switch:
    """Reversal of the bending direction along a pressure ramp (pressures in MPa).

    Attributes
    ----------
    first_direction : int
        +1 or -1, the sign of the transverse tip displacement at the first step (0: none).
    turning : float or None
        Pressure of the largest displacement in the first direction, if it falls after it.
    peak : float or None
        That largest displacement (mm).
    switch : float or None
        Pressure at which the displacement changes sign (None: not below the top pressure).
    """

    first_direction: int
    turning: float | None
    peak: float | None
    switch: float | None

    def to_dict(self) -> dict[str, Any]:
        def kpa(v: float | None) -> float | None:
            return None if v is None else round(1e3 * v, 4)

        return {
            "first_direction": self.first_direction,
            "turning_kpa": kpa(self.turning),
            "peak_mm": None if self.peak is None else round(self.peak, 4),
            "switch_kpa": kpa(self.switch),
        }


def find_switch(pressures: ArrayLike, transverse: ArrayLike) -> Switch:
    """Turning and switch pressures of a tip path.

    Parameters
    ----------
    pressures : array_like
        Increasing pressures of the converged steps (the unloaded state is implied).
    transverse : array_like
        Transverse tip displacement at those pressures.

    Examples
    --------
    >>> s = find_switch([5, 10, 15, 20], [1.0, 2.0, 1.0, -1.0])
    >>> s.first_direction, s.turning, s.peak, s.switch
    (1, 10.0, 2.0, 17.5)
    >>> find_switch([5, 10], [-1.0, -2.0]).switch is None
    True
    """
    p = np.asarray(pressures, dtype=float)
    v = np.asarray(transverse, dtype=float)
    if p.shape != v.shape or p.ndim != 1:
        raise ValueError(f"pressures and displacements must be 1D of equal length, got {p.shape} and {v.shape}")
    nonzero = np.flatnonzero(v != 0)
    if nonzero.size == 0:
        return Switch(0, None, None, None)
    sign = int(np.sign(v[nonzero[0]]))
    w = sign * v
    k = int(np.argmax(w))
    turning = float(p[k]) if k < len(w) - 1 and w[-1] < w[k] else None
    peak = float(v[k]) if turning is not None else None
    switch = None
    for i in range(nonzero[0], len(w) - 1):
        if w[i] > 0 and w[i + 1] <= 0:
            switch = float(p[i] + (p[i + 1] - p[i]) * w[i] / (w[i] - w[i + 1]))
            break
    return Switch(sign, turning, peak, switch)

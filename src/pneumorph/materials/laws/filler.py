"""The pressure-dependent filler law of the 2D reduced-order model (chapter 5).

The plane-strain model of the actuator fills each cavity with a fictitious isotropic
linear-elastic material whose modulus depends on the cavity pressure, so that the 2D
model bends like the 3D one. The dissertation fits (Eq 5.2, pressure in MPa)

    E(P) = 0.0643 - 1.82 P + 12.4 P^2   [MPa],

calibrated over 0-45 kPa. Outside that range the quadratic is not a model of anything (it
turns negative between about 59 and 88 kPa), so :meth:`FillerLaw.modulus` refuses it.

Examples
--------
>>> law = FillerLaw(name="eq5_2", display_name="Eq 5.2", coefficients=(0.0643, -1.82, 12.4),
...                 pressure_range=(0.0, 0.045), poisson_ratio=0.3)
>>> [round(float(e), 6) for e in law.modulus([0.0, 0.0225, 0.045])]
[0.0643, 0.029627, 0.00751]
>>> law.modulus(0.060)
Traceback (most recent call last):
    ...
pneumorph.errors.PressureRangeError: pressure 60 kPa is outside the calibrated range 0-45 kPa of the filler
law 'eq5_2'; recalibrate the law for this range instead of extrapolating
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.errors import MaterialDataError, PressureRangeError

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class FillerLaw:
    """A polynomial modulus law ``E(P) = sum_k c_k P^k`` with its calibrated range.

    Parameters
    ----------
    name : str
        Library key.
    display_name : str
        Human-readable name.
    coefficients : tuple of float
        ``c_0, c_1, ...`` in MPa, MPa^0 ... i.e. ``c_k`` in MPa^(1-k), for P in MPa.
    pressure_range : (float, float)
        Calibrated pressure range in MPa (lower >= 0).
    poisson_ratio : float
        Poisson's ratio of the filler, in (-1, 0.5).
    source, range_source : str
        Where the law and its range come from.
    poisson_ratio_source, poisson_ratio_assumed, poisson_ratio_reason
        Provenance of the Poisson's ratio.
    printed : tuple
        ``(coefficients, modulus_unit, pressure_unit)`` exactly as printed, if known.

    Raises
    ------
    MaterialDataError
        If the range is empty or negative, the Poisson's ratio is out of range, or the
        modulus is not positive everywhere inside the calibrated range.
    """

    name: str
    display_name: str
    coefficients: tuple[float, ...]
    pressure_range: tuple[float, float]
    poisson_ratio: float
    source: str = ""
    range_source: str | None = None
    poisson_ratio_source: str | None = None
    poisson_ratio_assumed: bool = False
    poisson_ratio_reason: str | None = None
    printed: tuple[tuple[float, ...], str, str] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "coefficients", tuple(float(c) for c in self.coefficients))
        lower, upper = (float(x) for x in self.pressure_range)
        object.__setattr__(self, "pressure_range", (lower, upper))
        if not self.coefficients or not all(math.isfinite(c) for c in self.coefficients):
            raise MaterialDataError(f"filler law {self.name!r}: coefficients must be finite numbers, "
                                    f"got {self.coefficients}")
        if not (0.0 <= lower < upper and math.isfinite(upper)):
            raise MaterialDataError(
                f"filler law {self.name!r}: calibrated range must satisfy 0 <= lower < upper, "
                f"got {lower * 1e3:g}-{upper * 1e3:g} kPa"
            )
        if not -1.0 < self.poisson_ratio < 0.5:
            raise MaterialDataError(
                f"filler law {self.name!r}: Poisson's ratio must lie in (-1, 0.5), got {self.poisson_ratio}"
            )
        p_min, e_min = self.minimum()
        if e_min <= 0.0:
            raise MaterialDataError(
                f"filler law {self.name!r}: modulus {e_min:.6g} MPa at {p_min * 1e3:.6g} kPa is not "
                f"positive inside the calibrated range {lower * 1e3:g}-{upper * 1e3:g} kPa"
            )

    def _polynomial(self, p: FloatArray) -> FloatArray:
        # numpy.polyval wants the highest power first
        return np.asarray(np.polyval(self.coefficients[::-1], p), dtype=float)

    def minimum(self) -> tuple[float, float]:
        """Smallest modulus inside the calibrated range: ``(pressure [MPa], E [MPa])``.

        Exact for any degree: the minimum of a polynomial on an interval is at an end or
        at a real root of its derivative.
        """
        lower, upper = self.pressure_range
        candidates = [lower, upper]
        if len(self.coefficients) > 2:
            derivative = np.polyder(np.array(self.coefficients[::-1]))
            for root in np.roots(derivative):
                if abs(root.imag) < 1e-12 and lower < root.real < upper:
                    candidates.append(float(root.real))
        values = self._polynomial(np.array(candidates))
        i = int(np.argmin(values))
        return candidates[i], float(values[i])

    @overload
    def modulus(self, pressure_mpa: float) -> float: ...

    @overload
    def modulus(self, pressure_mpa: ArrayLike) -> FloatArray | float: ...

    def modulus(self, pressure_mpa: ArrayLike) -> FloatArray | float:
        """Young's modulus of the filler at the given cavity pressure(s).

        Parameters
        ----------
        pressure_mpa : float or array_like
            Pressure in MPa (1 kPa = 0.001 MPa). Values within a relative 1e-9 of the range
            ends (rounding of load ramps) count as inside.

        Returns
        -------
        float or ndarray
            Modulus in MPa; a float for scalar input, else an array of the input's shape.

        Raises
        ------
        PressureRangeError
            If any pressure lies outside the calibrated range (the first offending value
            is named).
        ValueError
            If a pressure is not a finite number.
        """
        p = np.asarray(pressure_mpa, dtype=float)
        if not np.all(np.isfinite(p)):
            raise ValueError(f"pressure must be finite, got {pressure_mpa!r}")
        lower, upper = self.pressure_range
        tol = 1e-9 * (upper - lower)
        outside = (p < lower - tol) | (p > upper + tol)
        if np.any(outside):
            first = float(p[outside].flat[0]) if p.ndim else float(p)
            raise PressureRangeError(first, lower, upper, what=f"filler law {self.name!r}")
        e = self._polynomial(np.clip(p, lower, upper))
        return float(e) if p.ndim == 0 else e

    def umat(self, pressure_mpa: float) -> Any:
        """FElupe linear-elastic material at a fixed pressure (FElupe imported lazily)."""
        from pneumorph.materials.laws import felupe_models

        return felupe_models.build_linear_elastic(self.modulus(float(pressure_mpa)), self.poisson_ratio)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form for JSON."""
        out: dict[str, Any] = {
            "name": self.name,
            "display_name": self.display_name,
            "law": "E(P) = sum_k c_k P^k",
            "coefficients_internal": list(self.coefficients),
            "coefficients_internal_units": "c_k in MPa^(1-k), P in MPa",
            "calibrated_range_MPa": list(self.pressure_range),
            "calibrated_range_kPa": [x * 1e3 for x in self.pressure_range],
            "minimum_in_range": dict(zip(("pressure_MPa", "modulus_MPa"), self.minimum(), strict=False)),
            "source": self.source,
            "range_source": self.range_source,
            "poisson_ratio": {
                "value": self.poisson_ratio,
                "source": self.poisson_ratio_source,
                "assumed": self.poisson_ratio_assumed,
                "reason": self.poisson_ratio_reason,
            },
        }
        if self.printed is not None:
            coefficients, e_unit, p_unit = self.printed
            out["printed"] = {"coefficients": list(coefficients), "modulus_unit": e_unit, "pressure_unit": p_unit}
        return out

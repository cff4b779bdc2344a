"""A compressible Ogden matrix reinforced by crimped fibres: the paper in the silicone, in 3D.

The energy is the matrix's (Eq 2.12, :class:`~pneumorph.fem.ogden.OgdenCompressible`) plus
that of fibres along a unit vector ``a`` of the reference configuration, which carry
``primary`` (MPa; 0 for an ideal crimp, slack) of nominal stress per unit stretch until
their crimp has straightened at the stretch ``straight`` and then ``slope`` more
(:func:`~pneumorph.fem.fast.kernels.crimped_fibre_3d`, a quadratic blend of half-width
``blend`` joining the two). Pulled across the fibres the material is the matrix alone (with
``primary`` > 0, the matrix and the fibres' resistance to the contraction along them): it
stiffens along ``a`` and not across it.

The direction is a field: one unit vector for the whole material or one per element, so a
curved layer can carry its fibres along it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.fem.fast.kernels import crimped_fibre_3d
from pneumorph.fem.ogden import OgdenCompressible

FloatArray = NDArray[np.float64]


def straight_stretch(crimp_ratio: float) -> float:
    """Stretch at which a triangular crimp of ratio ``CR = A / lambda`` is straight: ``2 s / lambda``.

    A flute of the wave is ``s = sqrt((2A)^2 + (lambda/2)^2)`` long (Eq 3.1) over half a
    wavelength, so a crimp over the whole length straightens at ``2 s / lambda = sqrt(1 + 16 CR^2)``,
    whatever its amplitude (:func:`pneumorph.composite.crimp.limit_transition_strain` is this
    minus one).

    Examples
    --------
    >>> round(straight_stretch(0.2), 6)
    1.280625
    """
    return float(np.hypot(1.0, 4.0 * float(crimp_ratio)))


class CrimpedFibreOgden(OgdenCompressible):
    """Ogden matrix with crimped fibres along a direction per element (fast and FElupe paths).

    Parameters
    ----------
    mu, alpha, bulk, mixed
        The matrix, as :class:`~pneumorph.fem.ogden.OgdenCompressible` (no thermal stretch).
    direction : array_like, shape (3,) or (cells, 3)
        The fibres' direction, for all elements or per element (normalised here).
    straight : float
        Stretch along the fibres at which their crimp is straight (``1 + eps_transition``).
    slope : float
        Nominal stress of the straight fibres per unit stretch (MPa), smeared over the layer.
    blend : float
        Half-width of the slack-to-taut blend in stretch (default 0.02).
    primary : float
        Nominal stress per unit stretch of the fibres before they straighten (MPa; default 0,
        an ideal crimp), in tension and compression.

    Examples
    --------
    >>> import numpy as np
    >>> m = CrimpedFibreOgden([0.1], [2.0], 10.0, direction=[1.0, 0.0, 0.0], straight=1.3, slope=100.0)
    >>> F = np.diag([1.0, 1.5, 1.0])[..., None]          # across the fibres: the matrix alone
    >>> bool(np.allclose(m.kernel(F)[0], OgdenCompressible([0.1], [2.0], 10.0).kernel(F)[0]))
    True
    """

    def __init__(self, mu: Sequence[float], alpha: Sequence[float], bulk: float, direction: Any, straight: float,
                 slope: float, blend: float = 0.02, mixed: bool = False, primary: float = 0.0) -> None:
        super().__init__(mu, alpha, bulk, mixed=mixed)
        a = np.asarray(direction, dtype=float)
        if a.ndim not in (1, 2) or a.shape[-1] != 3:
            raise ValueError(f"the fibre direction must be a 3-vector or one per element (cells, 3), got {a.shape}")
        norm = np.linalg.norm(a, axis=-1, keepdims=True)
        if not np.all(np.isfinite(a)) or np.any(norm == 0):
            raise ValueError("the fibre direction must be finite and non-zero")
        if not (np.isfinite(blend) and blend > 0):
            raise ValueError(f"the blend must be positive, got {blend}")
        if not (np.isfinite(straight) and straight > 1.0 + blend):
            raise ValueError(f"the straightening stretch must exceed 1 + blend = {1 + blend:g}, got {straight}")
        if not (np.isfinite(slope) and slope >= 0 and np.isfinite(primary) and primary >= 0):
            raise ValueError(f"the fibre slopes must be non-negative numbers, got {slope} and {primary}")
        self.direction = (a / norm).reshape(-1, 3)
        self.straight, self.slope, self.blend = float(straight), float(slope), float(blend)
        self.primary = float(primary)
        self.kwargs = {**self.kwargs, "straight": self.straight, "slope": self.slope, "blend": self.blend,
                       "primary": self.primary}

    def directions(self, points: int) -> FloatArray:
        """The unit vectors at ``points`` points ordered by element, then point, as (3, points)."""
        per_cell = self.direction.shape[0]
        if per_cell == 1:
            return np.broadcast_to(self.direction.T, (3, points))
        if points % per_cell:
            raise ValueError(f"{per_cell} fibre directions do not divide {points} quadrature points")
        return np.repeat(self.direction.T, points // per_cell, axis=1)

    def kernel(self, F: FloatArray, tangent: bool = True, principal: tuple[FloatArray, FloatArray] | None = None,
               pairs: Sequence[tuple[int, int]] | None = None,
               volumetric: bool = True) -> tuple[FloatArray, FloatArray | None, FloatArray]:
        """The matrix's stress, tangent and ``det F`` (points ordered by element), with the fibres' added.

        >>> import numpy as np
        >>> m = CrimpedFibreOgden([0.1], [2.0], 10.0, [1.0, 0.0, 0.0], straight=1.3, slope=100.0)
        >>> F = np.diag([1.5, 1.0, 1.0])[..., None]
        >>> round(float(m.kernel(F)[0][0, 0, 0] - OgdenCompressible([0.1], [2.0], 10.0).kernel(F)[0][0, 0, 0]), 9)
        20.0
        """
        P, A, J = super().kernel(F, tangent, principal, pairs, volumetric)
        Pf, Af = crimped_fibre_3d(F, self.directions(F.shape[-1]), self.straight, self.slope, self.blend,
                                  tangent, pairs, self.primary)
        return P + Pf, None if A is None or Af is None else A + Af, J

    def _evaluate(self, F: FloatArray, tangent: bool) -> tuple[FloatArray, FloatArray | None]:
        """FElupe's ``(3, 3, q, c)`` layout, reordered by element (the directions' order) and back."""
        if F.ndim != 4:
            return super()._evaluate(F, tangent)
        q, c = F.shape[2:]
        P, A = super()._evaluate(np.ascontiguousarray(F.transpose(0, 1, 3, 2)).reshape(3, 3, c * q, 1), tangent)
        P = P.reshape(3, 3, c, q).transpose(0, 1, 3, 2)
        return P, None if A is None else A.reshape(3, 3, 3, 3, c, q).transpose(0, 1, 2, 3, 5, 4)


@dataclass(frozen=True)
class CastPaper:
    """The cast crimped paper of Table 3.2 as the fibres of a composite region (its matrix the region's material).

    The paper's numbers of :class:`CrimpedFibreOgden` for the library's Ecoflex 0030 matrix (bulk
    modulus 33.8 kPa), calibrated by :func:`pneumorph.bimodal.paper.calibrate_measured` so that the
    law pulled as the coupons were reads as Table 3.2; the fibres run along x, the actuator's
    long axis (a unit turned about it keeps them there).

    Attributes
    ----------
    crimp_ratio : float
    primary : float
        The paper's nominal stress per unit stretch before it is straight (MPa).
    straight : float
        The stretch at which it is straight.
    slope : float
        Its nominal stress per unit stretch once straight (MPa).
    blend : float
        Half-width of the slack-to-taut blend in stretch.

    Examples
    --------
    >>> law = CAST_PAPER["paper_0_2"].law([0.1], [2.0], 1.0)
    >>> law.direction.tolist(), round(law.straight, 6), law.slope
    ([[1.0, 0.0, 0.0]], 1.151974, 25.0157)
    """

    crimp_ratio: float
    primary: float
    straight: float
    slope: float
    blend: float = 0.02

    def law(self, mu: Sequence[float], alpha: Sequence[float], bulk: float, mixed: bool = False) -> CrimpedFibreOgden:
        """The matrix ``mu, alpha, bulk`` with this paper along x."""
        return CrimpedFibreOgden(mu, alpha, bulk, (1.0, 0.0, 0.0), self.straight, self.slope, self.blend, mixed=mixed,
                                 primary=self.primary)

    def to_dict(self) -> dict[str, float]:
        return asdict(self)


#: the cast composites by their material names (``paper_0_2``: Ecoflex 0030 with the paper of CR 0.2; the
#: library entries hold the matrix): :func:`pneumorph.bimodal.paper.calibrate_measured`'s paper for the
#: library's Ecoflex and a blend of 0.02
CAST_PAPER = {
    "paper_0_2": CastPaper(0.2, 0.148554, 1.151974, 25.0157),
    "paper_0_25": CastPaper(0.25, 0.0146595, 1.299745, 20.6591),
    "paper_0_3": CastPaper(0.3, 0.0122235, 1.355537, 16.4637),
}


__all__ = ["CAST_PAPER", "CastPaper", "CrimpedFibreOgden", "straight_stretch"]

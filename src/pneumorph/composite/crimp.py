"""Analytical transition strain of a triangular crimp (Ellis 2020, section 3.2.2).

A paper strain limiter folded into a triangular wave of amplitude ``A`` (peak-to-valley
``2A``) and wavelength ``lambda`` is embedded in a silicone slab of crimped length ``L0``.
The composite is soft until the paper has unfolded, then takes the paper's stiffness.
The strain at which that happens follows from the paper's unfolded length:

    s = sqrt((2A)^2 + (lambda/2)^2)          flute (side) length,      Eq 3.1
    N = (L0 - lambda/2) / lambda             number of flutes,          Eq 3.2
    L_e = 2 N s                              effective paper length,    Eq 3.3
    eps_transition = (L_e - L0) / L0                                    Eq 3.4

``N`` is used exactly as Eq 3.2 gives it (not rounded). For a crimp that runs over the
whole length the paper is ``L0 * 2 s / lambda`` long, the limit of Eq 3.4 for
``L0 >> lambda``: :func:`limit_transition_strain`.

Examples
--------
>>> c = Crimp.from_ratio(0.25, amplitude=1.5, length=176.25)
>>> round(c.wavelength, 6), round(c.flutes, 6)
(6.0, 28.875)
>>> round(100 * c.transition_strain, 2)
39.01
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from pneumorph.errors import CrimpError


def _check_positive(name: str, value: float, unit: str = "mm") -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise CrimpError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(x) or x <= 0.0:
        raise CrimpError(f"{name} must be a positive, finite length in {unit}, got {value!r}"
                         if unit else f"{name} must be positive and finite, got {value!r}")
    return x


def _check_crimp(amplitude: float, wavelength: float, length: float) -> tuple[float, float, float]:
    a = _check_positive("amplitude A", amplitude)
    lam = _check_positive("wavelength lambda", wavelength)
    l0 = _check_positive("crimped length L0", length)
    if lam > l0:
        raise CrimpError(
            f"wavelength {lam:g} mm is longer than the coupon (L0 = {l0:g} mm); "
            "a crimp needs at least one wavelength in the crimped length"
        )
    return a, lam, l0


def flute_length(amplitude: float, wavelength: float) -> float:
    """Side length of one flute, ``s = sqrt((2A)^2 + (lambda/2)^2)`` (Eq 3.1), in mm.

    Examples
    --------
    >>> flute_length(1.5, 8.0)
    5.0
    """
    a = _check_positive("amplitude A", amplitude)
    lam = _check_positive("wavelength lambda", wavelength)
    return math.hypot(2.0 * a, lam / 2.0)


def flute_count(length: float, wavelength: float) -> float:
    """Number of flutes ``N = (L0 - lambda/2) / lambda`` (Eq 3.2), not rounded.

    Examples
    --------
    >>> flute_count(176.25, 7.5)
    23.0
    """
    _, lam, l0 = _check_crimp(1.0, wavelength, length)
    return (l0 - lam / 2.0) / lam


def effective_length(amplitude: float, wavelength: float, length: float) -> float:
    """Unfolded length of the strain limiter, ``L_e = 2 N s`` (Eq 3.3), in mm.

    Examples
    --------
    >>> round(effective_length(1.5, 5.0, 176.25), 3)
    271.406
    """
    a, lam, l0 = _check_crimp(amplitude, wavelength, length)
    return 2.0 * flute_count(l0, lam) * flute_length(a, lam)


def transition_strain(amplitude: float, wavelength: float, length: float) -> float:
    """Strain at which the crimp has unfolded, ``(L_e - L0) / L0`` (Eq 3.4), a fraction.

    Raises
    ------
    CrimpError
        Non-positive or non-finite amplitude, wavelength or length, or a wavelength
        longer than the coupon.

    Examples
    --------
    >>> round(100 * transition_strain(1.5, 5.0, 176.25), 2)
    53.99
    """
    a, lam, l0 = _check_crimp(amplitude, wavelength, length)
    return (effective_length(a, lam, l0) - l0) / l0


def limit_transition_strain(amplitude: float, wavelength: float) -> float:
    """Transition strain of a crimp over the whole length, ``2 s / lambda - 1``.

    The limit of Eq 3.4 for ``L0 >> lambda``; also the exact value when the paper is
    crimped from end to end (as in the finite-element coupon).

    Examples
    --------
    >>> round(100 * limit_transition_strain(1.5, 7.5), 2)
    28.06
    """
    from pneumorph.fem.fibre import straight_stretch  # the crimp ratio's straightening stretch, 2 s / lambda

    a = _check_positive("amplitude A", amplitude)
    return straight_stretch(a / _check_positive("wavelength lambda", wavelength)) - 1.0


@dataclass(frozen=True)
class Crimp:
    """A triangular crimp of amplitude ``A`` and wavelength ``lambda`` in a coupon of length ``L0``.

    Parameters
    ----------
    amplitude : float
        ``A`` in mm: the paper runs between ``-A`` and ``+A`` (peak to valley ``2A``).
    wavelength : float
        ``lambda`` in mm (one peak and one valley).
    length : float
        Crimped length ``L0`` of the coupon in mm.

    Raises
    ------
    CrimpError
        A crimp that cannot exist: amplitude, wavelength or length not positive and
        finite, or a wavelength longer than the coupon.

    Examples
    --------
    >>> c = Crimp(amplitude=1.5, wavelength=5.0, length=176.25)
    >>> c.crimp_ratio
    0.3
    >>> round(100 * c.transition_strain, 1), round(100 * c.limit_transition_strain, 1)
    (54.0, 56.2)
    """

    amplitude: float
    wavelength: float
    length: float

    def __post_init__(self) -> None:
        a, lam, l0 = _check_crimp(self.amplitude, self.wavelength, self.length)
        object.__setattr__(self, "amplitude", a)
        object.__setattr__(self, "wavelength", lam)
        object.__setattr__(self, "length", l0)

    @classmethod
    def from_ratio(cls, crimp_ratio: float, amplitude: float, length: float) -> Crimp:
        """The crimp of ratio ``CR = A / lambda``: ``lambda = A / CR``.

        Examples
        --------
        >>> Crimp.from_ratio(0.2, amplitude=1.5, length=176.25).wavelength
        7.5
        """
        cr = _check_positive("crimp ratio CR", crimp_ratio, unit="")
        a = _check_positive("amplitude A", amplitude)
        return cls(amplitude=a, wavelength=a / cr, length=length)

    @property
    def crimp_ratio(self) -> float:
        """``CR = A / lambda``."""
        return self.amplitude / self.wavelength

    @property
    def flute_length(self) -> float:
        """``s`` (Eq 3.1), mm."""
        return flute_length(self.amplitude, self.wavelength)

    @property
    def flutes(self) -> float:
        """``N`` (Eq 3.2), not rounded."""
        return flute_count(self.length, self.wavelength)

    @property
    def effective_length(self) -> float:
        """``L_e`` (Eq 3.3), mm."""
        return effective_length(self.amplitude, self.wavelength, self.length)

    @property
    def transition_strain(self) -> float:
        """Eq 3.4, a fraction."""
        return transition_strain(self.amplitude, self.wavelength, self.length)

    @property
    def limit_transition_strain(self) -> float:
        """``2 s / lambda - 1``: the paper crimped over the whole length, a fraction."""
        return limit_transition_strain(self.amplitude, self.wavelength)

    def y(self, x: Any) -> Any:
        """Height of the paper's mid-line at axial position(s) ``x`` (mm).

        The wave starts on the mid-plane at ``x = 0`` rising, with peaks ``+A`` at
        ``lambda/4 + k lambda`` and valleys ``-A`` at ``3 lambda/4 + k lambda``.

        Examples
        --------
        >>> c = Crimp(1.5, 6.0, 60.0)
        >>> [float(c.y(x)) for x in (0.0, 1.5, 3.0, 4.5, 6.0)]
        [0.0, 1.5, 0.0, -1.5, 0.0]
        """
        import numpy as np

        phase = np.mod(np.asarray(x, dtype=float) / self.wavelength + 0.25, 1.0)
        return self.amplitude * (1.0 - 4.0 * np.abs(phase - 0.5))

    def to_dict(self) -> dict[str, float]:
        """Plain data: inputs and Eqs 3.1-3.4 (strains as fractions)."""
        return {
            "amplitude": self.amplitude,
            "wavelength": self.wavelength,
            "length": self.length,
            "crimp_ratio": self.crimp_ratio,
            "flute_length": self.flute_length,
            "flutes": self.flutes,
            "effective_length": self.effective_length,
            "transition_strain": self.transition_strain,
            "limit_transition_strain": self.limit_transition_strain,
        }

"""Closed-form incompressible hyperelastic models.

Every model is an immutable dataclass that gives, for principal stretches
``(l1, l2, l3)`` of an incompressible deformation, the principal *deviatoric Kirchhoff
stresses* ``tau_i = l_i dW/dl_i``. From these the nominal (first Piola-Kirchhoff,
engineering) stress of the three homogeneous test modes follows without any model-specific
algebra: with direction 3 traction free,

    P_1 = (tau_1 - tau_3) / l_1.

The three modes use the stretches

============  =====================================  ===============================
mode          stretches (l1, l2, l3)                 also called
============  =====================================  ===============================
uniaxial      (l, l^-1/2, l^-1/2)                     tension (l > 1), compression
equibiaxial   (l, l, l^-2)                            biaxial
planar        (l, 1, l^-1)                            pure shear
============  =====================================  ===============================

Strain-energy conventions
-------------------------
Ogden parameters are taken in the published (MSC Marc / Nastran) convention of the
dissertation, ``W = sum mu_n / alpha_n (l1^a + l2^a + l3^a - 3)`` (Eq 2.12), whose initial
shear modulus is ``mu0 = sum mu_n alpha_n / 2``. FElupe writes
``psi = sum 2 mu_i / alpha_i^2 (...)``; see :func:`ogden_marc_to_felupe`.

Examples
--------
>>> from pneumorph.materials.laws.hyperelastic import NeoHooke, Ogden
>>> NeoHooke(c10=0.5).uniaxial(2.0)  # 2 C10 (l - l^-2)
array(1.75)
>>> round(Ogden(mu=(-6.503e-6, 0.2169, 1.372e-3), alpha=(-21.32, 1.180, 4.884)).shear_modulus, 4)
0.1314
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph import checks

FloatArray = NDArray[np.float64]


def mode_stretches(mode: str, stretch: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Principal stretches of an incompressible homogeneous test mode.

    Parameters
    ----------
    mode : {"uniaxial", "equibiaxial", "planar"}
        The loading mode.
    stretch : array_like
        The stretch ``l`` in the loaded direction (``l < 1`` is compression).

    Returns
    -------
    l1, l2, l3 : ndarray
        Principal stretches with ``l1 l2 l3 = 1``; direction 3 is traction free.

    Examples
    --------
    >>> [float(x) for x in mode_stretches("equibiaxial", 2.0)]
    [2.0, 2.0, 0.25]
    """
    lam = np.asarray(stretch, dtype=float)
    if mode == "uniaxial":
        return lam, lam**-0.5, lam**-0.5
    if mode == "equibiaxial":
        return lam, lam, lam**-2.0
    if mode == "planar":
        return lam, np.ones_like(lam), 1.0 / lam
    raise ValueError(f"unknown loading mode {mode!r}; expected one of {', '.join(checks.MODES)}")


@runtime_checkable
class HyperelasticModel(Protocol):
    """What every closed-form model provides (see :class:`_Base` for the mode stresses)."""

    kind: ClassVar[str]

    @property
    def shear_modulus(self) -> float: ...

    @property
    def parameters(self) -> dict[str, float]: ...

    def energy(self, l1: ArrayLike, l2: ArrayLike, l3: ArrayLike) -> FloatArray: ...

    def uniaxial(self, stretch: ArrayLike) -> FloatArray: ...

    def kirchhoff(
        self, l1: ArrayLike, l2: ArrayLike, l3: ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray]: ...

    def nominal_stress(self, mode: str, stretch: ArrayLike) -> FloatArray: ...


class _Base:
    """Mode stresses shared by all models; subclasses define ``energy`` and ``kirchhoff``."""

    kind: ClassVar[str] = ""

    def energy(self, l1: ArrayLike, l2: ArrayLike, l3: ArrayLike) -> FloatArray:
        raise NotImplementedError  # pragma: no cover

    def kirchhoff(
        self, l1: ArrayLike, l2: ArrayLike, l3: ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        raise NotImplementedError  # pragma: no cover

    def nominal_stress(self, mode: str, stretch: ArrayLike) -> FloatArray:
        """Nominal (engineering) stress in the loaded direction of ``mode``.

        Parameters
        ----------
        mode : {"uniaxial", "equibiaxial", "planar"}
            Loading mode.
        stretch : array_like
            Stretch in the loaded direction.

        Returns
        -------
        ndarray
            Force per undeformed area, in the units of the model parameters.
        """
        l1, l2, l3 = mode_stretches(mode, stretch)
        t1, _, t3 = self.kirchhoff(l1, l2, l3)
        return np.asarray((t1 - t3) / l1, dtype=float)

    def uniaxial(self, stretch: ArrayLike) -> FloatArray:
        """Nominal stress in uniaxial tension (``l > 1``) or compression (``l < 1``)."""
        return self.nominal_stress("uniaxial", stretch)

    def equibiaxial(self, stretch: ArrayLike) -> FloatArray:
        """Nominal stress in equibiaxial tension."""
        return self.nominal_stress("equibiaxial", stretch)

    def planar(self, stretch: ArrayLike) -> FloatArray:
        """Nominal stress in planar tension (pure shear)."""
        return self.nominal_stress("planar", stretch)


class _InvariantBase(_Base):
    """Models written in the invariants ``I1, I2`` of an incompressible deformation."""

    def derivatives(self, i1: FloatArray, i2: FloatArray) -> tuple[FloatArray, FloatArray]:
        """``(dW/dI1, dW/dI2)``."""
        raise NotImplementedError  # pragma: no cover

    def energy_invariants(self, i1: FloatArray, i2: FloatArray) -> FloatArray:
        raise NotImplementedError  # pragma: no cover

    @staticmethod
    def _invariants(
        l1: ArrayLike, l2: ArrayLike, l3: ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
        a, b, c = (np.asarray(x, dtype=float) ** 2 for x in (l1, l2, l3))
        return a + b + c, a * b + b * c + c * a, a, b, c

    def energy(self, l1: ArrayLike, l2: ArrayLike, l3: ArrayLike) -> FloatArray:
        i1, i2, *_ = self._invariants(l1, l2, l3)
        return self.energy_invariants(i1, i2)

    def kirchhoff(
        self, l1: ArrayLike, l2: ArrayLike, l3: ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        # l_i dW/dl_i = 2 W1 l_i^2 + 2 W2 l_i^2 (I1 - l_i^2)
        i1, i2, a, b, c = self._invariants(l1, l2, l3)
        w1, w2 = self.derivatives(i1, i2)
        return tuple(2.0 * w1 * s + 2.0 * w2 * s * (i1 - s) for s in (a, b, c))  # type: ignore[return-value]


@dataclass(frozen=True)
class NeoHooke(_InvariantBase):
    """Neo-Hookean model ``W = C10 (I1 - 3)`` (Eq 2.7); ``mu0 = 2 C10``.

    Examples
    --------
    >>> NeoHooke(c10=0.25).shear_modulus
    0.5
    """

    c10: float
    kind: ClassVar[str] = "neo-hooke"

    @property
    def shear_modulus(self) -> float:
        return 2.0 * self.c10

    @property
    def parameters(self) -> dict[str, float]:
        return {"C10": self.c10}

    def energy_invariants(self, i1: FloatArray, i2: FloatArray) -> FloatArray:
        return self.c10 * (i1 - 3.0)

    def derivatives(self, i1: FloatArray, i2: FloatArray) -> tuple[FloatArray, FloatArray]:
        return np.full_like(i1, self.c10), np.zeros_like(i2)


@dataclass(frozen=True)
class MooneyRivlin(_InvariantBase):
    """Mooney-Rivlin model, two- or three-term (Eqs 2.9, 2.10).

    ``W = C10 (I1 - 3) + C01 (I2 - 3) + C11 (I1 - 3)(I2 - 3)``; ``mu0 = 2 (C10 + C01)``.
    With ``c11 = 0`` (the default) it is the two-term model.

    Examples
    --------
    >>> MooneyRivlin(c10=0.2, c01=0.05).shear_modulus
    0.5
    """

    c10: float
    c01: float
    c11: float = 0.0
    kind: ClassVar[str] = "mooney-rivlin"

    @property
    def shear_modulus(self) -> float:
        return 2.0 * (self.c10 + self.c01)

    @property
    def parameters(self) -> dict[str, float]:
        return {"C10": self.c10, "C01": self.c01, "C11": self.c11}

    def energy_invariants(self, i1: FloatArray, i2: FloatArray) -> FloatArray:
        return self.c10 * (i1 - 3) + self.c01 * (i2 - 3) + self.c11 * (i1 - 3) * (i2 - 3)

    def derivatives(self, i1: FloatArray, i2: FloatArray) -> tuple[FloatArray, FloatArray]:
        return self.c10 + self.c11 * (i2 - 3.0), self.c01 + self.c11 * (i1 - 3.0)


@dataclass(frozen=True)
class Yeoh(_InvariantBase):
    """Generalised Yeoh model ``W = sum_i C_i (I1 - 3)^i`` (Eq 2.11); ``mu0 = 2 C_1``.

    Examples
    --------
    >>> Yeoh(c=(0.1, -0.001, 1e-4)).shear_modulus
    0.2
    """

    c: tuple[float, ...]
    kind: ClassVar[str] = "yeoh"

    def __post_init__(self) -> None:
        object.__setattr__(self, "c", tuple(float(x) for x in self.c))
        if not self.c:
            raise ValueError("Yeoh needs at least one coefficient")

    @property
    def shear_modulus(self) -> float:
        return 2.0 * self.c[0]

    @property
    def parameters(self) -> dict[str, float]:
        return {f"C{i + 1}0": v for i, v in enumerate(self.c)}

    def energy_invariants(self, i1: FloatArray, i2: FloatArray) -> FloatArray:
        x = i1 - 3.0
        return np.asarray(sum(ci * x ** (i + 1) for i, ci in enumerate(self.c)), dtype=float)

    def derivatives(self, i1: FloatArray, i2: FloatArray) -> tuple[FloatArray, FloatArray]:
        x = i1 - 3.0
        w1 = sum((i + 1) * ci * x**i for i, ci in enumerate(self.c))
        return np.asarray(w1 + 0.0 * x, dtype=float), np.zeros_like(i2)


@dataclass(frozen=True)
class Ogden(_Base):
    """Ogden model in the published (MSC Marc) convention (Eq 2.12, incompressible part).

    ``W = sum_n mu_n / alpha_n (l1^a_n + l2^a_n + l3^a_n - 3)``, ``mu0 = sum mu_n alpha_n / 2``.

    Parameters
    ----------
    mu : tuple of float
        Moduli ``mu_n`` (stress units, e.g. MPa), as printed in Table A.4 / B.1.
    alpha : tuple of float
        Exponents ``alpha_n`` (dimensionless, non-zero).

    Examples
    --------
    >>> m = Ogden(mu=(1.0,), alpha=(2.0,))   # equals neo-Hooke with C10 = 0.5
    >>> float(m.uniaxial(2.0)), float(NeoHooke(0.5).uniaxial(2.0))
    (1.75, 1.75)
    """

    mu: tuple[float, ...]
    alpha: tuple[float, ...]
    kind: ClassVar[str] = "ogden"

    def __post_init__(self) -> None:
        object.__setattr__(self, "mu", tuple(float(x) for x in self.mu))
        object.__setattr__(self, "alpha", tuple(float(x) for x in self.alpha))
        if len(self.mu) != len(self.alpha) or not self.mu:
            raise ValueError(
                f"Ogden needs as many mu as alpha (at least one); got {len(self.mu)} mu "
                f"and {len(self.alpha)} alpha"
            )
        if any(a == 0.0 for a in self.alpha):
            raise ValueError("Ogden exponents alpha must be non-zero")

    @property
    def terms(self) -> int:
        """Number of terms ``N``."""
        return len(self.mu)

    @property
    def shear_modulus(self) -> float:
        return float(sum(m * a for m, a in zip(self.mu, self.alpha, strict=False)) / 2.0)

    @property
    def parameters(self) -> dict[str, float]:
        out: dict[str, float] = {}
        for i, (m, a) in enumerate(zip(self.mu, self.alpha, strict=False), start=1):
            out[f"mu{i}"] = m
            out[f"alpha{i}"] = a
        return out

    def energy(self, l1: ArrayLike, l2: ArrayLike, l3: ArrayLike) -> FloatArray:
        s = (np.asarray(x, dtype=float) for x in (l1, l2, l3))
        a1, a2, a3 = s
        return np.asarray(
            sum(m / a * (a1**a + a2**a + a3**a - 3.0) for m, a in zip(self.mu, self.alpha, strict=False)),
            dtype=float,
        )

    def kirchhoff(
        self, l1: ArrayLike, l2: ArrayLike, l3: ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        out = []
        for s in (l1, l2, l3):
            s = np.asarray(s, dtype=float)
            out.append(np.asarray(sum(m * s**a for m, a in zip(self.mu, self.alpha, strict=False)), dtype=float))
        return out[0], out[1], out[2]


def ogden_marc_to_felupe(mu: tuple[float, ...], alpha: tuple[float, ...]) -> tuple[float, ...]:
    """Convert Ogden moduli from the published (Marc) to FElupe's convention.

    Marc: ``W = sum mu_n/alpha_n (...)``; FElupe: ``psi = sum 2 mu_i/alpha_i^2 (...)``,
    hence ``mu_felupe = mu_marc * alpha / 2`` (the exponents are the same).

    Examples
    --------
    >>> ogden_marc_to_felupe((0.2169,), (1.18,))
    (0.127971,)
    """
    return tuple(round(m * a / 2.0, 15) for m, a in zip(mu, alpha, strict=False))


@dataclass(frozen=True)
class StabilityReport:
    """Result of :func:`drucker_stability`.

    Attributes
    ----------
    stretch : ndarray
        The stretches checked (the same grid for every mode).
    stable : dict of str to ndarray of bool
        Per mode, whether the material is Drucker-stable at each stretch.
    """

    stretch: FloatArray
    stable: dict[str, NDArray[np.bool_]] = field(repr=False)

    @property
    def is_stable(self) -> bool:
        """True if every mode is stable over the whole range."""
        return all(bool(v.all()) for v in self.stable.values())

    def limits(self) -> dict[str, tuple[float, float]]:
        """Per mode, the interval of stretch around ``l = 1`` that is stable.

        Returns ``(lower, upper)``: the smallest and largest checked stretch reached from
        ``l = 1`` without passing an unstable point. A limit equal to the end of the
        checked range means no instability was found on that side.
        """
        out = {}
        lam = self.stretch
        i0 = int(np.argmin(abs(lam - 1.0)))
        for mode, ok in self.stable.items():
            hi = i0
            while hi + 1 < lam.size and ok[hi + 1]:
                hi += 1
            lo = i0
            while lo - 1 >= 0 and ok[lo - 1]:
                lo -= 1
            out[mode] = (float(lam[lo]), float(lam[hi]))
        return out

    def summary(self) -> str:
        """One line per mode saying where the model becomes unstable."""
        lines = []
        lam = self.stretch
        for mode, (lo, hi) in self.limits().items():
            parts = []
            if lo > lam[0]:
                parts.append(f"unstable below stretch {lo:.4g}")
            if hi < lam[-1]:
                parts.append(f"unstable above stretch {hi:.4g}")
            state = "; ".join(parts) if parts else "stable"
            lines.append(f"{mode}: {state} (checked {lam[0]:.3g}-{lam[-1]:.3g})")
        return "\n".join(lines)


def drucker_stability(
    model: HyperelasticModel,
    stretch_range: tuple[float, float] = (0.1, 10.0),
    num: int = 400,
) -> StabilityReport:
    """Check Drucker stability of an incompressible model along the three test modes.

    Drucker's postulate ``d tau : d eps > 0`` (Kirchhoff stress, logarithmic strain) for all
    isochoric strain increments holds if and only if the Hessian of
    ``w(e1, e2) = W(exp e1, exp e2, exp(-e1 - e2))`` is positive definite, because
    ``dw/de_i = tau_i - tau_3``. The Hessian is formed by central differences of the
    closed-form Kirchhoff stresses along each mode's stretch path.

    Parameters
    ----------
    model : HyperelasticModel
        Any closed-form model of this module.
    stretch_range : (float, float)
        Smallest and largest stretch of the loaded direction; compression (``l < 1``) is
        covered by the lower part of the range.
    num : int
        Number of geometrically spaced stretches.

    Returns
    -------
    StabilityReport

    Examples
    --------
    >>> drucker_stability(NeoHooke(0.5)).is_stable
    True
    >>> r = drucker_stability(MooneyRivlin(c10=0.3, c01=-0.1))
    >>> r.is_stable
    False
    """
    lo, hi = stretch_range
    if not (0 < lo < 1 < hi):
        raise ValueError(f"stretch_range must satisfy 0 < lower < 1 < upper, got {stretch_range}")
    lam = np.geomspace(lo, hi, num)
    lam = np.unique(np.concatenate([lam, [1.0]]))
    h = 1e-5
    stable: dict[str, NDArray[np.bool_]] = {}
    for mode in checks.MODES:
        l1, l2, _l3 = mode_stretches(mode, lam)
        e = np.stack([np.log(l1), np.log(l2)])

        def grad(e1: FloatArray, e2: FloatArray) -> FloatArray:
            t1, t2, t3 = model.kirchhoff(np.exp(e1), np.exp(e2), np.exp(-e1 - e2))
            return np.stack([t1 - t3, t2 - t3])

        hess = np.empty((2, 2, lam.size))
        for j in range(2):
            d = np.zeros((2, 1))
            d[j] = h
            hess[:, j] = (grad(*(e + d)) - grad(*(e - d))) / (2 * h)
        hess = 0.5 * (hess + hess.transpose(1, 0, 2))
        a, b, c = hess[0, 0], hess[0, 1], hess[1, 1]
        # 2x2 symmetric positive definite <=> a > 0 and det > 0
        scale = np.maximum(abs(a) + abs(c), 1e-300)
        stable[mode] = (a > 0) & ((a * c - b * b) > -1e-12 * scale**2)
    return StabilityReport(stretch=lam, stable=stable)

"""FElupe constitutive materials built from the closed-form models of :mod:`.hyperelastic`.

The strain-energy functions are written for tensortrax (automatic differentiation of a
function of the right Cauchy-Green tensor ``C``), in exactly the conventions of
Ellis (2020), Eqs 2.7-2.12, and wrapped in ``felupe.Hyperelastic``:

* the isochoric part uses the unimodular ``Cbar = J^(-2/3) C`` (``J = sqrt(det C)``), so
  ``Ibar1 = J^(-2/3) tr C``, ``Ibar2 = J^(-4/3) (tr(C)^2 - tr(C C)) / 2`` and the
  isochoric stretches ``lbar_i = J^(-1/3) l_i``;
* the volumetric part is the one of Eq 2.12, ``U(J) = 9/2 K (J^(1/3) - 1)^2``, whose
  small-strain bulk modulus is ``U''(1) = K``.

Ogden parameters are in the published (MSC Marc) convention,
``W = sum mu_n / alpha_n (lbar1^a_n + lbar2^a_n + lbar3^a_n - 3)``, not FElupe's
``2 mu / alpha^2``.

Examples
--------
>>> import numpy as np
>>> from pneumorph.materials.laws.hyperelastic import NeoHooke
>>> umat = build_umat(NeoHooke(c10=0.5), bulk_modulus=1000.0)
>>> F = np.diag([1.0, 1.0, 1.0]).reshape(3, 3, 1, 1)
>>> float(abs(umat.gradient([F, None])[0]).max())  # stress-free reference state
0.0
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, Literal

import felupe as fem
from tensortrax import Tensor
from tensortrax.math import sum as tsum
from tensortrax.math import trace
from tensortrax.math.linalg import det, eigvalsh

from pneumorph.errors import MaterialDataError, UnknownModelError
from pneumorph.materials.laws.hyperelastic import (
    HyperelasticModel,
    MooneyRivlin,
    NeoHooke,
    Ogden,
    Yeoh,
)

Formulation = Literal["compressible", "nearly-incompressible"]
FORMULATIONS: tuple[str, ...] = ("compressible", "nearly-incompressible")

#: Relative perturbation that tensortrax adds to ``C`` before its eigen-decomposition so
#: that repeated eigenvalues get distinct derivatives (see :func:`isochoric_function`).
#: It shifts the eigenvalues, and with them the Ogden stress, by ~eps |C| times the
#: stiffness. tensortrax's default, ``sqrt(machine eps) ~ 1.5e-8``, gives relative
#: stress errors up to 1e-4 for the Mold Star 15 fit (alpha1 = -21.32) at equibiaxial
#: stretch 3; 1e-12 gives 7e-9 there and <1e-10 at stretches up to 1.5. The price is in
#: the tangent only: its repeated-stretch terms become divided differences over the
#: split (round-off ~1e-16 / 1e-12), measured 3e-5 relative at the reference state,
#: which costs at most an extra Newton iteration and leaves the solution unchanged.
OGDEN_EIGEN_PERTURBATION = 1e-12

EnergyFunction = Callable[[Tensor], Tensor]


def _isochoric_invariants(C: Tensor) -> tuple[Tensor, Tensor]:
    """``Ibar1, Ibar2`` of the unimodular right Cauchy-Green tensor."""
    j23 = det(C) ** (-1.0 / 3.0)  # J^(-2/3)
    ibar1 = j23 * trace(C)
    ibar2 = j23**2 * (trace(C) ** 2 - trace(C @ C)) / 2.0
    return ibar1, ibar2


def isochoric_function(
    model: HyperelasticModel, eigen_perturbation: float = OGDEN_EIGEN_PERTURBATION
) -> EnergyFunction:
    """Isochoric strain-energy function ``W(Cbar(C))`` of a closed-form model.

    Parameters
    ----------
    model : NeoHooke, MooneyRivlin, Yeoh or Ogden
        A closed-form model from :mod:`pneumorph.materials.laws.hyperelastic`.
    eigen_perturbation : float
        Ogden only: relative perturbation of ``C`` that separates repeated eigenvalues
        in tensortrax's ``eigvalsh`` (default :data:`OGDEN_EIGEN_PERTURBATION`).

    Returns
    -------
    callable
        ``fun(C)`` of a tensortrax tensor ``C`` (right Cauchy-Green deformation tensor),
        for ``felupe.Hyperelastic(fun)``:

        * neo-Hooke (Eq 2.7): ``C10 (Ibar1 - 3)``
        * Mooney-Rivlin (Eqs 2.9, 2.10):
          ``C10 (Ibar1 - 3) + C01 (Ibar2 - 3) + C11 (Ibar1 - 3)(Ibar2 - 3)``
        * Yeoh (Eq 2.11): ``sum_i C_i (Ibar1 - 3)^i``
        * Ogden (Eq 2.12, Marc convention):
          ``sum_n mu_n / alpha_n (lbar1^a_n + lbar2^a_n + lbar3^a_n - 3)``

    Raises
    ------
    UnknownModelError
        If ``model`` is none of the four model types.

    Notes
    -----
    The Ogden energy needs the eigenvalues of ``C``. tensortrax splits repeated
    eigenvalues (the reference state, uniaxial and equibiaxial stretch) by perturbing
    ``C`` before the decomposition; the perturbation is
    :data:`OGDEN_EIGEN_PERTURBATION` instead of tensortrax's default, which changes the
    stress by up to ~1e-4 relative for the strongly non-linear silicone fits.

    Examples
    --------
    >>> import felupe as fem
    >>> from pneumorph.materials.laws.hyperelastic import Ogden
    >>> umat = fem.Hyperelastic(isochoric_function(Ogden(mu=(1.0,), alpha=(2.0,))))
    >>> import numpy as np
    >>> l1, l2 = 2.0, 0.5**0.5  # uniaxial, stretch 2
    >>> F = np.diag([l1, l2, l2]).reshape(3, 3, 1, 1)  # one quadrature point of one cell
    >>> P = umat.gradient([F, None])[0][..., 0, 0]
    >>> round(float(P[0, 0] - P[2, 2] * l2 / l1), 10)  # (tau1 - tau3) / l1
    1.75
    """
    if isinstance(model, NeoHooke):
        return _neo_hooke_energy(model)
    if isinstance(model, MooneyRivlin):
        return _mooney_rivlin_energy(model)
    if isinstance(model, Yeoh):
        return _yeoh_energy(model)
    if isinstance(model, Ogden):
        return _ogden_energy(model, eigen_perturbation)
    raise UnknownModelError(type(model).__name__, ("NeoHooke", "MooneyRivlin", "Yeoh", "Ogden"))


def _neo_hooke_energy(model: NeoHooke) -> EnergyFunction:
    """``C10 (Ibar1 - 3)`` (Eq 2.7)."""
    c10 = float(model.c10)

    def neo_hooke(C: Tensor) -> Tensor:
        ibar1, _ = _isochoric_invariants(C)
        return c10 * (ibar1 - 3.0)

    return neo_hooke


def _mooney_rivlin_energy(model: MooneyRivlin) -> EnergyFunction:
    """``C10 (Ibar1 - 3) + C01 (Ibar2 - 3) + C11 (Ibar1 - 3)(Ibar2 - 3)`` (Eqs 2.9, 2.10)."""
    c10, c01, c11 = float(model.c10), float(model.c01), float(model.c11)

    def mooney_rivlin(C: Tensor) -> Tensor:
        ibar1, ibar2 = _isochoric_invariants(C)
        w = c10 * (ibar1 - 3.0) + c01 * (ibar2 - 3.0)
        if c11 != 0.0:
            w = w + c11 * (ibar1 - 3.0) * (ibar2 - 3.0)
        return w

    return mooney_rivlin


def _yeoh_energy(model: Yeoh) -> EnergyFunction:
    """``sum_i C_i (Ibar1 - 3)^i`` (Eq 2.11)."""
    coefficients = tuple(float(c) for c in model.c)

    def yeoh(C: Tensor) -> Tensor:
        ibar1, _ = _isochoric_invariants(C)
        x = ibar1 - 3.0
        w = coefficients[0] * x
        for i, ci in enumerate(coefficients[1:], start=2):
            w = w + ci * x**i
        return w

    return yeoh


def _ogden_energy(model: Ogden, eigen_perturbation: float) -> EnergyFunction:
    """``sum_n mu_n / alpha_n (lbar1^a_n + lbar2^a_n + lbar3^a_n - 3)`` (Eq 2.12, Marc convention).

    ``eigen_perturbation`` separates repeated eigenvalues of ``C`` (see :func:`isochoric_function`).
    """
    terms = tuple(zip(model.mu, model.alpha, strict=True))
    eps = float(eigen_perturbation)

    def ogden(C: Tensor) -> Tensor:
        # squared isochoric stretches lbar_i^2 = J^(-2/3) l_i^2
        lbar2 = det(C) ** (-1.0 / 3.0) * eigvalsh(C, eps=eps)
        w = None
        for mu, alpha in terms:
            wn = mu / alpha * (tsum(lbar2 ** (alpha / 2.0)) - 3.0)
            w = wn if w is None else w + wn
        return w

    return ogden


def volumetric_energy(
    bulk_modulus: float,
) -> tuple[Callable[[Any], Any], Callable[[Any], Any], Callable[[Any], Any]]:
    """The volumetric energy of Eq 2.12 and its first two derivatives in ``J``.

    ``U = 9/2 K (J^(1/3) - 1)^2``, ``U' = 3 K (J^(-1/3) - J^(-2/3))``,
    ``U'' = K (2 J^(-5/3) - J^(-4/3))``.

    Parameters
    ----------
    bulk_modulus : float
        ``K`` (MPa), positive.

    Returns
    -------
    U, dUdJ, d2UdJdJ : callable
        Functions of ``J`` (array or tensortrax tensor).

    Examples
    --------
    >>> U, dU, d2U = volumetric_energy(2.0)
    >>> float(U(1.0)), float(dU(1.0)), float(d2U(1.0))
    (0.0, 0.0, 2.0)
    """
    k = _check_bulk(bulk_modulus)

    def energy(J: Any) -> Any:
        return 4.5 * k * (J ** (1.0 / 3.0) - 1.0) ** 2

    def first(J: Any) -> Any:
        return 3.0 * k * (J ** (-1.0 / 3.0) - J ** (-2.0 / 3.0))

    def second(J: Any) -> Any:
        return k * (2.0 * J ** (-5.0 / 3.0) - J ** (-4.0 / 3.0))

    return energy, first, second


def _check_bulk(bulk_modulus: float) -> float:
    k = float(bulk_modulus)
    if not math.isfinite(k) or k <= 0.0:
        raise MaterialDataError(
            f"bulk modulus must be a positive finite number (MPa), got {bulk_modulus!r}"
        )
    return k


def build_umat(
    model: HyperelasticModel,
    bulk_modulus: float,
    formulation: Formulation | str = "compressible",
) -> fem.Hyperelastic | fem.NearlyIncompressible:
    """FElupe material of a closed-form model with the volumetric term of Eq 2.12.

    Parameters
    ----------
    model : NeoHooke, MooneyRivlin, Yeoh or Ogden
        The isochoric behaviour (see :func:`isochoric_function`).
    bulk_modulus : float
        ``K`` in ``U(J) = 9/2 K (J^(1/3) - 1)^2`` (MPa), e.g. 0.119 for Mold Star 15
        (Table A.5).
    formulation : {"compressible", "nearly-incompressible"}
        ``"compressible"``: one ``felupe.Hyperelastic`` of the total energy
        ``W(Cbar) + U(J)``, for displacement elements (``SolidBody`` on a 3D field or on
        ``FieldPlaneStrain``).
        ``"nearly-incompressible"``: ``felupe.NearlyIncompressible`` of the isochoric
        material with the same ``U(J)``, for the mixed u/p/J formulation
        (``fem.FieldsMixed(region, n=3)`` with ``SolidBody``, or
        ``SolidBodyNearlyIncompressible``).

    Returns
    -------
    felupe.Hyperelastic or felupe.NearlyIncompressible

    Raises
    ------
    MaterialDataError
        For a non-positive or non-finite bulk modulus, or an unknown formulation.
    UnknownModelError
        For a model type without a FElupe counterpart.

    Examples
    --------
    >>> from pneumorph.materials.laws.hyperelastic import Yeoh
    >>> umat = build_umat(Yeoh(c=(0.1, 1e-3)), 0.119, "nearly-incompressible")
    >>> type(umat).__name__, umat.bulk
    ('NearlyIncompressible', 0.119)
    """
    if formulation not in FORMULATIONS:
        raise MaterialDataError(
            f"unknown formulation {formulation!r}; expected one of {', '.join(FORMULATIONS)}"
        )
    k = _check_bulk(bulk_modulus)
    isochoric = isochoric_function(model)

    if formulation == "nearly-incompressible":
        _, dudj, d2udjdj = volumetric_energy(k)
        return fem.NearlyIncompressible(
            fem.Hyperelastic(isochoric),
            bulk=k,
            dUdJ=lambda J, bulk: dudj(J),
            d2UdJdJ=lambda J, bulk: d2udjdj(J),
        )

    volumetric, _, _ = volumetric_energy(k)

    def total(C: Tensor) -> Tensor:
        return isochoric(C) + volumetric(det(C) ** 0.5)

    return fem.Hyperelastic(total)


def build_linear_elastic(
    youngs_modulus: float, poisson_ratio: float
) -> fem.LinearElasticLargeStrain:
    """Large-strain material with the small-strain constants ``E``, ``nu``.

    For the 2D filler of the reduced-order model (Eq 5.2) and the paper layer. Both see
    large rotations (the actuator bends through tens of degrees) at moderate strain, and
    the filler is compressed in the chambers. Small-strain linear elasticity is not
    objective under large rotations, and Saint Venant-Kirchhoff (the linear law in
    Green-Lagrange strain) softens and loses stability in compression. FElupe's
    ``LinearElasticLargeStrain`` is the compressible neo-Hooke
    ``psi = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2`` with the Lame constants of
    ``E`` and ``nu``: objective, polyconvex (stable in tension and compression) and equal
    to linear elasticity for small strains.

    Parameters
    ----------
    youngs_modulus : float
        ``E`` (MPa), positive.
    poisson_ratio : float
        ``nu``, in (-1, 0.5).

    Returns
    -------
    felupe.LinearElasticLargeStrain

    Raises
    ------
    MaterialDataError
        For ``E <= 0`` or ``nu`` outside (-1, 0.5).

    Examples
    --------
    >>> umat = build_linear_elastic(0.0643, 0.3)
    >>> round(umat.material.mu, 6)  # E / (2 (1 + nu))
    0.024731
    """
    e = float(youngs_modulus)
    nu = float(poisson_ratio)
    if not math.isfinite(e) or e <= 0.0:
        raise MaterialDataError(f"Young's modulus must be positive (MPa), got {youngs_modulus!r}")
    if not (-1.0 < nu < 0.5):
        raise MaterialDataError(f"Poisson's ratio must lie in (-1, 0.5), got {poisson_ratio!r}")
    return fem.LinearElasticLargeStrain(E=e, nu=nu)


__all__ = [
    "FORMULATIONS",
    "OGDEN_EIGEN_PERTURBATION",
    "build_linear_elastic",
    "build_umat",
    "isochoric_function",
    "volumetric_energy",
]

"""The composite as Ecoflex with the crimped paper in it, individually: a fibre-reinforced 3D law.

Chapter 3's composite is an Ecoflex 0030 slab of thickness ``H`` with one crimped paper sheet
in it. Along the crimp the paper is slack until it has unfolded, at the stretch
``2 s / lambda = sqrt(1 + 16 CR^2)`` of the crimp's analytic model for a crimp over the whole
length (:func:`pneumorph.fem.fibre.straight_stretch`, one plus
:func:`pneumorph.composite.crimp.limit_transition_strain`; the plane-strain coupon's FE
transition too), then it stretches as a sheet of modulus ``E`` and thickness ``t``
(the library's paper). Smeared over the slab, the straight paper adds the nominal stress

    s = E t / H (l / l_c - 1) = E t / (H l_c) (l - l_c)

along the crimp (``l`` the stretch, ``l_c`` the straightening stretch): a slope of
``E t / (H l_c)`` (MPa per unit stretch), the straight paper's ``E t L0 / L_paper`` of the
coupon per unit width over ``H``. Across the crimp the paper adds nothing. The matrix is the
Ecoflex's own Ogden law (Table A.4) with its bulk modulus.
:func:`paper_composite` builds the law (:class:`pneumorph.fem.fibre.CrimpedFibreOgden`);
:func:`uniaxial_stress` pulls it along one axis, the lateral stress zero, in 3D or in plane
strain (the coupon's state).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.errors import CrimpError
from pneumorph.fem.fibre import CrimpedFibreOgden, straight_stretch

FloatArray = NDArray[np.float64]

#: the dissertation's coupon and actuator layer: crimp amplitude and composite thickness (mm), section 3.2.1, B.1.1
AMPLITUDE = 1.5
THICKNESS = 5.0
#: half-width of the slack-to-taut blend in stretch: small beside the transition strains (0.28-0.56), wide
#: enough that a Newton step does not jump across the kink of a bilinear law
BLEND = 0.02


def paper_composite(crimp_ratio: float, thickness: float = THICKNESS, amplitude: float = AMPLITUDE,
                    matrix: str = "ecoflex_0030", paper: str = "paper_purco_80gsm", bulk: float | None = None,
                    direction: ArrayLike = (1.0, 0.0, 0.0), blend: float = BLEND,
                    mixed: bool = False, transition: float | None = None) -> CrimpedFibreOgden:
    """The 3D law of a composite layer of crimp ratio ``CR``: Ogden matrix and crimped paper along ``direction``.

    Parameters
    ----------
    crimp_ratio : float
        ``CR = A / lambda``.
    thickness, amplitude : float
        Layer thickness ``H`` and crimp amplitude ``A`` (mm; the amplitude only bounds the thickness:
        the straightening stretch depends on the crimp ratio alone).
    matrix, paper : str
        Library names of the Ogden matrix and of the paper (Young's modulus, thickness).
    bulk : float, optional
        Matrix bulk modulus (MPa) instead of the library's.
    direction : array_like, shape (3,) or (cells, 3)
        The crimp's direction (along the actuator: x).
    blend : float
        Half-width of the slack-to-taut blend in stretch.
    mixed : bool
        Integrate the matrix's volumetric term on the elements' dilatation (nearly incompressible).
    transition : float, optional
        The paper's straightening strain instead of the crimp's analytic ``2 s / lambda - 1``
        (e.g. a measured transition strain, Table 3.2).

    Raises
    ------
    CrimpError
        A crimp that cannot exist, or a layer thinner than the crimp height ``2A``.

    Examples
    --------
    >>> law = paper_composite(0.3)
    >>> round(law.straight, 4), round(law.slope, 1)     # 2 s / lambda; 6.5 GPa x 0.107 mm / (5 mm x 1.562)
    (1.562, 89.0)
    """
    import pneumorph.materials as pm
    from pneumorph.materials.laws.hyperelastic import Ogden

    if not (np.isfinite(thickness) and thickness > 2.0 * amplitude):
        raise CrimpError(f"the layer ({thickness!r} mm) must be thicker than the crimp height "
                         f"2A = {2 * amplitude:g} mm")
    straight = straight_stretch(_positive_ratio(crimp_ratio)) if transition is None else 1.0 + float(transition)
    if not (np.isfinite(straight) and straight > 1.0 + blend):
        raise CrimpError(f"the transition strain must exceed the blend {blend:g}, got {transition!r}")
    m = pm.get(matrix)
    if not isinstance(m.model, Ogden):
        raise CrimpError(f"the matrix {matrix!r} must have an Ogden model, it has {type(m.model).__name__}")
    if bulk is None:
        if m.bulk_modulus is None:
            raise CrimpError(f"the matrix {matrix!r} has no bulk modulus; pass bulk")
        bulk = m.bulk_modulus.value
    p = pm.get(paper)
    if p.youngs_modulus is None or p.thickness is None:
        raise CrimpError(f"the paper {paper!r} needs a Young's modulus and a thickness")
    slope = p.youngs_modulus.value * p.thickness.value / (thickness * straight)
    return CrimpedFibreOgden(m.model.mu, m.model.alpha, float(bulk), direction, straight, slope, blend, mixed=mixed)


def _positive_ratio(crimp_ratio: float) -> float:
    cr = float(crimp_ratio)
    if not (np.isfinite(cr) and cr > 0):
        raise CrimpError(f"crimp ratio CR must be positive and finite, got {crimp_ratio!r}")
    return cr


def uniaxial_stress(law: Any, stretches: ArrayLike, plane_strain: bool = False, axis: int = 0) -> FloatArray:
    """Nominal stress ``P[axis, axis]`` of a law pulled along ``axis``, the lateral stresses zero.

    In 3D both lateral stretches are free (found equal: the matrix is isotropic and the fibres lie
    along ``axis`` or across it); in plane strain the one in the plane is free and the third is 1
    (the plane-strain coupon's state, pulled along x with z the depth).

    Examples
    --------
    >>> law = paper_composite(0.3)
    >>> s = uniaxial_stress(law, [1.5, 1.7])          # kPa: before and after the paper is straight
    >>> round(1e3 * float(s[0]), 1), round(float(s[1]), 2)
    (20.1, 12.31)
    """
    from scipy.optimize import brentq

    lateral = [k for k in range(3) if k != axis]
    if plane_strain:
        lateral = lateral[:1]

    def stress(lam: float, other: float) -> FloatArray:
        stretch = np.ones(3)
        stretch[axis] = lam
        stretch[lateral] = other
        return law.kernel(np.diag(stretch)[..., None], tangent=False)[0][..., 0]

    out = []
    for lam in np.atleast_1d(np.asarray(stretches, dtype=float)):
        other = brentq(lambda x, lam=lam: stress(lam, x)[lateral[0], lateral[0]], 0.2, 2.0, xtol=1e-14)
        out.append(stress(lam, other)[axis, axis])
    return np.asarray(out)


__all__ = ["AMPLITUDE", "BLEND", "THICKNESS", "paper_composite", "uniaxial_stress"]

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

That is the *ideal* crimp. The cast coupons of Table 3.2 (:data:`MEASURED`) behave otherwise:
the creased, wet-cast paper straightens earlier (15.2, 30.0, 35.6 % against the ideal 28.1,
41.4, 56.2 %), resists being unfolded before it does (primary modulus 216 kPa for CR 0.2
against the Ecoflex's 60) and is some four times softer once straight (25.2 MPa against the
ideal 108.6). :func:`measured_composite` is the same law with a linear pre-transition
stiffness of the paper (``primary``) and its straightening stretch and slope calibrated
(:func:`calibrate_measured`) so that the law pulled as the coupons were and read by the
two-line method of section 3.2.6 (:func:`two_line`) gives Table 3.2's three numbers.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.errors import CrimpError
from pneumorph.fem.fibre import CAST_PAPER, CrimpedFibreOgden, straight_stretch

FloatArray = NDArray[np.float64]

#: the dissertation's coupon and actuator layer: crimp amplitude and composite thickness (mm), section 3.2.1, B.1.1
AMPLITUDE = 1.5
THICKNESS = 5.0
#: half-width of the slack-to-taut blend in stretch: small beside the transition strains (0.15-0.56), wide
#: enough that a Newton step does not jump across the kink of a bilinear law
BLEND = 0.02
#: Table 3.2, the cast coupons (means of four): primary modulus (MPa), transition strain, secondary modulus (MPa),
#: read by the two-line method from the averaged surface strain
MEASURED = {0.2: (0.216, 0.152, 25.2), 0.25: (0.0819, 0.300, 20.7), 0.3: (0.0800, 0.356, 16.5)}
#: the paper of the measured law with the library's Ecoflex (bulk modulus 33.8 kPa) and :data:`BLEND`: its
#: pre-transition slope (MPa), straightening stretch and slope once straight (MPa), from :func:`calibrate_measured`
MEASURED_PAPER = {p.crimp_ratio: (p.primary, p.straight, p.slope) for p in CAST_PAPER.values()}
#: the paper laws: the cast coupons' (Table 3.2) or the ideal crimp's
PAPER_MODELS = ("measured", "ideal")


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


def measured_composite(crimp_ratio: float, matrix: str = "ecoflex_0030", bulk: float | None = None,
                       direction: ArrayLike = (1.0, 0.0, 0.0), mixed: bool = False) -> CrimpedFibreOgden:
    """The composite law calibrated to the cast coupons of Table 3.2 (a crimp ratio of :data:`MEASURED`).

    The matrix of :func:`paper_composite`; the paper carries ``primary`` per unit stretch before
    it is straight and ``slope`` more after, the three chosen by :func:`calibrate_measured` (the
    stored :data:`MEASURED_PAPER` for the library's Ecoflex) so that the two-line reading of the
    law's uniaxial curve is the table's.

    Parameters
    ----------
    crimp_ratio : float
        0.2, 0.25 or 0.3.
    matrix, bulk, direction, mixed
        As :func:`paper_composite`; a bulk modulus other than the library's is calibrated anew.

    Raises
    ------
    CrimpError
        A crimp ratio that Table 3.2 does not have.

    Examples
    --------
    >>> law = measured_composite(0.2)
    >>> round(law.straight - 1.0, 4), round(law.slope, 2), round(1e3 * law.primary, 1)
    (0.152, 25.02, 148.6)
    """
    cr = _measured_ratio(crimp_ratio)
    base = paper_composite(cr, matrix=matrix, bulk=bulk, direction=direction, mixed=mixed)
    library = paper_composite(cr, matrix=matrix).bulk
    if matrix == "ecoflex_0030" and base.bulk == library:
        primary, straight, slope = MEASURED_PAPER[cr]
    else:
        primary, straight, slope = calibrate_measured(cr, matrix, base.bulk)
    return CrimpedFibreOgden(base.mu.tolist(), base.alpha.tolist(), base.bulk, base.direction, straight, slope, BLEND,
                             mixed=mixed, primary=primary)


def calibrate_measured(crimp_ratio: float, matrix: str = "ecoflex_0030", bulk: float | None = None,
                       iterations: int = 3) -> tuple[float, float, float]:
    """The paper's pre-transition slope, straightening stretch and slope of the Table 3.2 law.

    Each of the three moves mainly one number of the two-line reading (:func:`two_line`): the
    pre-transition slope the primary modulus, the slope the secondary, the straightening
    stretch the transition; each is corrected by its number's miss, ``iterations`` times
    (from the table's own numbers; three bring all three within 1e-6 of the table). A matrix
    stiffer than the table's primary modulus on its own (the Ecoflex with K = 0.5 MPa: 86 kPa
    against CR 0.3's 80) leaves the pre-transition slope at zero.

    Returns
    -------
    tuple of float
        ``(primary, straight, slope)``: MPa, stretch, MPa.

    Examples
    --------
    >>> primary, straight, slope = calibrate_measured(0.3, iterations=1)
    >>> round(straight, 3), round(slope, 1)
    (1.356, 16.5)
    """
    cr = _measured_ratio(crimp_ratio)
    e1, eps, e2 = MEASURED[cr]
    base = paper_composite(cr, matrix=matrix, bulk=bulk)
    eps_matrix = np.linspace(0.0, 0.10, 11)  # the matrix alone over the primary line's 10 % (the paper is slack there)
    matrix_slope = float(np.polyfit(eps_matrix, uniaxial_stress(base, 1.0 + eps_matrix), 1)[0])
    primary, straight, slope = max(0.0, e1 - matrix_slope), 1.0 + eps, e2 - e1
    for _ in range(iterations):
        law = CrimpedFibreOgden(base.mu.tolist(), base.alpha.tolist(), base.bulk, base.direction, straight, slope,
                                BLEND, primary=primary)
        r = two_line(law, eps)
        primary = max(0.0, primary + e1 - r.primary_modulus)
        slope += e2 - r.secondary_modulus
        straight += eps - r.transition_strain
    return primary, straight, slope


def two_line(law: Any, transition: float, levels: int = 100) -> Any:
    """Table 3.2's reading of a law pulled along x (3D, lateral stresses zero) to ``transition + 0.10``.

    ``levels`` equal strain levels, as the FE coupon is pulled (:func:`pneumorph.composite.coupon.simulate_coupon`):
    the primary line through the points up to 10 % strain, the secondary through the last ten
    (:func:`pneumorph.materials.characterisation.analyses.bilinear`).

    Examples
    --------
    >>> r = two_line(measured_composite(0.25), 0.30)
    >>> round(1e3 * r.primary_modulus, 1), round(100 * r.transition_strain, 2), round(r.secondary_modulus, 2)
    (81.9, 30.0, 20.7)
    """
    from pneumorph.materials.characterisation.analyses import bilinear

    eps = np.linspace(0.0, float(transition) + 0.10, levels + 1)
    return bilinear(eps, uniaxial_stress(law, 1.0 + eps))


def _measured_ratio(crimp_ratio: float) -> float:
    cr = _positive_ratio(crimp_ratio)
    for known in MEASURED:
        if abs(cr - known) < 1e-9:
            return known
    raise CrimpError(f"Table 3.2 measured the crimp ratios {', '.join(f'{c:g}' for c in MEASURED)}, not {cr:g}")


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


__all__ = ["AMPLITUDE", "BLEND", "MEASURED", "MEASURED_PAPER", "PAPER_MODELS", "THICKNESS", "calibrate_measured",
           "measured_composite", "paper_composite", "two_line", "uniaxial_stress"]

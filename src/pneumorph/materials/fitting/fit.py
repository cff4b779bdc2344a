"""Fitting incompressible hyperelastic models to stress-stretch test data.

:func:`fit` calibrates one model by least squares on the nominal stress
(:func:`scipy.optimize.least_squares`) over every mode of a :class:`TestData` (uniaxial
tension and compression, equibiaxial, planar); :func:`compare` fits several models to the
same data and tabulates R^2 per mode, like Table A.3 of Ellis (2020).

Goodness of fit is the coefficient of determination per mode (Eqs A.1-A.3)

    R^2 = 1 - SSE / SSTO,  SSE = sum (Y_i - Yhat_i)^2,  SSTO = sum (Y_i - mean(Y))^2,

with ``Y`` the measured nominal stress of that mode; the overall R^2 pools all points
(SSTO about the mean of all of them).

Models and their parameters (Marc convention, stress in MPa):

=================  ==========================================  ============================
name               strain energy                               parameters
=================  ==========================================  ============================
neo-hooke          C10 (I1-3)                                  C10
mooney-rivlin-2    C10 (I1-3) + C01 (I2-3)                     C10, C01
mooney-rivlin-3    ... + C11 (I1-3)(I2-3)                      C10, C01, C11
yeoh, yeoh-N       sum_i C_i0 (I1-3)^i, N = 3 for ``yeoh``     C10 ... CN0
ogden-3, ogden-N   sum_n mu_n/alpha_n (l1^a_n + l2^a_n + ...)  mu_n, alpha_n
=================  ==========================================  ============================

The invariant models are linear in their parameters: their least-squares optimum is
unique and is found from the linear normal equations (then confirmed by
``least_squares``). The Ogden model is linear in ``mu`` but not in ``alpha`` and its
optimum is not unique (terms can be swapped, several local minima). Each of ``starts``
starts draws exponents uniformly in [-10, 10] from a seeded generator, optimises the
exponents with the moduli solved exactly for each trial (variable projection), then
polishes all parameters together; the start with the smallest residual is kept, terms
sorted by ``alpha``. Consecutive exponents are kept at least ``min_alpha_gap`` (0.5) apart:
left free, two exponents tend to merge, the pair then imitating a ``l^a ln(l)`` term with
huge moduli of opposite sign (e.g. +-4850 MPa for a 4 MPa curve) that cancel.

Residual weighting (``weighting``): ``"absolute"`` (default) minimises the plain sum of
squared stress errors, the quantity R^2 measures; ``"relative"`` divides each residual by
the measured stress (floored at 1 % of the mode's largest stress, so the unloaded point
does not dominate); ``"balanced"`` divides each mode's residuals by ``sqrt(SSTO)`` of
that mode, i.e. minimises ``sum_modes (1 - R^2_mode)``, so a mode with small stresses or
few points counts as much as the others. ``mode_weights`` multiplies a mode's squared
residuals on top of that.

Examples
--------
>>> from pneumorph.materials.characterisation.datasets import load_dataset
>>> r = fit("yeoh", load_dataset("treloar1944"))
>>> {m: round(v, 3) for m, v in r.r2.items()}
{'uniaxial': 0.995, 'equibiaxial': 0.945, 'planar': 0.998}
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np

from pneumorph.checks import MODEL_NAMES, MODES, WEIGHTINGS
from pneumorph.errors import FitError, UnknownModelError
from pneumorph.materials.characterisation.testdata import TestCurve, TestData
from pneumorph.materials.fitting.ogden import fit_ogden
from pneumorph.materials.laws.hyperelastic import (
    FloatArray,
    HyperelasticModel,
    MooneyRivlin,
    NeoHooke,
    Ogden,
    StabilityReport,
    Yeoh,
    drucker_stability,
)

_MAX_TERMS = 6


@dataclass(frozen=True)
class ModelSpec:
    """A fittable model: canonical name, family and number of terms."""

    name: str
    family: str  # neo-hooke | mooney-rivlin | yeoh | ogden
    terms: int

    @property
    def n_parameters(self) -> int:
        return 2 * self.terms if self.family == "ogden" else self.terms

    def build(self, p: Sequence[float]) -> HyperelasticModel:
        """The model with parameter vector ``p`` (Ogden: all mu, then all alpha)."""
        p = [float(x) for x in p]
        if self.family == "neo-hooke":
            return NeoHooke(p[0])
        if self.family == "mooney-rivlin":
            return MooneyRivlin(*p)
        if self.family == "yeoh":
            return Yeoh(tuple(p))
        return Ogden(tuple(p[: self.terms]), tuple(p[self.terms :]))


def resolve_model(name: str) -> ModelSpec:
    """Parse a model name (case and ``_``/``-`` insensitive).

    Examples
    --------
    >>> resolve_model("Yeoh"), resolve_model("ogden_2").n_parameters
    (ModelSpec(name='yeoh-3', family='yeoh', terms=3), 4)
    """
    key = name.strip().lower().replace("_", "-").replace(" ", "-")
    fixed = {"neo-hooke": ("neo-hooke", 1), "neohooke": ("neo-hooke", 1),
             "mooney-rivlin-2": ("mooney-rivlin", 2), "mooney-rivlin-3": ("mooney-rivlin", 3),
             "yeoh": ("yeoh", 3), "ogden": ("ogden", 3)}
    if key in fixed:
        fam, n = fixed[key]
    elif m := re.fullmatch(r"(yeoh|ogden)-(\d+)", key):
        fam, n = m.group(1), int(m.group(2))
        if not 1 <= n <= _MAX_TERMS:
            raise UnknownModelError(name, MODEL_NAMES)
    else:
        raise UnknownModelError(name, MODEL_NAMES)
    canon = {"neo-hooke": "neo-hooke", "mooney-rivlin": f"mooney-rivlin-{n}"}.get(fam, f"{fam}-{n}")
    return ModelSpec(canon, fam, n)


@dataclass(frozen=True, eq=False)
class FitResult:
    """Outcome of :func:`fit`.

    Attributes
    ----------
    model_name : str
        Canonical model name (``"yeoh"`` becomes ``"yeoh-3"``).
    model : HyperelasticModel
        The fitted model (:mod:`pneumorph.materials.laws.hyperelastic`).
    parameters : mapping of str to float
        Named parameters, MPa (Ogden exponents dimensionless).
    mu0 : float
        Initial shear modulus, MPa.
    r2 : mapping of str to float
        R^2 per mode (Eqs A.1-A.3); NaN where a mode's data do not vary.
    r2_overall : float
        R^2 of all points pooled.
    residual_norm : float
        ``sqrt(SSE)`` of the unweighted stress residuals over all points, MPa.
    rmse : mapping of str to float
        Root-mean-square stress error per mode, MPa.
    n_points : mapping of str to int
    stretch_range : mapping of str to (float, float)
    stability : StabilityReport
        Drucker stability of the fitted model over a stretch range covering the data.
    starts : int
        Optimiser starts used (1 for the models linear in their parameters).
    seed : int or None
        Seed of the starts (None if a Generator was passed or no random start was drawn).
    weighting : str
    data_name : str
    sources : tuple of str
    stable_constrained : bool
        Whether the parameter signs were constrained for stability (``fit(stable=True)``).
    """

    model_name: str
    model: HyperelasticModel
    parameters: Mapping[str, float]
    mu0: float
    r2: Mapping[str, float]
    r2_overall: float
    residual_norm: float
    rmse: Mapping[str, float]
    n_points: Mapping[str, int]
    stretch_range: Mapping[str, tuple[float, float]]
    stability: StabilityReport
    starts: int
    seed: int | None
    weighting: str
    data_name: str = ""
    sources: tuple[str, ...] = ()
    stable_constrained: bool = False

    def predict(self, mode: str, stretch: Any) -> FloatArray:
        """Nominal stress of the fitted model, MPa."""
        return self.model.nominal_stress(mode, stretch)

    def to_dict(self) -> dict[str, Any]:
        """Plain, JSON-ready data."""
        return {
            "model": self.model_name,
            "parameters": dict(self.parameters),
            "mu0_MPa": self.mu0,
            "r2": dict(self.r2),
            "r2_overall": self.r2_overall,
            "residual_norm_MPa": self.residual_norm,
            "rmse_MPa": dict(self.rmse),
            "n_points": dict(self.n_points),
            "stretch_range": {k: list(v) for k, v in self.stretch_range.items()},
            "drucker_stable": self.stability.is_stable,
            "stable_limits": {k: list(v) for k, v in self.stability.limits().items()},
            "stability_checked": [float(self.stability.stretch[0]), float(self.stability.stretch[-1])],
            "starts": self.starts,
            "seed": self.seed,
            "weighting": self.weighting,
            "stable_constrained": self.stable_constrained,
            "data": self.data_name,
            "sources": list(self.sources),
        }

    def summary(self) -> str:
        """Human-readable report: parameters, mu0, R^2 per mode, stability."""
        head = (f"{self.model_name} fitted to {self.data_name or 'data'} "
                f"({self.weighting} residuals, {self.starts} start{'s' if self.starts > 1 else ''}"
                f"{', signs constrained for stability' if self.stable_constrained else ''})")
        lines = [head]
        for mode, n in self.n_points.items():
            lo, hi = self.stretch_range[mode]
            lines.append(f"  {mode}: {n} points, stretch {lo:.4g}-{hi:.4g}")
        lines.append("  parameters (MPa" + ("; alpha dimensionless):" if "alpha1" in self.parameters else "):"))
        lines += [f"    {k:7s} = {v: .6g}" for k, v in self.parameters.items()]
        lines.append(f"  mu0 = {self.mu0:.6g} MPa")
        lines += [f"  R^2 {m:12s} = {v:.6f}" for m, v in self.r2.items()]
        lines.append(f"  R^2 {'overall':12s} = {self.r2_overall:.6f}   (residual norm {self.residual_norm:.4g} MPa)")
        lines.append("  Drucker stability: " + ("stable" if self.stability.is_stable else "NOT stable everywhere"))
        lines += ["    " + s for s in self.stability.summary().splitlines()]
        return "\n".join(lines)


def r_squared(measured: Any, predicted: Any) -> float:
    """Coefficient of determination ``1 - SSE/SSTO`` (Eqs A.1-A.3); NaN if SSTO is 0.

    Examples
    --------
    >>> r_squared([1.0, 2.0, 3.0], [1.0, 2.0, 4.0])
    0.5
    """
    y = np.asarray(measured, dtype=float)
    sse = float(np.sum((y - np.asarray(predicted, dtype=float)) ** 2))
    ssto = float(np.sum((y - y.mean()) ** 2))
    return 1.0 - sse / ssto if ssto > 0 else float("nan")


def _linear_columns(spec: ModelSpec, curves: Sequence[TestCurve]) -> FloatArray:
    """Nominal stress of the model with each parameter 1 and the others 0 (it is linear)."""
    eye = np.eye(spec.n_parameters)
    return np.column_stack([
        np.concatenate([spec.build(e.tolist()).nominal_stress(c.mode, c.stretch) for c in curves]) for e in eye
    ])


def _weights(curves: Sequence[TestCurve], weighting: str, mode_weights: Mapping[str, float] | None) -> FloatArray:
    w = []
    for c in curves:
        p = c.stress
        if weighting == "absolute":
            wc = np.ones_like(p)
        elif weighting == "relative":
            wc = 1.0 / np.maximum(abs(p), 0.01 * max(float(abs(p).max()), 1e-12))
        else:
            ssto = float(np.sum((p - p.mean()) ** 2))
            wc = np.full_like(p, 1.0 / np.sqrt(ssto if ssto > 0 else max(float(np.sum(p**2)), 1e-12)))
        w.append(wc * np.sqrt((mode_weights or {}).get(c.mode, 1.0)))
    return np.concatenate(w)


def fit(model_name: str, data: TestData | TestCurve, *, modes: Sequence[str] | None = None, weighting: str = "absolute",
        mode_weights: Mapping[str, float] | None = None, starts: int = 8, seed: int | np.random.Generator | None = 0,
        alpha_bound: float = 30.0, min_alpha_gap: float = 0.5, stable: bool = False,
        stability_range: tuple[float, float] | None = None) -> FitResult:
    """Fit a hyperelastic model to test data by least squares on the nominal stress.

    Parameters
    ----------
    model_name : str
        One of :data:`pneumorph.checks.MODEL_NAMES` (``N`` is a number of terms, 1-6).
    data : TestData or TestCurve
        The measurements; every mode present is used unless ``modes`` says otherwise.
    modes : sequence of str, optional
        Restrict the fit to these modes.
    weighting : {"absolute", "relative", "balanced"}
        Residual weighting (see the module notes); default plain stress residuals.
    mode_weights : mapping of str to float, optional
        Extra factor on each mode's squared residuals.
    starts : int
        Number of starts of the Ogden fit (ignored by the linear models).
    seed : int or numpy.random.Generator or None
        Seed of the Ogden starts; the same seed gives the same result.
    alpha_bound : float
        Bound of the smallest Ogden exponent (``|alpha_1| <= alpha_bound``) and of the gaps
        between consecutive exponents.
    min_alpha_gap : float
        Smallest gap between consecutive Ogden exponents (see the module notes).
    stable : bool
        Constrain the signs of the parameters to values that make the model Drucker-stable
        at every stretch: Ogden ``mu_n alpha_n >= 0`` for every term, the invariant models
        all coefficients ``>= 0`` (for neo-Hooke, Mooney-Rivlin-2 and Yeoh this is
        sufficient; for Mooney-Rivlin-3 the ``C11`` term can still be unstable, see
        ``FitResult.stability``). Default False: unconstrained, as in the dissertation.
    stability_range : (float, float), optional
        Stretch range of the Drucker check; default ``(min(0.5, smallest stretch),
        max(1.5, largest stretch))``.

    Returns
    -------
    FitResult

    Raises
    ------
    UnknownModelError
        For a model name that is not known.
    FitError
        Too few points for the parameters, or parameters the data cannot determine.

    Examples
    --------
    >>> from pneumorph.materials.characterisation.testdata import TestCurve
    >>> lam = [1.1, 1.5, 2.0, 3.0]
    >>> curve = TestCurve("uniaxial", lam, NeoHooke(0.2).uniaxial(lam))
    >>> r = fit("neo-hooke", curve)
    >>> round(r.parameters["C10"], 6), round(r.r2["uniaxial"], 6)
    (0.2, 1.0)
    """
    spec = resolve_model(model_name)
    data, curves, y = _fit_data(spec, data, modes, weighting)
    w = _weights(curves, weighting, mode_weights)
    if spec.family == "ogden":
        if starts < 1:
            raise ValueError(f"starts must be at least 1, got {starts}")
        rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
        p = fit_ogden(curves, y, w, spec.terms, starts, rng, alpha_bound, min_alpha_gap, stable)
        nstarts, used_seed = starts, seed if isinstance(seed, int | type(None)) else None
    else:
        p, nstarts, used_seed = _fit_linear(spec, curves, y, w, stable), 1, None
    return _result(spec.build(p.tolist()), spec, curves, y, stability_range, {
        "starts": nstarts, "seed": used_seed, "weighting": weighting, "data_name": data.name,
        "sources": data.sources, "stable_constrained": stable})


def _fit_data(spec: ModelSpec, data: TestData | TestCurve, modes: Sequence[str] | None,
              weighting: str) -> tuple[TestData, list[TestCurve], FloatArray]:
    """The data as :class:`TestData`, the curves to fit (in the order of ``MODES``) and their stresses.

    Raises
    ------
    ValueError
        An unknown ``weighting``.
    FitError
        A mode the data do not have, or no more points than the model has parameters.
    """
    if isinstance(data, TestCurve):
        data = TestData((data,), data.description)
    if weighting not in WEIGHTINGS:
        raise ValueError(f"weighting must be one of {WEIGHTINGS}, got {weighting!r}")
    use = tuple(modes) if modes is not None else data.modes
    missing = [m for m in use if m not in data.modes]
    if missing:
        raise FitError(f"no {', '.join(missing)} data to fit; the data have {', '.join(data.modes)}")
    curves = [data.curve(m) for m in MODES if m in use]
    y = np.concatenate([c.stress for c in curves])
    npar = spec.n_parameters
    if y.size <= npar:
        raise FitError(f"{spec.name} has {npar} parameters but only {y.size} data points were given; "
                       f"need more than {npar}")
    return data, curves, y


def _fit_linear(spec: ModelSpec, curves: Sequence[TestCurve], y: FloatArray, w: FloatArray,
                stable: bool) -> FloatArray:
    """The parameters of a model linear in them: weighted least squares (``stable``: all >= 0).

    Raises
    ------
    FitError
        The data cannot determine every parameter (a rank-deficient system).
    """
    from scipy.optimize import (  # deferred: keeps the CLI start fast
        least_squares,
        lsq_linear,
    )

    npar = spec.n_parameters
    a = _linear_columns(spec, curves)
    aw = a * w[:, None]
    p0, _, rank, _ = np.linalg.lstsq(aw, y * w, rcond=None)
    if rank < npar:
        raise FitError(f"the data cannot determine the {npar} parameters of {spec.name} "
                       f"(rank {rank}); add points over a wider stretch range or another mode")
    if stable:  # bounded linear least squares: convex, so still the unique optimum
        return np.asarray(lsq_linear(aw, y * w, bounds=(0.0, np.inf), method="bvls").x, dtype=np.float64)
    return np.asarray(least_squares(lambda q: aw @ q - y * w, p0, jac=lambda q: aw, method="lm").x, dtype=np.float64)


def _result(model: HyperelasticModel, spec: ModelSpec, curves: Sequence[TestCurve], y: FloatArray,
            stability_range: tuple[float, float] | None, run: dict[str, Any]) -> FitResult:
    """The fitted ``model``'s goodness per mode and overall, its stability, and the ``run``'s settings.

    The stability range is ``stability_range``, else the curves' stretches widened to
    0.5-1.5 at least; ``run`` holds the :class:`FitResult` fields from ``starts`` on.
    """
    pred = [model.nominal_stress(c.mode, c.stretch) for c in curves]
    lo = min(float(c.stretch.min()) for c in curves)
    hi = max(float(c.stretch.max()) for c in curves)
    srange = stability_range or (min(0.5, lo), max(1.5, hi))
    params = model.parameters
    if spec.name == "mooney-rivlin-2":
        params = {k: v for k, v in params.items() if k != "C11"}
    return FitResult(
        model_name=spec.name,
        model=model,
        parameters=MappingProxyType(dict(params)),
        mu0=float(model.shear_modulus),
        r2=MappingProxyType({c.mode: r_squared(c.stress, q) for c, q in zip(curves, pred, strict=False)}),
        r2_overall=r_squared(y, np.concatenate(pred)),
        residual_norm=float(np.linalg.norm(y - np.concatenate(pred))),
        rmse=MappingProxyType({c.mode: float(np.sqrt(np.mean((c.stress - q) ** 2)))
                               for c, q in zip(curves, pred, strict=True)}),
        n_points=MappingProxyType({c.mode: len(c) for c in curves}),
        stretch_range=MappingProxyType({c.mode: (float(c.stretch[0]), float(c.stretch[-1])) for c in curves}),
        stability=drucker_stability(model, stretch_range=srange),
        **run,
    )



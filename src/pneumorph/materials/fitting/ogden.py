"""The multi-start least-squares fit of an Ogden model (:func:`pneumorph.materials.fitting.fit.fit`).

Ogden's model is nonlinear in its exponents: the moduli ``mu_n`` for given exponents are a
linear least-squares problem (:func:`ogden_columns`), the exponents are found from several
random starts by variable projection, then all parameters are polished together
(:func:`fit_ogden`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from pneumorph.errors import FitError
from pneumorph.materials.characterisation.testdata import TestCurve
from pneumorph.materials.laws.hyperelastic import FloatArray, mode_stretches

__all__ = ["fit_ogden", "ogden_columns"]


def ogden_columns(curves: Sequence[TestCurve], alpha: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Per unit mu_n: nominal stress (l1^a - l3^a)/l1 and its derivative in a, stacked over modes.

    Parameters
    ----------
    curves : sequence of TestCurve
    alpha : ndarray, shape (n,)
        The exponents.

    Returns
    -------
    columns, derivatives : ndarray, shape (points, n)

    Examples
    --------
    >>> c = TestCurve("uniaxial", [1.0, 2.0], [0.0, 1.0])
    >>> ogden_columns([c], np.array([2.0]))[0].round(3).tolist()
    [[0.0], [1.75]]
    """
    cols, dcols = [], []
    for c in curves:
        l1, _, l3 = mode_stretches(c.mode, c.stretch)
        g1, g3 = np.log(l1)[:, None], np.log(l3)[:, None]
        p1, p3 = l1[:, None] ** alpha, l3[:, None] ** alpha
        cols.append((p1 - p3) / l1[:, None])
        dcols.append((p1 * g1 - p3 * g3) / l1[:, None])
    return np.vstack(cols), np.vstack(dcols)


def fit_ogden(curves: Sequence[TestCurve], y: FloatArray, w: FloatArray, n: int, starts: int,
               rng: np.random.Generator, alpha_bound: float, gap: float, stable: bool) -> FloatArray:
    """Multi-start Ogden fit; returns (mu..., alpha...) with increasing alpha.

    The exponents are parametrised as ``alpha_1`` and the gaps ``alpha_(k+1) - alpha_k >=
    gap``: two terms with (nearly) equal exponents degenerate into huge moduli of opposite
    sign that cancel, a solution with no meaning as material parameters. With ``stable``
    every term keeps ``mu_n alpha_n >= 0`` (such pairs cannot cancel, so the final polish
    works on the exponents directly, each keeping its sign). ``y`` and ``w`` are the
    stresses of ``curves`` and their weights, ``n`` the terms; each of the ``starts`` draws
    its exponents from ``rng`` (the lowest cost wins); ``alpha_bound``, ``gap`` and
    ``stable`` are :func:`~pneumorph.materials.fitting.fit.fit`'s ``alpha_bound``,
    ``min_alpha_gap`` and ``stable``. Raises :class:`FitError` if every start ends with
    non-finite parameters.
    """
    from scipy.optimize import (  # deferred: keeps the CLI start fast
        least_squares,
        lsq_linear,
    )

    yw = y * w
    tri = np.tril(np.ones((n, n)))

    def alphas(x: FloatArray) -> FloatArray:
        return tri @ x

    def mu_for(alpha: FloatArray) -> FloatArray:
        a, _ = ogden_columns(curves, alpha)
        if not stable:
            return np.asarray(np.linalg.lstsq(a * w[:, None], yw, rcond=None)[0], dtype=np.float64)
        pos = alpha > 0
        return lsq_linear(a * w[:, None], yw, bounds=(np.where(pos, 0.0, -np.inf), np.where(pos, np.inf, 0.0)),
                          method="bvls").x

    def projected(x: FloatArray) -> FloatArray:
        alpha = alphas(x)
        a, _ = ogden_columns(curves, alpha)
        return (a @ mu_for(alpha) - y) * w

    def full(p: FloatArray) -> FloatArray:
        a, _ = ogden_columns(curves, p[n:] if stable else alphas(p[n:]))
        return (a @ p[:n] - y) * w

    def full_jac(p: FloatArray) -> FloatArray:
        a, da = ogden_columns(curves, p[n:] if stable else alphas(p[n:]))
        return np.hstack([a, (da * p[:n]) @ (np.eye(n) if stable else tri)]) * w[:, None]

    lo = [-alpha_bound] + [gap] * (n - 1)
    hi = [alpha_bound] * n
    best, best_alpha = None, None
    for _ in range(starts):
        a0 = np.sort(rng.uniform(-10.0, 10.0, n))
        x0 = np.clip(np.concatenate([a0[:1], np.diff(a0)]), lo, hi)
        with np.errstate(all="ignore"):
            vp = least_squares(projected, x0, bounds=(lo, hi), max_nfev=200)
            alpha = alphas(vp.x)
            mu = mu_for(alpha)
            if stable:
                big = max(alpha_bound, float(np.abs(alpha).max()))
                pos = alpha > 0
                blo = np.concatenate([np.where(pos, 0.0, -np.inf), np.where(pos, 1e-3, -big)])
                bhi = np.concatenate([np.where(pos, np.inf, 0.0), np.where(pos, big, -1e-3)])
                p0 = np.clip(np.concatenate([mu, alpha]), blo, bhi)
            else:
                blo = np.array([-np.inf] * n + lo)
                bhi = np.array([np.inf] * n + hi)
                p0 = np.concatenate([mu, vp.x])
            res = least_squares(full, p0, jac=full_jac, bounds=(blo, bhi), x_scale="jac", max_nfev=300)
        if np.all(np.isfinite(res.x)) and (best is None or res.cost < best.cost):
            best = res
            best_alpha = res.x[n:] if stable else alphas(res.x[n:])
    if best is None or best_alpha is None:
        raise FitError("the Ogden fit failed from every start (non-finite parameters)")
    order = np.argsort(best_alpha)
    return np.concatenate([best.x[:n][order], best_alpha[order]])

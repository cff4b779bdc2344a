"""Fitness of a response against an objective, at every reported pressure (Eq 4.1).

Reading of the dissertation (section 4.5.4). Eq 4.1 is evaluated at each of the ten
solution increments, with ``Y`` the *displacements* of the tracked unit centres (the mean
of the four nodes at the cavity's vertices) and of the desired profile:

.. math:: F_k = \\sqrt{\\sum_i (Y^{desired}(x_{k,i}) - Y_{k,i})^2}

Here ``Y_{k,i} = y_{k,i} - y^{ref}_i`` is the height of centre ``i`` at level ``k`` above
its own undeformed position - the displacement the dissertation reads from its punch file,
i.e. the height above the undeformed axis - and the target is evaluated at the centre's
*current* position along the actuator, ``x_{k,i}`` (undeformed x plus the x displacement),
so that an actuator that shortens as it bends is compared where its units are. The lowest
``F_k`` over the levels selects the reported pressure (method 2 of section 4.3). Ties go to
the lower pressure.

Polar targets ``r = f(theta)`` use the same datum: centre ``i`` sits at
``(x_{k,i}, Y_{k,i})`` relative to the base, with radius ``r`` and angle ``theta``
(unwrapped along the actuator so a curl past 180 degrees keeps counting), and the error is
the root of the summed squared radial differences.

A path (:class:`~pneumorph.design.objectives.paths.PathTarget`) is matched by the centres as the model
reports them, with no datum: each centre's distance to its stretch of the path, summed in
squares as Eq 4.1 (:mod:`pneumorph.design.objectives.paths`).

Contact goals (``grip``, ``wrap``) read the forces and contact a model with obstacles reports
(:mod:`pneumorph.design.objectives.contact`).

Tip goals (Table 6.1) use the tip in the same frame: ``X`` = the tip's x, ``Y`` = its
height above the undeformed tip, the distance to the base ``sqrt(X^2 + Y^2)`` and the curl
in degrees (counter-clockwise positive).

A failed response (not converged, or every level NaN) scores the worst value
(``+inf`` when minimising, ``-inf`` when maximising); a single NaN level scores the worst
value at that level only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.objectives.contact import ContactGoal, contact_values
from pneumorph.design.objectives.paths import PathTarget
from pneumorph.design.objectives.targets import Objective, ProfileTarget, Sense, StagedTarget
from pneumorph.models.response import Response

FloatArray = NDArray[np.float64]


def worst(sense: Sense) -> float:
    """The worst possible fitness for an objective's sense.

    >>> worst("min"), worst("max")
    (inf, -inf)
    """
    return float("inf") if sense == "min" else float("-inf")


@dataclass(frozen=True)
class Score:
    """The fitness of one design at every reported level, and its best level.

    Attributes
    ----------
    values : ndarray, shape (k,)
        Objective value per level (mm or degrees); worst where the level is NaN.
    level : int or None
        Index of the best level; None for a failed design.
    value : float
        The objective value at the best level; the worst value for a failed design.
    pressure : float or None
        The pressure of the best level (MPa).
    failed : bool
        True if the design did not give a usable response.
    """

    values: FloatArray
    level: int | None
    value: float
    pressure: float | None
    failed: bool = False


def profile_error_array(
    centres: FloatArray, reference_centres: FloatArray, target: ProfileTarget, length: float
) -> FloatArray:
    """Eq 4.1 for stacked centres ``(..., n, 2)`` (or ``(..., n, 3)``) against their references.

    Returns the error over the last two axes, shape ``centres.shape[:-2]``. A Cartesian target
    counts a centre's distance in y and z (:meth:`ProfileTarget.squared_error`): centres of
    two columns lie at ``z = 0``, and a planar target is ``z = 0``.
    """
    x = centres[..., 0]
    y = centres[..., 1] - reference_centres[..., 1]
    if target.coordinates == "cartesian":
        z = centres[..., 2] - reference_centres[..., 2] if centres.shape[-1] == 3 else None
        with np.errstate(invalid="ignore"):
            return np.sqrt(np.sum(target.squared_error(x, y, length, z), axis=-1))
    theta = np.unwrap(np.arctan2(y, x), axis=-1)
    want, got = target.curve(theta, length), np.hypot(x, y)
    with np.errstate(invalid="ignore"):
        return np.sqrt(np.sum((want - got) ** 2, axis=-1))


def path_error_array(centres: FloatArray, reference_centres: FloatArray, target: PathTarget, length: float,
                     height: float) -> FloatArray:
    """A path's value for stacked centres ``(..., n, 2)`` or ``(..., n, 3)``, shape ``centres.shape[:-2]`` (mm).

    The centres count as they are, but for z, which is measured from the undeformed centres' (the
    mid-plane); a relative path (a preset) is drawn for an actuator ``length`` mm long whose axis
    lies ``height`` mm up (:meth:`~pneumorph.design.objectives.paths.PathTarget.at`).
    """
    c = np.asarray(centres, dtype=float)
    if c.shape[-1] == 3:
        c = c.copy()
        c[..., 2] -= np.asarray(reference_centres, dtype=float)[..., 2]
    with np.errstate(invalid="ignore"):
        return target.at(length, height).error(c)


def path_errors(response: Response, target: PathTarget) -> FloatArray:
    """A path's value at every reported level, shape (k,); NaN where a level is missing.

    Examples
    --------
    >>> import numpy as np
    >>> from pneumorph.design.objectives.paths import path_target
    >>> ref = np.array([[5.0, 4.5], [15.0, 4.5]])
    >>> r = Response.empty("00", np.array([0.01]), ref, np.array([20.0, 6.0]))
    >>> r.centres[0] = [[5.0, 5.5], [15.0, 4.5]]; r.tip[0] = [20.0, 6.0]; r.curl[0] = 0.0
    >>> path_errors(r, path_target([[0, 4.5], [20, 4.5]])).tolist()  # the first centre 1 mm off the path
    [1.0]
    """
    return path_error_array(response.centres, response.reference_centres[None], target,
                            float(response.reference_tip[0]), float(response.reference_tip[1]))


def profile_errors(response: Response, target: ProfileTarget) -> FloatArray:
    """Eq 4.1 at every reported level, shape (k,); NaN where a level is missing.

    Examples
    --------
    >>> import numpy as np
    >>> from pneumorph.design.objectives.targets import profile_target
    >>> ref = np.array([[5.0, 0.0], [15.0, 0.0]])
    >>> r = Response.empty("00", np.array([0.01]), ref, np.array([20.0, 0.0]))
    >>> r.centres[0] = [[5.0, 1.0], [15.0, 2.0]]; r.tip[0] = [20.0, 2.0]; r.curl[0] = 0.0
    >>> profile_errors(r, profile_target("y = 0.1*x")).round(6).tolist()  # sqrt(0.5^2 + 0.5^2)
    [0.707107]
    """
    return profile_error_array(response.centres, response.reference_centres[None], target,
                               float(response.reference_tip[0]))


def tip_value_array(tip: FloatArray, reference_tip: FloatArray, curl: FloatArray, name: str,
                    point: tuple[float, ...] | None = None) -> FloatArray:
    """The quantity a tip goal optimises for stacked tips ``(..., 2)`` (or ``(..., 3)``) and curls ``(...)``.

    ``reach`` with a point ``(x, y, z)`` or a tip of three columns is the distance in space (a
    tip of two columns, and a point of two, lie at z = 0).

    >>> tip_value_array(np.array([3.0, 4.0]), np.zeros(2), np.zeros(()), "reach", (0.0, 0.0, 12.0)).item()
    13.0
    """
    x = tip[..., 0]
    y = tip[..., 1] - reference_tip[..., 1]
    if name in ("max-x", "min-x"):
        return x.copy()
    if name in ("max-y", "min-y"):
        return y
    if name == "min-distance":
        return np.hypot(x, y)
    if name == "max-curl":
        return np.array(curl, dtype=float, copy=True)
    if name == "reach" and point is not None and (len(point) == 3 or tip.shape[-1] == 3):
        z = tip[..., 2] - reference_tip[..., 2] if tip.shape[-1] == 3 else np.zeros_like(x)
        pz = point[2] if len(point) == 3 else 0.0  # a point (x, y) lies in the plane z = 0
        return np.sqrt((x - point[0]) ** 2 + (y - point[1]) ** 2 + (z - pz) ** 2)
    if name == "reach" and point is not None:
        return np.hypot(x - point[0], y - point[1])
    raise ValueError(f"no tip quantity for goal {name!r}")


def tip_values(response: Response, name: str, point: tuple[float, ...] | None = None) -> FloatArray:
    """The quantity a tip goal optimises, at every reported level, shape (k,)."""
    return tip_value_array(response.tip, response.reference_tip, response.curl, name, point)


def objective_values(response: Response, objective: Objective) -> FloatArray:
    """Raw objective value at every level (NaN where the level is missing).

    A :class:`~pneumorph.design.objectives.targets.StagedTarget` has its combined value at the level of
    its highest stage and the worst value elsewhere
    (:meth:`~pneumorph.design.objectives.targets.StagedTarget.at_levels`).
    """
    if isinstance(objective, StagedTarget):
        return objective.at_levels(stage_values(response, objective), response.pressures)
    if isinstance(objective, ProfileTarget):
        return profile_errors(response, objective)
    if isinstance(objective, PathTarget):
        return path_errors(response, objective)
    if isinstance(objective, ContactGoal):
        return contact_values(response, objective)
    return tip_values(response, objective.name, objective.point)


def stage_values(response: Response, objective: StagedTarget) -> FloatArray:
    """Each stage's value at its own level (mm), shape (S,).

    Examples
    --------
    >>> import numpy as np
    >>> from pneumorph.design.objectives.targets import make_objective, staged_target
    >>> ref = np.array([[5.0, 0.0], [15.0, 0.0]])
    >>> r = Response.empty("00", np.array([0.01, 0.02]), ref, np.array([20.0, 0.0]))
    >>> r.centres[:] = ref; r.centres[1, :, 1] = 1.0; r.tip[:] = [20.0, 0.0]; r.curl[:] = 0.0
    >>> t = staged_target([(0.01, make_objective("y = 0*x")), (0.02, make_objective("y = 0*x"))])
    >>> stage_values(r, t).tolist()  # flat at 10 kPa; both centres 1 mm up at 20 kPa: sqrt(2)
    [0.0, 1.4142135623730951]
    >>> objective_values(r, t).tolist()  # the root-sum-square at the top stage's level
    [inf, 1.4142135623730951]
    """
    levels = objective.levels(response.pressures)
    return np.array([objective_values(response, stage.target)[k] for stage, k in zip(objective.stages, levels,
                                                                                       strict=True)])


def failed_score(objective: Objective, n_levels: int) -> Score:
    """The score of a design that could not be evaluated."""
    bad = worst(objective.sense)
    return Score(np.full(n_levels, bad), None, bad, None, failed=True)


def score(response: Response | None, objective: Objective, n_levels: int | None = None) -> Score:
    """Fitness of a response at every level and its best level.

    Parameters
    ----------
    response : Response or None
        None (or a non-converged response) for a failed solve.
    objective : ProfileTarget or TipGoal
    n_levels : int, optional
        Number of levels of a failed design's score (default: the response's, else 0).

    Returns
    -------
    Score

    Examples
    --------
    >>> import numpy as np
    >>> from pneumorph.design.objectives.targets import tip_goal
    >>> ref = np.array([[5.0, 0.0]])
    >>> r = Response.empty("0", np.array([0.02, 0.04]), ref, np.array([10.0, 0.0]))
    >>> r.centres[:] = ref; r.tip[:] = [[9.0, 3.0], [7.0, 5.0]]; r.curl[:] = [20.0, 45.0]
    >>> s = score(r, tip_goal("max-y"))
    >>> s.level, s.value, s.pressure
    (1, 5.0, 0.04)
    >>> score(None, tip_goal("max-y"), n_levels=2).value
    -inf
    """
    if response is None or not response.converged:
        k = n_levels if n_levels is not None else (response.n_levels if response is not None else 0)
        return failed_score(objective, k)
    values = objective_values(response, objective)
    bad = worst(objective.sense)
    values = np.where(np.isfinite(values), values, bad)
    if not np.isfinite(values).any():
        return Score(values, None, bad, None, failed=True)
    level = int(np.argmin(values) if objective.sense == "min" else np.argmax(values))
    return Score(values, level, float(values[level]), float(response.pressures[level]))

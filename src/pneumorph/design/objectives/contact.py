"""Objectives over obstacles: the grip force on them and the wrap (their contact length or area), maximised.

A model with obstacles (``[[model.obstacle]]``, :mod:`pneumorph.models.fe.obstacles`) reports, at every
pressure level, the force the actuator exerts on each obstacle and how much of its surface touches it
(``metadata["contact"]``). These goals read them:

- ``grip``: the force on the obstacles (N), the magnitudes summed over all of them;
- ``wrap``: the contact length (2D, mm) or area (3D, mm^2), summed over all of them.

Only an FE model with contact measures them: the chain model knows no contact, so a certified search
cannot hold them and a run over obstacles searches with FE (the genetic algorithm or the exhaustive
search, :meth:`~pneumorph.design.config.DesignConfig.searchable`). A response without contact metadata
(a model without obstacles) has no value for them: :func:`contact_values` refuses it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import SearchConfigError

#: the contact goals by name: what each sums over the obstacles at a level, and its label
CONTACT_GOALS: dict[str, tuple[str, str]] = {
    "grip": ("force_magnitude_n", "maximum grip force on the obstacles (N)"),
    "wrap": ("contact", "maximum contact with the obstacles (length in 2D, mm; area in 3D, mm^2)"),
}


@dataclass(frozen=True)
class ContactGoal:
    """A goal over the obstacles of the model: ``grip`` or ``wrap`` (:data:`CONTACT_GOALS`), maximised.

    Examples
    --------
    >>> goal = ContactGoal("grip")
    >>> goal.sense, goal.unit, goal.label
    ('max', 'N', 'maximum grip force on the obstacles (N)')
    """

    name: str
    sense: Literal["max"] = field(default="max", init=False)
    point: None = field(default=None, init=False)

    @property
    def unit(self) -> str:
        return "N" if self.name == "grip" else "mm or mm^2"

    @property
    def label(self) -> str:
        return CONTACT_GOALS[self.name][1]


def contact_values(response: Any, goal: ContactGoal) -> NDArray[np.float64]:
    """The goal's value at every reported level of ``response`` (a :class:`~pneumorph.models.Response`), shape
    (k,); NaN at a level not reached.

    Raises
    ------
    SearchConfigError
        The response has no contact metadata (its model has no obstacles).

    Examples
    --------
    >>> import numpy as np
    >>> from pneumorph.models.response import Response
    >>> r = Response.empty("0", np.array([0.01, 0.02]), np.zeros((1, 2)), np.array([10.0, 0.0]))
    >>> touch = [{"force_magnitude_n": 0.25, "contact_length_mm": 1.5}, {"force_magnitude_n": 0.5,
    ...          "contact_length_mm": 0.5}]
    >>> r.metadata["contact"] = {"levels": [{"obstacles": [{"force_magnitude_n": 0.0, "contact_length_mm": 0.0}]},
    ...                                     {"obstacles": touch}]}
    >>> contact_values(r, ContactGoal("grip")).tolist(), contact_values(r, ContactGoal("wrap")).tolist()
    ([0.0, 0.75], [0.0, 2.0])
    """
    contact = response.metadata.get("contact")
    if contact is None:
        raise SearchConfigError(f"the objective {goal.name!r} needs obstacles in the model ([[model.obstacle]]): "
                                "the response has no contact")
    key = CONTACT_GOALS[goal.name][0]
    out = np.full(len(response.pressures), np.nan)
    for k, level in enumerate(contact["levels"][: len(out)]):
        obstacles = level["obstacles"]
        if key == "contact":
            out[k] = sum(o.get("contact_length_mm", o.get("contact_area_mm2", 0.0)) for o in obstacles)
        else:
            out[k] = sum(o[key] for o in obstacles)
    return out


def contact_goal(name: str) -> ContactGoal:
    """The contact goal called ``name``.

    Raises
    ------
    SearchConfigError
        A name that is not one of :data:`CONTACT_GOALS`.

    >>> contact_goal("wrap").label
    'maximum contact with the obstacles (length in 2D, mm; area in 3D, mm^2)'
    """
    if name not in CONTACT_GOALS:
        raise SearchConfigError(f"contact goals are {', '.join(CONTACT_GOALS)}, got {name!r}")
    return ContactGoal(name)


def check_contact_goal(objective: Any, model: Any) -> None:
    """Refuse a contact goal on a model without obstacles, before any solve.

    >>> check_contact_goal(ContactGoal("grip"), object())
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: the objective 'grip' needs obstacles in the model: give
    [[model.obstacle]] (a cylinder to grip, say) in the config's [model]
    """
    if isinstance(objective, ContactGoal) and not getattr(model, "obstacles", ()):
        raise SearchConfigError(f"the objective {objective.name!r} needs obstacles in the model: give "
                                "[[model.obstacle]] (a cylinder to grip, say) in the config's [model]")


__all__ = ["CONTACT_GOALS", "ContactGoal", "check_contact_goal", "contact_goal", "contact_values"]

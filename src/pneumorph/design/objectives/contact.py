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

A goal may also ask the finger to clear the obstacles at a lower pressure (``[design.clear]``,
:class:`Clearance`): at that level of the ramp no point of the actuator's outer surface may come closer to any
obstacle than ``clearance_mm``, while the grip or wrap counts at the levels above it. A design that does not clear
scores as a failed one (the worst value at every level). The chain model screens the designs first
(:mod:`pneumorph.design.certified.clearing`): one whose free shape the chain's validated error proves to come too
close is rejected without an FE solve.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from pneumorph.checks import real
from pneumorph.errors import SearchConfigError

#: relative difference within which a stage's pressure (or a clearance's) is a level of the ramp
LEVEL_MATCH = 1e-6

#: the contact goals by name: what each sums over the obstacles at a level, and its label
CONTACT_GOALS: dict[str, tuple[str, str]] = {
    "grip": ("force_magnitude_n", "maximum grip force on the obstacles (N)"),
    "wrap": ("contact", "maximum contact with the obstacles (length in 2D, mm; area in 3D, mm^2)"),
}


@dataclass(frozen=True)
class Clearance:
    """The clearance a design must keep from every obstacle at one pressure of its ramp.

    Attributes
    ----------
    pressure : float
        The pressure (MPa), a level of the model's ramp.
    distance : float
        The least distance (mm, >= 0) between the actuator's outer surface and any obstacle there.
    """

    pressure: float
    distance: float = 0.0

    @property
    def label(self) -> str:
        return f"clearing the obstacles by >= {self.distance:g} mm at {self.pressure * 1e3:g} kPa"


@dataclass(frozen=True)
class ContactGoal:
    """A goal over the obstacles of the model: ``grip`` or ``wrap`` (:data:`CONTACT_GOALS`), maximised, with an
    optional :class:`Clearance` at a lower pressure.

    Examples
    --------
    >>> goal = ContactGoal("grip")
    >>> goal.sense, goal.unit, goal.label
    ('max', 'N', 'maximum grip force on the obstacles (N)')
    >>> ContactGoal("grip", Clearance(0.018, 1.0)).label
    'maximum grip force on the obstacles (N), clearing the obstacles by >= 1 mm at 18 kPa'
    """

    name: str
    clear: Clearance | None = None
    sense: Literal["max"] = field(default="max", init=False)
    point: None = field(default=None, init=False)

    @property
    def unit(self) -> str:
        return "N" if self.name == "grip" else "mm or mm^2"

    @property
    def label(self) -> str:
        return CONTACT_GOALS[self.name][1] + ("" if self.clear is None else f", {self.clear.label}")

    def clear_level(self, pressures: Any) -> int | None:
        """The level of :attr:`clear` among a ramp's ``pressures`` (MPa); None without one.

        Raises
        ------
        SearchConfigError
            The clearance's pressure is not a level of the ramp, or it is the top level (nothing above it to grip).

        >>> ContactGoal("grip", Clearance(0.018)).clear_level([0.009, 0.018, 0.027])
        1
        """
        if self.clear is None:
            return None
        p = np.asarray(pressures, dtype=float)
        near = np.flatnonzero(np.abs(p - self.clear.pressure) <= LEVEL_MATCH * self.clear.pressure)
        if not near.size or near[0] == len(p) - 1:
            levels = ", ".join(f"{v * 1e3:.4g}" for v in p[:-1])
            raise SearchConfigError(f"[design.clear] pressure_kpa = {self.clear.pressure * 1e3:g}: must be a level "
                                    f"of the model's ramp below its top, one of {levels} kPa")
        return int(near[0])


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
    k1 = goal.clear_level(response.pressures)
    if goal.clear is not None and k1 is not None:
        out[: k1 + 1] = np.nan  # the grip counts above the clearing level only
        if not clearance(contact, k1) >= goal.clear.distance:  # NaN (a level not reached) does not clear
            out[:] = np.nan
    return out


def clearance(contact: dict[str, Any], level: int) -> float:
    """The least clearance (mm) between the actuator's outer surface and any obstacle at ``level`` of a response's
    contact metadata; NaN for a level not reported.

    Raises
    ------
    SearchConfigError
        A level without clearances (a cached response of a pneumorph that did not report them).

    >>> clearance({"levels": [{"obstacles": [{"clearance_mm": 2.5}, {"clearance_mm": 0.75}]}]}, 0)
    0.75
    """
    levels = contact["levels"]
    if level >= len(levels):
        return float("nan")
    if any("clearance_mm" not in o for o in levels[level]["obstacles"]):
        raise SearchConfigError("a response with obstacles but no clearance (an evaluation cache entry of a "
                                "pneumorph that did not report it): give the run a fresh --cache")
    return float(min((o["clearance_mm"] for o in levels[level]["obstacles"]), default=np.nan))


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


def clearing(objective: Any, table: Any) -> Any:
    """``objective`` with the clearance of a ``[design.clear]`` table (``pressure_kpa``, ``clearance_mm``; None:
    ``objective`` as it is).

    Raises
    ------
    SearchConfigError
        A table on an objective that is no contact goal, an unknown key, a pressure that is not > 0 or a clearance
        that is not >= 0 (NaN included).

    >>> clearing(ContactGoal("wrap"), {"pressure_kpa": 18, "clearance_mm": 1}).clear
    Clearance(pressure=0.018, distance=1.0)
    """
    if table is None:
        return objective
    where = "[design.clear]"
    if not isinstance(objective, ContactGoal):
        raise SearchConfigError(f"{where} applies to a contact goal ({', '.join(CONTACT_GOALS)}), not to "
                                f"{objective.name!r}")
    if not isinstance(table, dict) or set(table) - {"pressure_kpa", "clearance_mm"} or "pressure_kpa" not in table:
        raise SearchConfigError(f"{where} must be a table of pressure_kpa (a level of the ramp) and clearance_mm "
                                f"(default 0), got {table!r}")
    pressure = real(table["pressure_kpa"], f"{where} pressure_kpa", 0.0, low_open=True, unit="kPa",
                    error=SearchConfigError)
    distance = real(table.get("clearance_mm", 0.0), f"{where} clearance_mm", 0.0, unit="mm", error=SearchConfigError)
    return replace(objective, clear=Clearance(pressure / 1e3, distance))


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


__all__ = ["CONTACT_GOALS", "LEVEL_MATCH", "Clearance", "ContactGoal", "check_contact_goal", "clearance", "clearing",
           "contact_goal", "contact_values"]

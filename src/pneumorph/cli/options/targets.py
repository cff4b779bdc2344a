"""The goal options of ``pneumorph design`` read into the design config's tables: ``--target path:FILE`` (its
points), ``--stage KPA:TARGET`` (``[[design.stage]]``) and ``--clear KPA[:MM]`` (``[design.clear]``), each
checked as the option that gave it (one line, exit 2) before any setting is merged."""

from __future__ import annotations

import math
from typing import Any

import click

from pneumorph.cli.options import params as P


def target_changes(target: str) -> dict[str, Any]:
    """The config's changes for ``--target``: a path from ``path:FILE`` (its points, read here), else the text."""
    head, sep, rest = target.partition(":")
    if sep and head.strip().lower() == "path":
        from pneumorph.design.objectives.paths import read_path

        route = read_path(rest.strip())
        return {"objective": "path", "path": route.points}
    return {"objective": target}


def stage_changes(stages: tuple[str, ...], other_target: bool, amplitude: float | None, periods: float | None,
                  units: int | None) -> dict[str, Any]:
    """The config's changes for ``--stage`` options (none without them), each stage's target checked along the
    built-in unit (and again along the model's)."""
    if not stages:
        return {}
    if other_target:
        raise click.UsageError("--stage gives the targets at each pressure: leave out --target, --objective and "
                               "--point")
    from pneumorph.design import DesignConfig

    stage = tuple(stage_option(text, amplitude, periods) for text in stages)
    with P.blame("--stage"):
        DesignConfig(objective="stages", stage=stage, units=units or DesignConfig.units)
    return {"objective": "stages", "stage": stage}


def clear_option(text: str, objective: str) -> dict[str, Any]:
    """``--clear KPA[:MM]`` as a ``[design.clear]`` table, checked for the contact goal ``objective``
    (:func:`~pneumorph.design.objectives.contact.clearing`; the level of the ramp when the run starts).

    >>> clear_option("27:1.5", "grip"), clear_option("27", "wrap")
    ({'pressure_kpa': 27.0, 'clearance_mm': 1.5}, {'pressure_kpa': 27.0})
    """
    from pneumorph.design.objectives.contact import CONTACT_GOALS, clearing, contact_goal

    parts = text.split(":")
    try:
        numbers = [float(v) for v in parts]
    except ValueError:
        numbers = []
    if len(numbers) not in (1, 2) or not all(math.isfinite(v) for v in numbers):
        raise click.BadParameter(f"{text!r} is not KPA[:MM] (e.g. 27:1, a clearance of 1 mm at 27 kPa)",
                                 param_hint="'--clear'")
    if objective not in CONTACT_GOALS:
        raise click.BadParameter(f"applies to --objective {' or '.join(CONTACT_GOALS)}, not to {objective!r}",
                                 param_hint="'--clear'")
    table = {"pressure_kpa": numbers[0], **({"clearance_mm": numbers[1]} if len(numbers) == 2 else {})}
    with P.blame("--clear"):
        clearing(contact_goal(objective), table)
    return table


def stage_option(text: str, amplitude: float | None, periods: float | None) -> dict[str, Any]:
    """One ``--stage KPA:TARGET`` as a ``[[design.stage]]`` table (its values checked by the config).

    >>> stage_option("18:reach 60 40", None, None)
    {'pressure_kpa': 18.0, 'objective': 'reach', 'point': (60.0, 40.0)}
    >>> stage_option("45: sin", 5.0, None)
    {'pressure_kpa': 45.0, 'objective': 'sin', 'amplitude': 5.0}
    """
    kpa, sep, target = text.partition(":")
    try:
        pressure = float(kpa)
    except ValueError:
        pressure = float("nan")
    if not sep or not target.strip() or not math.isfinite(pressure):
        raise click.BadParameter(f"{text!r} is not KPA:TARGET (e.g. 18:sin or '45:reach 60 40')",
                                 param_hint="'--stage'")
    words = target.split()
    if words[0].lower() == "reach":
        try:
            point = tuple(float(v) for v in words[1:])
        except ValueError:
            point = ()
        if len(point) not in (2, 3):
            raise click.BadParameter(f"{text!r}: reach needs the tip point X Y (or X Y Z) in mm, e.g. "
                                     "'45:reach 60 40'", param_hint="'--stage'")
        return {"pressure_kpa": pressure, "objective": "reach", "point": point}
    stage: dict[str, Any] = {"pressure_kpa": pressure, "objective": target.strip()}
    stage.update({k: v for k, v in (("amplitude", amplitude), ("periods", periods)) if v is not None})
    return stage


__all__ = ["clear_option", "stage_changes", "stage_option", "target_changes"]

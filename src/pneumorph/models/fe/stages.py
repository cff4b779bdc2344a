"""What a solve does before and around its pressure ramp: the weight first, then the ramp's driver.

Under gravity the unpressurised actuator is loaded with its weight (two substeps, the ramp's
Newton settings), and the pressure ramp starts from that state with gravity held. The ramp is
driven by the pressure, or by the cavities' volume with the pressure an output
(:class:`~pneumorph.fem.fast.volume.VolumeControl`, a model whose ramp has a ``volume``).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from pneumorph.errors import SimulationFailed
from pneumorph.fem import StepSettings, ramp
from pneumorph.fem.fast.volume import volume_control


def gravity_steps(steps: StepSettings) -> StepSettings:
    """The gravity stage of a ramp of ``steps``: two substeps, its Newton settings.

    >>> gravity_steps(StepSettings(increments=10, substeps=1)).substeps
    2
    """
    return replace(steps, increments=1, substeps=2)


def weigh(model: Any, body: Any, substep: Any, follow: Any, design: str) -> int:
    """Load ``model``'s unpressurised actuator with its weight; the Newton iterations it took.

    Raises
    ------
    SimulationFailed
        The actuator does not carry its own weight (before any pressure).
    """
    g = np.asarray(model.gravity, dtype=float)

    def apply(t: float) -> None:
        body.set_gravity(t * g)

    try:
        stats = ramp(body.items, body.field, apply, body.dof1, body.dof0, gravity_steps(model.ramp.steps),
                     on_substep=follow, substep=substep, predictor_order=model.predictor_order_for(design),
                     carry=model.carry_step)
    except SimulationFailed as exc:
        raise SimulationFailed(reached=0.0, cause=f"under its own weight, before any pressure: {exc.cause}",
                               design=design, pressure=model.ramp.pressure) from None
    return stats.newton_iterations


def before_the_ramp(model: Any, body: Any, substep: Any, follow: Any, design: str, metadata: dict[str, Any],
                    tip: Any, apply: Any) -> tuple[Any, Any, Any, int]:
    """The weight first (its tip into ``metadata``), then the ramp's driver: ``apply`` and ``substep`` as given
    (the pressure drives), or the volume control's (:func:`~pneumorph.fem.fast.volume.volume_control`).

    Returns
    -------
    apply, substep, control, gravity_iterations
        ``control`` is the volume control, or None.
    """
    iterations = 0
    if model.gravity is not None:
        iterations = weigh(model, body, substep, follow, design)
        metadata.update(gravity_mm_s2=list(model.gravity), gravity_tip=tip(body.displacement).tolist())
    control = volume_control(model.ramp.volume, substep, apply, body.displacement)
    if control is not None:  # the volume drives, the pressure of every level is an output
        apply, substep = control.apply, control
        metadata["volume0"] = control.volume0
    return apply, substep, control, iterations


__all__ = ["before_the_ramp", "gravity_steps", "weigh"]

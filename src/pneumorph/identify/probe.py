"""The evaluator's model of an identification: an FE model whose response carries the shape a scan sees.

:class:`ShapeProbe` is an :class:`~pneumorph.models.response.ActuatorModel` (as the unit
optimisation's probe is): it solves a design with its FE model and returns the
:class:`~pneumorph.models.response.Response` with the
:class:`~pneumorph.correlation.ModelShape` at the last level (the scan's pressure) in its
metadata (``"model_shape"``). So every solve of a fit goes through the package's
evaluators (serial, processes, Dask, as ``(model, design)`` cases of ``iter_cases``) and
its SQLite cache, keyed by the probe's fingerprint (the FE model's and the shape's
revision): a rerun answers from the cache, an interrupted fit resumes.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from pneumorph.correlation.compare import ModelShape, model_shape
from pneumorph.errors import SimulationFailed
from pneumorph.models.fe import FEModel
from pneumorph.models.probe import Probe
from pneumorph.models.response import Response

#: bumped when what the probe stores changes (part of its fingerprint)
SHAPE_REVISION = 1


class ShapeProbe(Probe):
    """``model`` whose responses hold the deformed shape at the last level.

    Parameters
    ----------
    model : FEModel
        The model at one point of the parameter space (its ramp ends at the scan's pressure).

    Examples
    --------
    >>> from pneumorph.models.factory import make_model
    >>> probe = ShapeProbe(make_model(2, {"pressure_kpa": 10, "unit": {"element_size": 3.0}}))
    >>> shape = shape_of(probe.evaluate("01"))
    >>> shape.outline.shape[1:], len(shape.centres), shape.surface.shape
    ((2, 2), 2, (0, 3))
    """

    kind = "identify-shape"
    revision_key = "shape_revision"
    revision = SHAPE_REVISION
    metadata_key = "model_shape"

    def __init__(self, model: FEModel) -> None:
        super().__init__(model)
        self.fidelity = f"shape-{model.fidelity}"

    def measure(self, solution: Any) -> dict[str, Any]:
        """The deformed shape at the last level (:func:`~pneumorph.correlation.compare.model_shape`), as lists.

        Raises
        ------
        SimulationFailed
            The ramp stopped before the last level.
        """
        r = solution.response
        if not np.all(np.isfinite(solution.displacements[-1])):
            raise SimulationFailed(float(r.reached) if np.isfinite(r.reached) else 0.0,
                                   "the ramp did not reach the scan's pressure", r.orientation,
                                   float(self.model.ramp.pressure), partial=r)
        return shape_to_dict(model_shape(solution))


class JacobianProbe(ShapeProbe):
    """The shapes of a design at a point of the parameter space and at each of its Jacobian's steps.

    The point's model solves its ramp; each step's model (``variants``: the same mesh grid, one
    parameter moved) starts from that state at the top pressure
    (:func:`~pneumorph.models.fe.warmstart.solve_near`), a few Newton iterations instead of a
    ramp each, converged to the ramp's own test. The response holds the point's shape as a
    :class:`ShapeProbe`'s does, and the steps' shapes under ``"variants"`` (:func:`variant_shapes`);
    the fingerprint digests every model.

    Examples
    --------
    >>> from pneumorph.models.factory import make_model
    >>> coarse = {"pressure_kpa": 10, "unit": {"element_size": 3.0}}
    >>> probe = JacobianProbe(make_model(2, coarse), [make_model(2, {**coarse, "body_bulk_scale": 1.02})])
    >>> r = probe.evaluate("01")
    >>> moved = variant_shapes(r)[0]
    >>> direct = shape_of(ShapeProbe(probe.variants[0]).evaluate("01"))
    >>> float(np.abs(moved.outline - direct.outline).max()) < 1e-6
    True
    """

    kind = "identify-jacobian"

    def __init__(self, model: FEModel, variants: Any) -> None:
        super().__init__(model)
        self.variants = tuple(variants)

    def describe(self) -> dict[str, Any]:
        return {**super().describe(), "variants": [v.describe() for v in self.variants]}

    def measure(self, solution: Any) -> dict[str, Any]:
        """The point's shape and, under ``"variants"``, each step's (warm-started from ``solution``)."""
        from pneumorph.models.fe.warmstart import solve_near

        design = solution.response.orientation
        return {**super().measure(solution),
                "variants": [shape_to_dict(model_shape(solve_near(v, design, solution))) for v in self.variants]}


def variant_shapes(response: Response) -> list[ModelShape]:
    """The steps' shapes a :class:`JacobianProbe` stored in ``response``, in its variants' order."""
    return [shape_of(replace(response, metadata={"model_shape": d}))
            for d in response.metadata["model_shape"]["variants"]]


def shape_to_dict(shape: ModelShape) -> dict[str, Any]:
    """Plain lists of a :class:`ModelShape` (the outline's two end points per segment), for the cache."""
    return {"surface": shape.surface.tolist(), "side": shape.side.astype(int).tolist(),
            "outline": shape.outline[:, :2].tolist(), "centres": shape.centres.tolist(), "pitch": shape.pitch,
            "normals": shape.normals.tolist()}


def shape_of(response: Response) -> ModelShape:
    """The :class:`ModelShape` a :class:`ShapeProbe` stored in ``response`` (also read back from a cache).

    Raises
    ------
    KeyError
        The response was not made by a probe.
    """
    d = response.metadata["model_shape"]
    surface = np.asarray(d["surface"], dtype=float).reshape(-1, 3)
    outline = np.asarray(d["outline"], dtype=float).reshape(-1, 2, 2)
    return ModelShape(surface, np.asarray(d["side"], dtype=bool), outline,
                      np.asarray(d["centres"], dtype=float).reshape(-1, 2), float(d["pitch"]),
                      np.asarray(d["normals"], dtype=float).reshape(-1, 3))


__all__ = ["SHAPE_REVISION", "JacobianProbe", "ShapeProbe", "shape_of", "shape_to_dict", "variant_shapes"]

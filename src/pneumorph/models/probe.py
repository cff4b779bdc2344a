"""A model whose responses carry a measurement of the solution: the evaluators' unit of a probe.

A :class:`Probe` wraps an FE model and is itself an
:class:`~pneumorph.models.response.ActuatorModel`: it solves a design with the FE model and
returns its :class:`~pneumorph.models.response.Response` with what :meth:`Probe.measure`
reads from the full solution (fields the response alone does not keep) in its metadata. So
a study that needs more than the response still goes through the package's evaluators
(serial, processes, Dask) and its SQLite cache, keyed by the probe's fingerprint: the FE
model's description, the probe's kind and the revision of what it measures.

Subclasses name their ``kind``, ``revision_key`` and ``revision`` (bumped when what they
store changes) and ``metadata_key``, and implement :meth:`Probe.measure`
(:class:`~pneumorph.unitopt.probe.UnitProbe`, :class:`~pneumorph.identify.probe.ShapeProbe`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, ClassVar

from pneumorph.io.provenance import digest
from pneumorph.models.response import FloatArray, Response


class Probe:
    """An FE model whose responses hold a measurement of each solution (in ``metadata[metadata_key]``).

    Parameters
    ----------
    model : FEModel
        The model that solves the designs.
    """

    kind: ClassVar[str] = "probe"
    revision_key: ClassVar[str] = "revision"
    revision: ClassVar[int] = 1
    metadata_key: ClassVar[str] = "measures"

    def __init__(self, model: Any) -> None:
        self.model = model
        self.n_units = int(model.n_units)

    def describe(self) -> dict[str, Any]:
        """The probe's kind, its revision and the FE model's description (what its fingerprint digests)."""
        return {"probe": self.kind, self.revision_key: self.revision, "model": self.model.describe()}

    def fingerprint(self) -> str:
        return digest(self.describe())

    def pressures(self) -> FloatArray:
        return self.model.pressures()

    def measure(self, solution: Any) -> dict[str, Any]:
        """What the probe reads from a solution, as plain data (stored in the response and the cache)."""
        raise NotImplementedError

    def evaluate(self, orientation: str) -> Response:
        """Solve ``orientation`` and return the response with the measurement and the probe's fingerprint."""
        solution = self.model.solve(orientation)
        r = solution.response
        return replace(r, metadata={**r.metadata, self.metadata_key: self.measure(solution),
                                    "probe": self.fingerprint()})


__all__ = ["Probe"]

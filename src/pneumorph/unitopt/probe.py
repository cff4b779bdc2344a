"""The evaluator's model of the unit optimisation: a short 3D actuator that reports Omega, h_b, strain.

:class:`UnitProbe` is an :class:`~pneumorph.models.response.ActuatorModel`: it solves a
candidate unit in :class:`~pneumorph.models.fe.Full3D` (a few aligned units, the package's
3D model and ramp) and returns the :class:`~pneumorph.models.response.Response` with the
:class:`~pneumorph.unitopt.measures.UnitMeasures` in its metadata (``"unit_measures"``). So
every candidate goes through the package's evaluators (serial, processes, Dask, as a
``(model, design)`` case of ``iter_cases``) and its SQLite cache, keyed by the probe's
fingerprint (the 3D model's, the measures' revision): a rerun answers from the cache.

Why 3 units: Omega is a turn of an *interior* unit (one between two others, as in a long
actuator), the fewest units that have one is 3, and the interior unit of the 3-unit
actuator turns as the interior units of the 15-unit one (``docs/unit-library.md``, the
validation of the optimised units).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from pneumorph import checks
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import Full3D, RampSpec
from pneumorph.models.probe import Probe
from pneumorph.models.response import Response
from pneumorph.unitopt.measures import MEASURES_REVISION, UnitMeasures, measure

#: units of the probe actuator (the fewest with an interior unit)
DEFAULT_UNITS = 3
#: the 3D model's ramp with at most 2 halvings of a failed substep (Full3D's default: 6): a unit that needs more
#: is at a limit point before the design pressure, infeasible; near one the 6 halvings and the small substeps
#: after them cost 10-50 times a converging unit's solve (seen: 100-600 s against 4-14 s on a loaded machine).
#: The cut-backs are not part of the fingerprint (they change the converged states only within the tolerance)
PROBE_STEPS = replace(Full3D.default_steps, max_cutbacks=2)


class UnitProbe(Probe):
    """A candidate unit in a short aligned 3D actuator; ``evaluate`` adds its measures.

    Parameters
    ----------
    unit : UnitSpec
        The candidate.
    n_units : int
        Units of the actuator (at least 3).
    pressure : float
        Design pressure, MPa (the ramp's last level).

    Examples
    --------
    >>> probe = UnitProbe(UnitSpec(element_size=3.0), pressure=0.01)
    >>> probe.design, probe.fidelity
    ('000', 'unit-probe-3d')
    >>> r = probe.evaluate("000")
    >>> m = UnitMeasures.from_dict(r.metadata["unit_measures"])
    >>> bool(m.omega_deg > 0 and m.balloon_mm > 0 and m.strain > 0)
    True
    """

    fidelity = "unit-probe-3d"
    kind = "unitopt"
    revision_key = "measures_revision"
    revision = MEASURES_REVISION
    metadata_key = "unit_measures"

    def __init__(self, unit: UnitSpec, n_units: int = DEFAULT_UNITS, pressure: float = 0.045) -> None:
        n = checks.integer(n_units, "probe units", 3, checks.MAX_UNITS, limit="MAX_UNITS")
        super().__init__(Full3D(n, unit=unit, ramp_spec=RampSpec(pressure=pressure, steps=PROBE_STEPS)))
        self.unit = unit

    @property
    def design(self) -> str:
        """The one design the probe solves: every unit aligned (orientation 0)."""
        return "0" * self.n_units

    def measure(self, solution: Any) -> dict[str, Any]:
        """Omega, h_b and the strain of an aligned design's solution (:func:`~pneumorph.unitopt.measures.measure`).

        Raises
        ------
        SettingsError
            A design with a unit turned over (the measures read the soft wall at ``y = 0``).
        """
        r = solution.response
        return measure(solution.mesh, solution.displacements, float(r.curl[-1])).to_dict()


def measures_of(response: Response) -> UnitMeasures:
    """The measures a :class:`UnitProbe` stored in ``response`` (also when read back from a cache).

    Raises
    ------
    KeyError
        The response was not made by a probe.
    """
    return UnitMeasures.from_dict(response.metadata["unit_measures"])


__all__ = ["DEFAULT_UNITS", "PROBE_STEPS", "UnitProbe", "measures_of"]

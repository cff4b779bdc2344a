"""The unit optimisation's records: its settings (:class:`OptimiseSettings`) and its outcome
(:class:`UnitOptimisation`); the run: :mod:`pneumorph.unitopt.run`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pneumorph import checks
from pneumorph.unitopt.probe import DEFAULT_UNITS
from pneumorph.unitopt.problem import (
    UnitCandidate,
    check_strain_limit,
)
from pneumorph.unitopt.space import DesignSpace

#: largest principal nominal strain of Mold Star 15 at break: 440 % elongation at break (ASTM D-412), Smooth-On,
#: "Mold Star 15 SLOW" technical bulletin. The dissertation did not test to failure ("not concerned with material
#: failure", appendix A.2); its actuators held 45 kPa with 1.5 mm walls (section 4.2)
DEFAULT_STRAIN_LIMIT = 4.40

STRAIN_LIMIT_SOURCE = ("Smooth-On, Mold Star 15 SLOW technical bulletin: elongation at break 440 % (ASTM D-412); "
                       "nominal strain = largest principal stretch - 1")


@dataclass(frozen=True)
class OptimiseSettings:
    """What :func:`optimise` runs.

    Parameters
    ----------
    space : DesignSpace
        The varied dimensions and their bounds.
    strain_limit : float
        Largest principal nominal strain allowed in the body material (:data:`DEFAULT_STRAIN_LIMIT`).
    pressure : float
        Design pressure, MPa.
    n_units : int
        Units of the probe actuator (at least 3).
    pop_size, generations : int
        NSGA-II's population and generations (the initial population is generation 0).
    seed : int
        Seeds the start and pymoo.

    Raises
    ------
    SettingsError
        A non-positive strain limit, a population below 4, a count out of range.
    """

    space: DesignSpace = field(default_factory=DesignSpace.default)
    strain_limit: float = DEFAULT_STRAIN_LIMIT
    pressure: float = 0.045
    n_units: int = DEFAULT_UNITS
    pop_size: int = 16
    generations: int = 8
    seed: int = 0

    def __post_init__(self) -> None:
        check_strain_limit(self.strain_limit)
        checks.real(self.pressure, "pressure", 0.0, checks.MAX_PRESSURE_KPA / 1e3, low_open=True, unit="MPa",
                    limit="MAX_PRESSURE_KPA")
        checks.integer(self.n_units, "probe units", 3, checks.MAX_UNITS, limit="MAX_UNITS")
        checks.integer(self.pop_size, "population", 4, checks.MAX_POPULATION, limit="MAX_POPULATION")
        checks.integer(self.generations, "generations", 1, checks.MAX_GENERATIONS, limit="MAX_GENERATIONS")
        checks.integer(self.seed, "seed", 0, 2**32 - 1)

    def to_dict(self) -> dict[str, Any]:
        return {"space": self.space.to_dict(), "strain_limit": self.strain_limit,
                "strain_limit_source": STRAIN_LIMIT_SOURCE if self.strain_limit == DEFAULT_STRAIN_LIMIT else "user",
                "pressure_kpa": self.pressure * 1e3, "n_units": self.n_units, "pop_size": self.pop_size,
                "generations": self.generations, "seed": self.seed, "algorithm": "pymoo NSGA2"}


@dataclass(frozen=True)
class UnitOptimisation:
    """The outcome of :func:`optimise`.

    Attributes
    ----------
    settings : OptimiseSettings
    candidates : list of UnitCandidate
        Every candidate solved, in the order first asked for.
    front : list of UnitCandidate
        The feasible non-dominated candidates, by increasing h_b.
    base : UnitCandidate
        The base unit (the built-in one), solved with the same probe.
    solves, hits : int
        Candidates solved in this run and answered from the cache.
    """

    settings: OptimiseSettings
    candidates: list[UnitCandidate]
    front: list[UnitCandidate]
    base: UnitCandidate
    solves: int = 0
    hits: int = 0

    def better(self) -> list[UnitCandidate]:
        """Feasible candidates that turn more than the base unit at the same or a lower h_b, best Omega first."""
        b = self.base.measures
        if b is None:
            return []
        limit = self.settings.strain_limit
        out = [(c.measures.omega_deg, c) for c in self.candidates if c.feasible(limit) and c.measures is not None
               and c.measures.omega_deg > b.omega_deg and c.measures.balloon_mm <= b.balloon_mm]
        return [c for _, c in sorted(out, key=lambda pair: -pair[0])]

    def chosen(self) -> dict[str, UnitCandidate]:
        """The points written as unit files: ``max-omega``, ``min-balloon``, ``knee`` and ``better``."""
        if not self.front:
            return {}
        f = np.array([c.objectives() for c in self.front])
        span = np.where(np.ptp(f, axis=0) > 0, np.ptp(f, axis=0), 1.0)
        knee = int(np.argmin(np.linalg.norm((f - f.min(axis=0)) / span, axis=1)))
        out = {"max-omega": self.front[int(np.argmin(f[:, 0]))], "min-balloon": self.front[int(np.argmin(f[:, 1]))],
               "knee": self.front[knee]}
        better = self.better()
        if better:
            out["better"] = better[0]
        return out

"""Which algorithm a design run's settings ask for."""

from __future__ import annotations

from typing import Any

from pneumorph.design.algorithms.certified import CertifiedSearch
from pneumorph.design.algorithms.exhaustive import ExhaustiveSearch
from pneumorph.design.algorithms.ga import GeneticSearch
from pneumorph.design.algorithms.problem import Algorithm
from pneumorph.design.algorithms.robust import RobustSearch

#: the algorithm of each ``[design] search`` (``robust``: the certified search with ``[design] robust``)
ALGORITHMS: dict[str, type[Any]] = {
    "certified": CertifiedSearch,
    "robust": RobustSearch,
    "ga": GeneticSearch,
    "exhaustive": ExhaustiveSearch,
}


def algorithm_for(config: Any) -> Algorithm:
    """A new algorithm for a :class:`~pneumorph.design.config.DesignConfig`'s ``search`` (and ``robust``)."""
    key = "robust" if config.search == "certified" and config.robust is not None else config.search
    algorithm: Algorithm = ALGORITHMS[key]()
    return algorithm

"""The search strategies of a design run, one module each, with the interface of
:class:`pneumorph.design.algorithms.problem.Algorithm`.

- ``certified`` (:class:`CertifiedSearch`): every design scored by the chain model, the best
  verified by FE, with a bound on what any other design could do.
- ``robust`` (:class:`RobustSearch`): the certified search, then every design ranked by its
  worst or mean error under the mould tolerance (``[design] robust``).
- ``ga`` (:class:`GeneticSearch`): the genetic algorithm of chapter 4.
- ``exhaustive`` (:class:`ExhaustiveSearch`): all 2^n designs by FE.

A new strategy is a new module here with a class of that interface, named in :data:`ALGORITHMS`.

Examples
--------
>>> from pneumorph.design.config import DesignConfig
>>> [algorithm_for(DesignConfig(search=s)).name for s in ("certified", "ga", "exhaustive")]
['certified', 'ga', 'exhaustive']
>>> type(algorithm_for(DesignConfig(robust="worst"))).__name__
'RobustSearch'
"""

from pneumorph.design.algorithms.certified import CertifiedSearch
from pneumorph.design.algorithms.exhaustive import ExhaustiveSearch
from pneumorph.design.algorithms.ga import GeneticSearch
from pneumorph.design.algorithms.registry import ALGORITHMS, algorithm_for
from pneumorph.design.algorithms.robust import RobustSearch

__all__ = ["ALGORITHMS", "CertifiedSearch", "ExhaustiveSearch", "GeneticSearch", "RobustSearch", "algorithm_for"]

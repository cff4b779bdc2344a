"""Evaluating designs: serial, process-pool and Dask evaluators, and the evaluation cache.

Examples
--------
>>> from pneumorph.execution import CachedEvaluator, EvaluationCache, SerialEvaluator
>>> evaluator = CachedEvaluator(SerialEvaluator(), EvaluationCache(":memory:"))
>>> evaluator.solves, evaluator.hits
(0, 0)
"""

from pneumorph.execution.cache import (
    CachedEvaluator,
    EvaluationCache,
    chain_table_dir,
    default_cache_path,
)
from pneumorph.execution.evaluators import (
    DaskEvaluator,
    Evaluator,
    ProcessPoolEvaluator,
    SerialEvaluator,
    make_evaluator,
)
from pneumorph.execution.outcome import Outcome, solve

__all__ = [
    "CachedEvaluator",
    "DaskEvaluator",
    "EvaluationCache",
    "Evaluator",
    "Outcome",
    "ProcessPoolEvaluator",
    "SerialEvaluator",
    "chain_table_dir",
    "default_cache_path",
    "make_evaluator",
    "solve",
]

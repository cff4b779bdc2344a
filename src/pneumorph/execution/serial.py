"""The evaluators' one interface (:class:`Evaluator`) and the simplest of them, :class:`SerialEvaluator`
(see :mod:`pneumorph.execution.evaluators`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import Any, Protocol, runtime_checkable

from pneumorph.execution.outcome import Outcome, solve
from pneumorph.models.response import ActuatorModel

THREAD_VARIABLES = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS", "NUMEXPR_NUM_THREADS")


@runtime_checkable
class Evaluator(Protocol):
    """Solves designs of a model; see the module docstring."""

    def iter_evaluate(self, model: ActuatorModel, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]: ...

    def evaluate_many(self, model: ActuatorModel, designs: Iterable[str]) -> list[Outcome]: ...

    def iter_cases(self, cases: Iterable[tuple[ActuatorModel, str]]) -> Iterator[tuple[int, Outcome]]: ...

    def close(self) -> None: ...


class EvaluatorBase:
    def evaluate_many(self, model: ActuatorModel, designs: Iterable[str]) -> list[Outcome]:
        """Outcomes of ``designs``, in their order."""
        designs = list(designs)
        out: list[Outcome | None] = [None] * len(designs)
        for i, outcome in self.iter_evaluate(model, designs):  # type: ignore[attr-defined]
            out[i] = outcome
        return out  # type: ignore[return-value]

    def close(self) -> None:
        """Release workers (nothing to do for the serial evaluator)."""

    def __enter__(self) -> Any:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class SerialEvaluator(EvaluatorBase):
    """Solve the designs one after another in this process.

    Examples
    --------
    >>> SerialEvaluator().evaluate_many(object(), [])
    []
    """

    def iter_evaluate(self, model: ActuatorModel, designs: Iterable[str]) -> Iterator[tuple[int, Outcome]]:
        for i, design in enumerate(designs):
            yield i, solve(model, design)

    def iter_cases(self, cases: Iterable[tuple[ActuatorModel, str]]) -> Iterator[tuple[int, Outcome]]:
        for i, (model, design) in enumerate(cases):
            yield i, solve(model, design)

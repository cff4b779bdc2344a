"""Exhaustive search over all ``2^n`` orientation vectors: the ground truth for the GA.

Mirror symmetry. Inverting every unit mirrors the actuator about its long axis, so the
response of ``mirror(d)`` is the response of ``d`` with ``y -> -y`` and the curl negated
(:func:`mirror_response`). Every objective is a function of the response, so with the
symmetry only the designs whose first unit is 0 are solved and the other half is derived,
exactly, for every objective:

==============================  ==============================================
objective                       the mirrored design's value
==============================  ==============================================
max-x, min-x, min-distance      the same as the original's
max-y, min-y                    from the tip height negated (max-y <-> min-y)
max-curl                        from the curl negated
reach (px, py)                  the original's distance to (px, -py)
profile y = f(x)                the original's error against -f(x) (sin <-> -sin)
profile r = f(theta)            the original's error against f(-theta)
==============================  ==============================================

This holds only for a model that is mirror-symmetric (no gravity across it, no obstacles); before
relying on it the search solves one design and its mirror and compares them (``verify_symmetry``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from pneumorph.design.objectives.fitness import Score
from pneumorph.design.objectives.targets import Objective, Sense
from pneumorph.design.search.scoring import Candidate, ScoreBook
from pneumorph.errors import SearchConfigError
from pneumorph.execution.evaluators import Evaluator
from pneumorph.execution.outcome import Outcome
from pneumorph.geometry.orientation import mirror
from pneumorph.models.response import ActuatorModel, Response

MAX_UNITS = 20
"""Longest actuator searched exhaustively by default (2^20 = 1,048,576 designs)."""


def mirror_response(response: Response) -> Response:
    """The response of the mirrored design: y mirrored about the axis, curl negated.

    The axis is the height of the undeformed tip (the centre of the end face).

    Examples
    --------
    >>> import numpy as np
    >>> r = Response.empty("01", np.array([0.045]), np.array([[5.0, 0.0], [15.0, 0.0]]), np.array([20.0, 0.0]))
    >>> r.centres[0] = [[5.0, 1.0], [14.0, 3.0]]; r.tip[0] = [19.0, 5.0]; r.curl[0] = 30.0
    >>> m = mirror_response(r)
    >>> m.orientation, m.centres[0, :, 1].tolist(), m.tip[0].tolist(), m.curl.tolist()
    ('10', [-1.0, -3.0], [19.0, -5.0], [-30.0])
    """
    axis = float(response.reference_tip[1])

    def flip(a: np.ndarray) -> np.ndarray:
        out = np.array(a, dtype=float, copy=True)
        out[..., 1] = 2.0 * axis - out[..., 1]
        return out

    return Response(
        orientation=mirror(response.orientation),
        pressures=response.pressures.copy(),
        centres=flip(response.centres),
        reference_centres=flip(response.reference_centres),
        tip=flip(response.tip),
        reference_tip=flip(response.reference_tip),
        curl=-response.curl,
        converged=response.converged,
        reached=response.reached,
        failure=response.failure,
        metadata={**response.metadata, "mirrored_from": response.orientation},
    )


def mirror_outcome(outcome: Outcome) -> Outcome:
    """The outcome of the mirrored design, derived without a solve."""
    resp = None if outcome.response is None else mirror_response(outcome.response)
    return replace(outcome, design=mirror(outcome.design), response=resp, wall_time=0.0)


def symmetry_deviation(a: Response, b: Response) -> float:
    """Largest difference between ``b`` and the mirror of ``a`` (mm; curl in degrees)."""
    m = mirror_response(a)
    parts = [m.centres - b.centres, m.tip - b.tip, m.curl - b.curl]
    return float(max(np.nanmax(np.abs(p)) if np.isfinite(p).any() else 0.0 for p in parts))


@dataclass(frozen=True)
class ExhaustiveResult:
    """All designs of an actuator, scored.

    Attributes
    ----------
    sense : {"min", "max"}
    n_designs : int
        ``2^n``.
    solves : int
        New model solves (cache hits and mirrored designs excluded).
    symmetry : bool
        Whether half of the designs were derived by mirror symmetry.
    hall_of_fame : tuple of Candidate
        The best designs, best first.
    wall_time : float
    scores : dict
        Every design and its score.
    """

    sense: Sense
    n_designs: int
    solves: int
    symmetry: bool
    hall_of_fame: tuple[Candidate, ...]
    wall_time: float
    scores: dict[str, Score] = field(repr=False)
    ranking: tuple[str, ...] = field(repr=False, default=())

    @property
    def best(self) -> Candidate:
        return self.hall_of_fame[0]


def all_designs(n: int, first: str | None = None) -> list[str]:
    """Every orientation vector of ``n`` units in binary order (optionally a fixed first unit).

    >>> all_designs(2), all_designs(3, first="0")
    (['00', '01', '10', '11'], ['000', '001', '010', '011'])
    """
    if first is None:
        return [format(i, f"0{n}b") for i in range(2**n)]
    return [first + format(i, f"0{n - 1}b") if n > 1 else first for i in range(2 ** (n - 1))]


def mirror_holds(model: ActuatorModel) -> bool:
    """Whether a design and its mirror give mirrored responses: no gravity across the actuator (y) and no
    obstacles (they are not mirrored with the design)."""
    if getattr(model, "obstacles", ()):
        return False
    gravity = getattr(model, "gravity", None)
    return gravity is None or len(gravity) < 2 or gravity[1] == 0.0


def run_exhaustive(
    model: ActuatorModel,
    objective: Objective,
    evaluator: Evaluator | None = None,
    symmetry: bool | None = None,
    verify_symmetry: bool = True,
    batch_size: int = 64,
    hall_of_fame: int = 10,
    on_progress: Callable[[int, int], None] | None = None,
    max_units: int = MAX_UNITS,
) -> ExhaustiveResult:
    """Evaluate every design of ``model`` and rank them.

    Parameters
    ----------
    model : ActuatorModel
    objective : ProfileTarget or TipGoal
    evaluator : Evaluator, optional
        Serial by default; batches of ``batch_size`` designs are sent at once.
    symmetry : bool, optional
        Solve only designs starting with 0 and derive their mirrors. Default: unless the
        model's gravity has a component across the actuator (y), which the mirror reverses.
    verify_symmetry : bool
        With ``symmetry``, first solve one design and its mirror and stop with an error if
        the model is not mirror-symmetric (one extra solve).
    hall_of_fame : int
        Number of best designs kept with their responses.
    on_progress : callable, optional
        Called with (designs scored, designs in total): once before the first solve, as each
        solve finishes (a design and its mirror) and after each batch.
    max_units : int
        Refuse longer actuators (``2^n`` grows fast).

    Raises
    ------
    SearchConfigError
        Fewer than 1 or more than ``max_units`` units, or a model that is not
        mirror-symmetric when ``verify_symmetry`` is set.
    """
    start = time.perf_counter()
    book = ScoreBook(model, objective, evaluator)
    n = book.n_units
    if n > max_units:
        raise SearchConfigError(
            f"exhaustive search over {n} units means 2^{n} = {2**n:,} designs; "
            f"at most {max_units} units are searched exhaustively - use the genetic algorithm"
        )
    if batch_size < 1:
        raise SearchConfigError(f"the batch size must be at least 1, got {batch_size}")
    if symmetry is None:
        symmetry = mirror_holds(model)
    total = 2**n
    todo = all_designs(n, first="0") if symmetry else all_designs(n)
    say = on_progress or (lambda done, total: None)
    say(0, total)  # before the first solve: the run has started, nothing is scored yet
    if symmetry and verify_symmetry and n > 1:
        _verify(book, todo[1])
    for lo in range(0, len(todo), batch_size):
        _score_batch(book, todo[lo : lo + batch_size], symmetry, lambda: say(len(book.scores), total))
    ranking = book.ranking()
    return ExhaustiveResult(
        objective.sense,
        total,
        book.solves,
        symmetry,
        book.hall_of_fame(hall_of_fame),
        time.perf_counter() - start,
        dict(book.scores),
        tuple(ranking),
    )


def _score_batch(book: ScoreBook, batch: list[str], symmetry: bool, said: Callable[[], None]) -> None:
    """Score ``batch`` (and with ``symmetry`` the mirrors), calling ``said`` as each solve finishes (a batch is
    solved in parallel; its outcomes come as they end) and once more at the end."""
    new = [d for d in batch if d not in book.outcomes]
    for _, outcome in book.evaluator.iter_evaluate(book.model, new) if new else ():
        book.solves += outcome.solved
        book.add(outcome)
        if symmetry and mirror(outcome.design) not in book.scores:
            book.add(mirror_outcome(outcome))
        said()
    if symmetry:
        for d in batch:
            if mirror(d) not in book.scores:
                book.add(mirror_outcome(book.outcomes[d]))
    said()


def _verify(book: ScoreBook, design: str) -> None:
    a, b = book.evaluator.evaluate_many(book.model, [design, mirror(design)])
    for o in (a, b):
        book.solves += o.solved
        book.add(o)
    if a.ok != b.ok:
        raise SearchConfigError(
            f"the model is not mirror-symmetric: design {a.design} {'converged' if a.ok else 'failed'} but its "
            f"mirror {b.design} {'converged' if b.ok else 'failed'}; search with symmetry=False"
        )
    if a.ok and b.ok:
        assert a.response is not None and b.response is not None
        length = float(a.response.reference_tip[0])
        dev = symmetry_deviation(a.response, b.response)
        if dev > 1e-6 * max(1.0, length):
            raise SearchConfigError(
                f"the model is not mirror-symmetric: design {b.design} differs from the mirror image of "
                f"{a.design} by {dev:.3g} (mm or degrees); search with symmetry=False"
            )

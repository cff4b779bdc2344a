"""What the branch-and-bounds over designs share: their limits, how open prefixes are narrowed
and kept, and the union of two answers (:mod:`pneumorph.design.certified.planegrowth` in the plane,
:mod:`pneumorph.design.certified.spacegrowth` in space).
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.certified.bounds import ChainScores, chain_errors
from pneumorph.errors import SearchBudgetError
from pneumorph.models.chain.windows import design_numbers

FloatArray = NDArray[np.float64]


MAX_ENUMERATE = 20
"""Longest actuator whose 2^n designs are all scored; longer ones go through branch-and-bound
(over ``2k`` choices per unit: while ``(2k)^n <= 2^MAX_ENUMERATE``)."""


MAX_NODES = 500_000
"""Most open prefixes the branch-and-bound keeps at one depth, by default (``[design] max_open``); beyond them it
keeps those of lowest bound, and the certificate's floor bounds the rest."""

MAX_OPEN_MEMORY = 4e9
"""Bytes the open prefixes of one depth and their children may take (:func:`open_memory`): a sixth of a 24 GB
machine. A cap on open prefixes whose memory would pass it is refused before the search; the default cap is
lowered to fit it (a unit library's ``2k`` children per prefix)."""

PREFIX_BYTES = 300.0
"""Bytes of one child prefix per pressure level while a depth is pruned, in the plane: its state (point, angle,
partial sums) and the bound's temporaries. Measured on the 2D and on the 3D table, 22 units, 10 levels, a sine
profile with the bound x64 (2D) and x256 (3D; every prefix open): the peak memory grew by 6.0 kB per open prefix of
2 children from 50,000 to 200,000 kept, on both (BENCHMARKS.md, "The certified search's open prefixes")."""

SPACE_PREFIX_BYTES = 310.0
"""Bytes of one child prefix per pressure level while a depth is pruned, in space (a chain of the ``spatial``
library: each prefix's point and frame, partial sums in y and z). Measured as :data:`PREFIX_BYTES` on its 3D table,
14 units of 4 children a prefix, 10 levels, a sine with the bound x64 (every prefix open): 12.3 kB more per open
prefix from 40,000 to 160,000 kept, 308 bytes a child and level (BENCHMARKS.md, "The certified search's open
prefixes")."""

BEAM = 4096
"""Prefixes the first search keeps at every depth (a good design, whose cost sets the threshold)."""


class BranchOverflow(SearchBudgetError):
    """The branch-and-bound keeps more open prefixes than it may (:data:`MAX_NODES`, ``[design] max_open``)."""


def prefix_bytes(space: bool = False) -> float:
    """Bytes of one child prefix per pressure level: :data:`SPACE_PREFIX_BYTES` for a chain in space, else
    :data:`PREFIX_BYTES`.

    >>> prefix_bytes(), prefix_bytes(space=True)
    (300.0, 310.0)
    """
    return SPACE_PREFIX_BYTES if space else PREFIX_BYTES


def open_memory(nodes: int, choices: int, levels: int, space: bool = False) -> float:
    """Bytes the branch-and-bound takes at a depth with ``nodes`` open prefixes of ``choices`` children each, over
    ``levels`` pressure levels (:func:`prefix_bytes`; ``space``: a chain in space).

    >>> round(open_memory(MAX_NODES, 2, 10) / 1e9, 1), round(open_memory(MAX_NODES, 8, 10) / 1e9, 1)
    (3.0, 12.0)
    >>> round(open_memory(MAX_NODES, 4, 10, space=True) / 1e9, 1)
    6.2
    """
    return float(nodes) * int(choices) * int(levels) * prefix_bytes(space)


def open_cap(choices: int, levels: int, max_open: int | None = None, budget: float = MAX_OPEN_MEMORY,
             space: bool = False) -> int:
    """The open prefixes a branch-and-bound keeps at most: ``max_open`` if given (refused where its memory passes
    ``budget``), else :data:`MAX_NODES`, lowered to what fits ``budget`` (``space``: a chain in space, whose
    prefixes take more, :func:`prefix_bytes`).

    >>> open_cap(2, 10), open_cap(8, 10), open_cap(4, 10), open_cap(4, 10, space=True)
    (500000, 166666, 333333, 322580)
    >>> open_cap(2, 10, max_open=2_000_000)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchBudgetError: max_open 2,000,000: ... 12.0 GB at one depth ...; give at most 666,666
    """
    fits = int(budget // (int(choices) * int(levels) * prefix_bytes(space)))
    if max_open is None:
        return max(1, min(MAX_NODES, fits))
    if int(max_open) > fits:
        raise SearchBudgetError(
            f"max_open {int(max_open):,}: the open prefixes of a loose chain table could take "
            f"{open_memory(int(max_open), choices, levels, space) / 1e9:.1f} GB at one depth ({choices} children "
            f"each, {levels} levels{', in space' if space else ''}), past the {budget / 1e9:.1f} GB budget "
            f"(MAX_OPEN_MEMORY); give at most {fits:,}")
    return int(max_open)


class OpenWatch:
    """How many prefixes a branch-and-bound keeps open: the most at one depth (:attr:`peak`), whether they reached
    the search's ``cap``, and a line through ``say`` at most every ``every`` seconds while it grows (a long search's
    progress) and when they reach the cap. A probing run's smaller cap (:data:`MAX_NODES` / 25) is the probe's own.

    Examples
    --------
    >>> lines = []
    >>> with watching(OpenWatch(lines.append, cap=4, every=0.0)) as watch:
    ...     _ = narrow(np.ones(6, dtype=bool), np.arange(6.0), None, 4, 3, 9, spill=[])
    >>> watch.peak, watch.reached, lines
    (4, True, ['  branch-and-bound: unit 3/9, 4 open prefixes (at the cap of 4; the best kept)'])
    """

    def __init__(self, say: Callable[[str], None], cap: int = MAX_NODES, every: float = 2.0) -> None:
        self.say, self.cap, self.every = say, int(cap), float(every)
        self.peak, self.reached = 0, False
        self.said_at = time.monotonic()

    def __call__(self, p: int, n: int, count: int) -> None:
        self.peak = max(self.peak, int(count))
        full = int(count) >= self.cap
        if (full and not self.reached) or time.monotonic() - self.said_at >= self.every:
            self.said_at = time.monotonic()
            state = f"at the cap of {self.cap:,}; the best kept" if full else f"cap {self.cap:,}"
            self.say(f"  branch-and-bound: unit {p}/{n}, {count:,} open prefixes ({state})")
        self.reached = self.reached or full


def more_open_advice(*also: str) -> str:
    """What lists more designs than a branch-and-bound's cap of open prefixes lets it: the one wording of the
    overflow's error (:func:`narrow`) and of the cap's note (:func:`cap_text`), with ``also`` after it.

    >>> more_open_advice()
    'a tighter table (a smaller margin, a table within its tolerance) or a larger max_open'
    >>> more_open_advice("--search ga")
    'a tighter table (a smaller margin, a table within its tolerance), a larger max_open, or --search ga'
    """
    ways = ["a tighter table (a smaller margin, a table within its tolerance)", "a larger max_open", *also]
    return f"{ways[0]} or {ways[1]}" if len(ways) == 2 else f"{', '.join(ways[:-1])}, or {ways[-1]}"


def cap_text(chain: Any, margin: float, cap: int) -> str:
    """What a branch-and-bound that reached its cap of open prefixes says: the chain table's bound (its worst
    held-out centre error, times the margin) that left them open, and what lists more.

    >>> from pneumorph.models.chain.model import ChainModel
    >>> from pneumorph.models.chain.sources import find_table
    >>> from pneumorph.models.factory import make_model
    >>> print(cap_text(ChainModel(find_table(make_model(22, {"fidelity": "2d"})), 22), 32.0, 500_000))
    ... # doctest: +ELLIPSIS
      the open prefixes reached the cap of 500,000: the chain table's bound (centres within 2.94 mm, margin 32) ...
    """
    worst = float(np.max(chain_errors(chain, margin)["centre"]))
    advice = more_open_advice()
    return (f"  the open prefixes reached the cap of {cap:,}: the chain table's bound (centres within {worst:.3g} mm, "
            f"margin {margin:g}) prunes too little to list every design that can matter; the best were kept and the "
            f"certificate's floor bounds the rest. {advice[0].upper()}{advice[1:]} lists more")


_WATCH: ContextVar[Callable[[int, int, int], None] | None] = ContextVar("open_watch", default=None)


@contextlib.contextmanager
def watching(watch: OpenWatch) -> Iterator[OpenWatch]:
    """Within the block, every depth a branch-and-bound prunes (:func:`narrow`, no beam) reports to ``watch``."""
    token = _WATCH.set(watch)
    try:
        yield watch
    finally:
        _WATCH.reset(token)


def narrow(keep: NDArray[np.bool_], bound: FloatArray, beam: int | None, max_nodes: int, p: int,
            n: int, spill: list[float] | None = None) -> NDArray[np.bool_]:
    """The open prefixes (``keep``) cut to the ``beam`` of lowest bound, if given.

    With ``spill`` (a list), more than ``max_nodes`` open prefixes are cut to the ``max_nodes``
    of lowest bound instead, and the least bound of those dropped is appended to ``spill``.

    Raises
    ------
    BranchOverflow
        More than ``max_nodes`` stay open at depth ``p`` of ``n`` (without ``spill``).
    """
    if beam is not None and keep.sum() > beam:
        keep = np.zeros(len(bound), dtype=bool)
        keep[np.argpartition(bound, beam)[:beam]] = True
    if keep.sum() > max_nodes and spill is not None:
        open_ = np.flatnonzero(keep)
        order = np.argpartition(bound[open_], max_nodes)
        spill.append(float(bound[open_[order[max_nodes:]]].min()))
        keep = np.zeros(len(bound), dtype=bool)
        keep[open_[order[:max_nodes]]] = True
    if keep.sum() > max_nodes:
        raise BranchOverflow(f"branch-and-bound: {int(keep.sum()):,} open prefixes at unit {p} of {n}, past the cap "
                             f"of {max_nodes:,}: too many designs come within the chain's error bound of the best to "
                             f"list them all; {more_open_advice('--search ga')}")
    if beam is None and (watch := _WATCH.get()) is not None:
        watch(p, n, int(keep.sum()))
    return keep


def kept(bits: NDArray[np.uint8], state: dict[str, Any],
         keep: NDArray[np.bool_]) -> tuple[NDArray[np.uint8], dict[str, Any]]:
    """The prefixes ``keep`` marks and their state (what a depth sends back to the growth)."""
    return bits[keep], {key: v[keep] for key, v in state.items()}


def union(a: ChainScores, b: ChainScores) -> ChainScores:
    """The designs of ``a`` and those of ``b`` that ``a`` lacks (their scores as they are)."""
    extra = ~np.isin(design_numbers(b.bits, b.choices), design_numbers(a.bits, a.choices))
    return ChainScores(np.concatenate([a.bits, b.bits[extra]]), np.concatenate([a.per_level, b.per_level[extra]]),
                       np.concatenate([a.cost, b.cost[extra]]), np.concatenate([a.level, b.level[extra]]),
                       np.concatenate([a.optimistic, b.optimistic[extra]]), np.concatenate([a.bound, b.bound[extra]]),
                       floor=a.floor, choices=a.choices)


__all__ = ["BEAM", "MAX_ENUMERATE", "MAX_NODES", "MAX_OPEN_MEMORY", "PREFIX_BYTES", "SPACE_PREFIX_BYTES",
           "BranchOverflow", "OpenWatch", "cap_text", "kept", "more_open_advice", "narrow", "open_cap", "open_memory",
           "prefix_bytes", "union", "watching"]

"""What the branch-and-bounds over designs share: their limits, how open prefixes are narrowed
and kept, and the union of two answers (:mod:`pneumorph.design.certified.planegrowth` in the plane,
:mod:`pneumorph.design.certified.spacegrowth` in space).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.design.certified.bounds import ChainScores
from pneumorph.errors import SearchConfigError
from pneumorph.models.chain.windows import design_numbers

FloatArray = NDArray[np.float64]


MAX_ENUMERATE = 20
"""Longest actuator whose 2^n designs are all scored; longer ones go through branch-and-bound
(over ``2k`` choices per unit: while ``(2k)^n <= 2^MAX_ENUMERATE``)."""


MAX_NODES = 500_000
"""Most open prefixes the branch-and-bound keeps at one depth."""

BEAM = 4096
"""Prefixes the first search keeps at every depth (a good design, whose cost sets the threshold)."""


class BranchOverflow(SearchConfigError):
    """The branch-and-bound keeps more open prefixes than it may (:data:`MAX_NODES`)."""


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
        raise BranchOverflow(f"branch-and-bound: {int(keep.sum()):,} open prefixes at unit {p} of {n}: too many "
                             "designs come within the chain's error bound of the best to list them all - use "
                             "--search ga")
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


__all__ = ["BEAM", "MAX_ENUMERATE", "MAX_NODES", "BranchOverflow", "kept", "narrow", "union"]

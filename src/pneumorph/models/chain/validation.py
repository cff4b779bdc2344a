"""Validating a chain table on held-out designs: their errors, and the rounds a build solves them in.

The held-out designs are random designs of the full length (seeded, :func:`heldout_designs`);
:func:`prediction_errors` measures a table's centre, tip and curl errors against their FE
responses. A build (:func:`~pneumorph.models.chain.fit.build_table`) solves them in rounds
(:func:`validate_in_rounds`): a window is refused at the first round off by more than the
tolerance, and with ``early`` a table clearly within it stops after :data:`MIN_HELDOUT`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from pneumorph.models.chain.space import angle_between
from pneumorph.models.chain.table import ChainTable
from pneumorph.models.chain.windows import design_strings, random_designs, unit_codes
from pneumorph.models.response import Response

#: held-out designs after which the validation may stop early (:func:`validate_in_rounds` with ``early``)
MIN_HELDOUT = 6
#: the validation stops early once the worst held-out error is within this fraction of the tolerance
CLEAR_FRACTION = 0.5


def prediction_errors(table: ChainTable, responses: Sequence[Response]) -> dict[str, Any]:
    """Centre, tip and curl errors of the table's predictions against FE responses.

    Returns a dict with per-level lists ``centre_mean_mm``, ``centre_worst_mm``,
    ``tip_worst_mm``, ``curl_worst_deg``, ``norm_worst_mm`` (the worst root of the summed
    squared centre errors of one design), and ``designs``; a chain in space that predicts the
    end face's frame adds ``end_frame_worst_deg`` (the angle between its frame and the FE's).
    A table over several unit types adds ``per_type``: per symbol the ``centre_worst_mm``,
    ``centre_mean_mm`` (per level) and ``centres`` (how many) of the centres of the units of
    that type.
    """
    k = table.n_levels
    centre_err, tip_err, curl_err, norm_err, end_err = [], [], [], [], []
    types = []
    for r in responses:
        bits = table.designs(r.orientation)
        types.append(bits[0] // 2)
        c, t, cu = table.predict(bits)
        end = table.end_frames(bits)
        if end is not None and r.end_frame is not None:  # the angle between the end faces' frames
            end_err.append(np.degrees(angle_between(end[0], r.end_frame)))
        e = np.linalg.norm(c[0] - r.centres, axis=-1)  # (k, n); in space for a chain in space
        centre_err.append(e)
        norm_err.append(np.sqrt((e**2).sum(axis=1)))
        tip_err.append(np.linalg.norm(t[0] - r.tip, axis=-1))
        curl_err.append(np.abs(cu[0] - r.curl))
    if not responses:
        nan = [float("nan")] * k
        return {"designs": [], "centre_mean_mm": nan, "centre_worst_mm": nan, "tip_worst_mm": nan,
                "curl_worst_deg": nan, "norm_worst_mm": nan}
    all_c = np.concatenate(centre_err, axis=1)
    out: dict[str, Any] = {
        "designs": [r.orientation for r in responses],
        "centre_mean_mm": all_c.mean(axis=1).tolist(),
        "centre_worst_mm": all_c.max(axis=1).tolist(),
        "tip_worst_mm": np.max(tip_err, axis=0).tolist(),
        "curl_worst_deg": np.max(curl_err, axis=0).tolist(),
        "norm_worst_mm": np.max(norm_err, axis=0).tolist(),
    }
    if end_err:
        out["end_frame_worst_deg"] = np.max(end_err, axis=0).tolist()
    if table.alphabet:
        of_type = np.concatenate(types)
        out["per_type"] = {}
        for code, symbol in enumerate(table.alphabet):
            mine = all_c[:, of_type == code]
            out["per_type"][symbol] = {"centres": int(mine.shape[1])}
            if mine.size:
                out["per_type"][symbol].update(centre_mean_mm=mine.mean(axis=1).tolist(),
                                               centre_worst_mm=mine.max(axis=1).tolist())
    return out


def heldout_designs(n_units: int, count: int, exclude: Sequence[str] = (), seed: int = 1,
                    alphabet: Sequence[str] = (), symmetric: Sequence[int] = ()) -> list[str]:
    """``count`` random designs of ``n_units`` units, none of them in ``exclude`` (seeded).

    Over several unit types (``alphabet``) every unit is a random type and orientation (one
    orientation for the ``symmetric`` types' indices).
    """
    rng = np.random.default_rng(seed)
    out: list[str] = []
    taken = set(exclude)
    k = max(1, len(alphabet))
    limit = len(unit_codes(k, symmetric)) ** n_units - len(taken)
    while len(out) < min(count, limit):
        d = design_strings(random_designs(1, n_units, rng, k, symmetric) if k > 1 else
                           rng.integers(0, 2, size=(1, n_units), dtype=np.uint8), alphabet)[0]
        if d not in taken:
            taken.add(d)
            out.append(d)
    return out


def evaluator_workers(evaluator: Any) -> int:
    """How many designs an evaluator solves at once (its ``workers``, or its inner evaluator's; else 1)."""
    for candidate in (evaluator, getattr(evaluator, "inner", None)):
        workers = getattr(candidate, "workers", None)
        if isinstance(workers, int) and workers > 0:
            return workers
    return 1


def validate_in_rounds(table: ChainTable, tests: Sequence[str], solve: Callable[..., list[Response]],
              tolerance: float, early: bool, batch: int) -> dict[str, Any]:
    """The table's errors on held-out designs solved in rounds of ``batch``: all of them, unless one round refutes
    the table (a worst error above ``tolerance``) or, with ``early``, at least :data:`MIN_HELDOUT` designs show it
    clearly within (at most ``CLEAR_FRACTION * tolerance``)."""
    responses: list[Response] = []
    val = prediction_errors(table, [])
    stop = ""
    for lo in range(0, len(tests), batch):
        responses += solve(list(tests[lo : lo + batch]), "held-out", lo, len(tests))
        val = prediction_errors(table, responses)
        worst = max(val["centre_worst_mm"])
        if worst > tolerance:
            stop = "refuted"
            break
        if early and len(responses) >= MIN_HELDOUT and worst <= CLEAR_FRACTION * tolerance:
            stop = "clear"
            break
    val.update(heldout_solved=len(responses), heldout_planned=len(tests),
               stopped_early=stop if len(responses) < len(tests) else "")
    return val


def stop_note(val: dict[str, Any], tolerance: float) -> str:
    """Why the validation stopped before its last held-out design, as a clause ('' if it did not)."""
    if val.get("stopped_early") == "refuted":
        return f" (stopped: above {tolerance:g} mm already)"
    if val.get("stopped_early") == "clear":
        return (f" (stopped early of {val['heldout_planned']}: within {CLEAR_FRACTION:g} of the tolerance after "
                f"{MIN_HELDOUT} or more)")
    return ""


__all__ = ["CLEAR_FRACTION", "MIN_HELDOUT", "evaluator_workers", "heldout_designs", "prediction_errors", "stop_note",
           "validate_in_rounds"]

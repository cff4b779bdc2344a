"""Fitting and validating a chain table: covering designs solved by FE, windows averaged, held-out designs checked.

A table (:class:`~pneumorph.models.chain.model.ChainTable`) is fitted from FE solves of a *covering
set* of designs in which every window occurs (:func:`~pneumorph.models.chain.windows.covering_designs`;
with ``short``, the end windows from actuators of ``2w`` units), each window's entry the mean
over its occurrences and their mirrors (:func:`fit_table`). It is validated on held-out random
designs of the full length (:func:`prediction_errors`), and :func:`build_table` grows the
window half-width until the worst unit-centre error of the held-out designs is within a
tolerance at every level.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from pneumorph.errors import ChainTableError, LocalityError
from pneumorph.geometry.library import UnitLibrary
from pneumorph.io.provenance import provenance
from pneumorph.models.chain.levels import first_levels, levels_reached, ramp_source
from pneumorph.models.chain.means import check_training, window_means
from pneumorph.models.chain.model import ChainTable, source_description, source_key, training_model
from pneumorph.models.chain.reference import binary_geometry, library_geometry
from pneumorph.models.chain.reference import first_symbols as first_symbols
from pneumorph.models.chain.terms import check_far_training, far_means, fit_text
from pneumorph.models.chain.training import MAX_TRAINING, check_training_size, training_designs
from pneumorph.models.chain.validation import (
    CLEAR_FRACTION,
    MIN_HELDOUT,
    evaluator_workers,
    heldout_designs,
    prediction_errors,
    stop_note,
    validate_in_rounds,
)
from pneumorph.models.response import Response, response_elements

__all__ = ["CLEAR_FRACTION", "DEFAULT_TOLERANCE", "MAX_TRAINING", "MAX_WINDOW", "MIN_HELDOUT", "build_table",
           "check_training_size", "evaluator_workers", "first_symbols", "fit_candidates", "fit_table", "fit_text",
           "heldout_designs", "prediction_errors", "response_elements", "training_designs"]

#: a level's worst held-out centre error above this is refused (mm, default)
DEFAULT_TOLERANCE = 0.2
#: widest window tried by :func:`build_table`
MAX_WINDOW = 3
# -- fitting --------------------------------------------------------------------------------
def fit_table(responses: Sequence[Response], window: int, source: dict[str, Any], mirror: bool = True,
              library: UnitLibrary | None = None, far: bool | str = False) -> ChainTable:
    """Fit a table to converged training responses (of one ramp; of any lengths).

    Each window's entry is the mean over its occurrences (and, with ``mirror``, over the
    mirrored occurrences with negated turns). With ``far``, each chord is the window's term
    plus the far-field terms of the next unit on each side (:mod:`pneumorph.models.chain.terms`),
    written out as a table of window +-(``window`` + 1); ``"split"``: their split layout.

    Parameters
    ----------
    library : UnitLibrary, optional
        The unit library of designs over several types (responses keyed by its letters); the
        table then covers its types (:attr:`ChainTable.alphabet`), and each type's pitch and
        centre offset are the library's units', checked against the training actuators.
        None or a one-type library: a 0/1 table.

    Raises
    ------
    ChainTableError
        No responses, a failed one, mixed lengths or levels; over a library, training
        actuators whose undeformed centres are not where the library's units put them.
    """
    longest, pressures = check_training(responses)
    n = longest.n_units
    w = int(window)
    alphabet = library.alphabet if library is not None else ()
    symmetric = library.symmetric_types if library is not None else ()
    if far:
        means = far_means(responses, w, mirror, alphabet, symmetric, len(pressures), n, far)
        w += 1
    else:
        means = window_means(responses, w, mirror, alphabet, symmetric, len(pressures))
    if n < 2:
        raise ChainTableError("a chain table needs training designs of at least 2 units")
    fitted = dict(window=w, pressures=np.asarray(pressures, dtype=float), **means, source=dict(source),
                  training=tuple(r.orientation for r in responses),  # a chain in space: its axis, undeformed
                  **({"centre_z": float(longest.reference_centres[0, 2])} if "space" in means else {}))
    if alphabet:
        assert library is not None
        return library_geometry(responses, alphabet, library, mirror, ChainTable(
            **fitted, pitch=0.0, centre_y=(0.0, 0.0), first_offset=0.0, tip_ref=(0.0, 0.0)))
    return ChainTable(**fitted, **binary_geometry(responses, longest, mirror))


def _solver(model: Any, evaluator: Any, solved: dict[str, Response], reached: dict[str, int],
            say: Callable[[str], None]) -> Callable[..., list[Response]]:
    """``solve(designs, what, before=0, total=None)``: the responses of ``designs``, those not in ``solved`` solved
    through ``evaluator`` (and kept in ``solved``), with a progress line per design.

    A design that fails after its first level is kept with the levels it reached (``reached``
    names it and how many): the table is then fitted to the levels every design reached.
    """
    n = int(model.n_units)

    def solve(designs: list[str], what: str, before: int = 0, total: int | None = None) -> list[Response]:
        """Solve ``designs`` (those not solved yet); progress lines count from ``before`` up to ``total``."""
        todo = [d for d in designs if d not in solved]
        t0 = time.perf_counter()
        done = 0 if total is None else before + len(designs) - len(todo)
        total = len(todo) if total is None else total
        # one stream of (model, design) cases, a model per length (short training designs), the longest first: no
        # pause between the lengths, and the last solves in flight are the short ones
        todo.sort(key=len, reverse=True)
        actuators = {length: model if length == n else model.with_units(length) for length in {len(d) for d in todo}}
        if todo:
            for _i, outcome in evaluator.iter_cases([(actuators[len(d)], d) for d in todo]):
                done += 1
                got = "cached" if outcome.cached else "solved"
                if not outcome.ok:
                    levels = levels_reached(outcome.response)
                    if levels == 0 or outcome.response is None:
                        raise ChainTableError(f"{what} design {outcome.design} failed in the FE model before its "
                                              f"first level ({outcome.failure}); the chain table needs every "
                                              "design solved at its first level at least")
                    reached[outcome.design] = levels
                    got = (f"{got} {outcome.design} to level {levels} of {outcome.response.n_levels} only: "
                           f"{outcome.failure}; the table keeps the levels every design reached")
                solved[outcome.design] = outcome.response
                say(f"  {what}: {done}/{total} solved ({got if not outcome.ok else f'{got} {outcome.design}'}, "
                    f"{time.perf_counter() - t0:.0f} s)")
        return [solved[d] for d in designs]

    return solve


def build_table(model: Any, evaluator: Any, window: int | None = None, tolerance: float = DEFAULT_TOLERANCE,
                heldout: int = 20, seed: int = 1, max_window: int = MAX_WINDOW,
                on_progress: Callable[[str], None] | None = None, short: bool = False, first_window: int = 1,
                early: bool = False, far: bool | str = False) -> ChainTable:
    """Fit and validate a chain table to an FE model by solving covering and held-out designs.

    Parameters
    ----------
    model : ActuatorModel
        The FE model of the training actuator (e.g. 15 units); it must be free (no gravity)
        and mirror-symmetric.
    evaluator : Evaluator
        How the designs are solved, a service of the layer above (e.g.
        :class:`~pneumorph.execution.SerialEvaluator`); a
        :class:`~pneumorph.execution.CachedEvaluator` makes the build resumable.
    window : int, optional
        A fixed half-width; by default ``first_window``, ``first_window + 1``, ... up to
        ``max_window`` until the worst held-out centre error is within ``tolerance`` at every
        level.
    tolerance : float
        Worst held-out unit-centre error allowed at any level (mm).
    heldout : int
        Random held-out designs (seeded by ``seed``) solved to validate the table. They are
        solved in rounds of the evaluator's width, those already solved first; a window is
        refused as soon as one of them is off by more than ``tolerance``, without solving the
        rest (the refusal needs no more evidence).
    on_progress : callable, optional
        Called with a line of text after each stage.
    short : bool
        Learn the windows that hold the base or the tip from actuators of ``2w`` units
        (:func:`~pneumorph.models.chain.windows.covering_designs` with ``short``; the model must have
        ``with_units``), the interior ones from actuators of the model's length. The held-out
        designs are of the model's length, as always.
    first_window : int
        The first half-width tried when ``window`` is not given (e.g. the window the shipped
        table of the same fidelity needed: :func:`~pneumorph.models.chain.sources.start_window`).
    early : bool
        Stop the validation once at least :data:`MIN_HELDOUT` held-out designs are solved and
        their worst centre error is within :data:`CLEAR_FRACTION` of the tolerance at every
        level; the validation records how many designs it used (``heldout_solved``) and
        whether it stopped early. The first :data:`MIN_HELDOUT` held-out designs are then
        solved in one stream with the covering designs.
    far : bool
        Without a fixed ``window``, try first the window one narrower than ``first_window``
        with far-field terms (:mod:`pneumorph.models.chain.terms`: a table of window
        ``first_window`` from end windows of the narrower one); with a fixed ``window``, that
        window with far-field terms (:func:`fit_candidates`); ``"split"``: in their split layout.

    A design that does not converge to the top pressure is kept with the levels it reached,
    and the table is fitted to the levels every design reached (its ``source["cut_from"]``
    names the model's ramp and the designs). When the next wider window would need more
    covering solves than a build may ask for (:func:`check_training_size`), the widest
    affordable table is validated on every held-out design and returned with its errors
    stated (``validation["beyond_tolerance"]``): the certified search carries them in its bound.

    Raises
    ------
    LocalityError
        The model has gravity, or no window up to ``max_window`` meets the tolerance.
    ChainTableError
        A design failed before its first level.
    """
    _check_buildable(model, tolerance)
    model = training_model(model)  # over sideways units: every design on the full width, a chain in space
    n = int(model.n_units)
    say = on_progress or (lambda text: None)
    library = getattr(model, "library", None)
    candidates = fit_candidates(n, window, first_window, max_window, far)
    solved: dict[str, Response] = {}
    reached: dict[str, int] = {}
    build = _Build(model, evaluator, tolerance, heldout, seed, short, early, say, solved,
                   _solver(model, evaluator, solved, reached, say), library, _source(model), time.perf_counter(),
                   reached)
    return _first_within(build, candidates)


def _first_within(build: _Build, candidates: list[tuple[int, bool | str]]) -> ChainTable:
    """The first candidate table within the tolerance; else, when the next is unaffordable, the last one with its
    errors stated (:func:`_stated`).

    Raises
    ------
    LocalityError
        Every affordable candidate is beyond the tolerance, and there is none wider to try.
    """
    best: ChainTable | None = None
    unaffordable = ""
    for w, with_far in candidates:
        try:
            table = _window_table(build, w, with_far)
        except LocalityError as exc:  # a wider window than a build may ask covering solves for
            if best is None:
                raise
            build.say(f"{fit_text(w, with_far)}: not tried: {exc}")
            unaffordable = str(exc).split(" (at most")[0].replace("a chain table over", "a table over")
            break
        if max(table.validation["centre_worst_mm"]) <= build.tolerance:
            return table
        best, tried = table, (w, with_far)
    assert best is not None
    if unaffordable:
        return _stated(build, best, *tried, unaffordable)
    raise LocalityError(
        f"the chain model does not reproduce this model within {build.tolerance:g} mm: with window +-{best.window} "
        f"the worst held-out unit-centre error is {max(best.validation['centre_worst_mm']):.3g} mm; the units "
        "interact further than the window reaches, so search with the FE model (--search ga or exhaustive)"
    )


def _check_buildable(model: Any, tolerance: float) -> None:
    """Refuse a model with gravity (the chain needs a free actuator) and a tolerance that is no positive number."""
    if getattr(model, "gravity", None) is not None:
        raise LocalityError("the chain model needs a free actuator: with gravity the weight makes moments along "
                            "the chain, so a unit's response depends on the whole actuator; search with the FE "
                            "model (--search ga or exhaustive)")
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise ChainTableError(f"the tolerance must be a positive number of mm, got {tolerance!r}")


def _windows(n: int, window: int | None, first_window: int, max_window: int) -> list[int]:
    """The half-widths to try: ``window``, else ``first_window`` (clipped to fit ``n`` units) up to ``max_window``.

    Raises
    ------
    ChainTableError
        A window wider than ``n`` units allow.
    """
    first = min(max(1, int(first_window)), max_window, max(1, (n - 1) // 2))
    windows = [int(window)] if window is not None else list(range(first, max_window + 1))
    if windows[0] < 1 or 2 * windows[-1] + 1 > n:
        raise ChainTableError(f"a window of +-{windows[-1]} units needs training designs of at least "
                              f"{2 * windows[-1] + 1} units; the model has {n}")
    return windows


def fit_candidates(n: int, window: int | None, first_window: int, max_window: int = MAX_WINDOW,
                   far: bool | str = False) -> list[tuple[int, bool | str]]:
    """The tables a build tries in turn: ``(w, far)``, window +-w, with far-field terms if ``far``.

    With ``far`` and no fixed ``window``, window ``first - 1`` with far-field terms (a table
    of window ``first``) comes first, then the plain windows; with a fixed ``window``, that
    window with far-field terms.

    >>> fit_candidates(15, None, 3, far=True), fit_candidates(15, 2, 3, far=True)
    ([(2, True), (3, False)], [(2, True)])
    """
    windows = _windows(n, window, first_window, max_window)
    plain: list[tuple[int, bool | str]] = [(w, False) for w in windows]
    if far and window is not None:
        if 2 * int(window) + 3 > n:
            raise ChainTableError(f"far-field terms of window +-{window} make a table of +-{int(window) + 1}: it "
                                  f"needs training designs of at least {2 * int(window) + 3} units; the model has {n}")
        return [(int(window), far)]
    if far and windows[0] >= 2:
        return [(windows[0] - 1, far), *plain]
    return plain


@dataclass(frozen=True)
class _Build:
    """What every window of a build shares: the model, the settings, the designs solved so far."""

    model: Any
    evaluator: Any
    tolerance: float
    heldout: int
    seed: int
    short: bool
    early: bool
    say: Callable[[str], None]
    solved: dict[str, Response]
    solve: Callable[..., list[Response]]
    library: UnitLibrary | None
    source: dict[str, Any]
    start: float
    reached: dict[str, int]  # the designs that failed after their first level: how many levels they reached

    def levels(self) -> int:
        """The levels every design solved so far reached (all the ramp's if none failed)."""
        return min(self.reached.values(), default=len(self.model.pressures()))

    def table_source(self, levels: int, why: str = "") -> dict[str, Any]:
        """The table's source: the model's, or with fewer levels than the ramp's, that of the ramp of ``levels``
        levels, its ``cut_from`` naming the model's ramp, why those levels (``why``: "those <why>"), and the designs
        that failed (and the levels they reached)."""
        pressures = self.model.pressures()
        if levels == len(pressures):
            return self.source
        return ramp_source(self.source, pressures, levels, cut_from={
            "key": self.source["key"], "levels": len(pressures), "pressure_mpa": float(pressures[-1]), "why": why,
            "failed": dict(sorted(self.reached.items()))})


class _FewerLevels(Exception):
    """A held-out design reached fewer levels than the table being validated has: fit it again to fewer."""


def _source(model: Any) -> dict[str, Any]:
    """A table's ``source``: the model's fidelity, key, fingerprint, length and description."""
    return {"fidelity": getattr(model, "fidelity", "?"), "key": source_key(model), "fingerprint": model.fingerprint(),
            "n_units": int(model.n_units), "description": source_description(model)}


def _stated(build: _Build, table: ChainTable, w: int, far: bool | str, wider: str) -> ChainTable:
    """The table of window ``w`` (``far``) when no wider window is affordable: validated on every held-out design
    (no stop once above the tolerance), its errors stated and marked ``beyond_tolerance`` in its validation;
    the certified search carries them into its bound."""
    worst = max(table.validation["centre_worst_mm"])
    build.say(f"{fit_text(w, far)}: the widest window a build may afford ({wider}); its worst held-out centre error "
              f"{worst:.3g} mm is above {build.tolerance:g} mm: validated on every held-out design and served with "
              "its errors stated")
    table = _window_table(build, w, far, every=True)
    val = {**table.validation, "beyond_tolerance": True, "wider": wider}
    return ChainTable(**{**table.__dict__, "validation": val})


def _window_table(build: _Build, w: int, far: bool | str = False, every: bool = False) -> ChainTable:
    """The table of half-width ``w`` (with ``far``: and its far-field terms), fitted to its covering designs and
    validated on held-out ones.

    Held-out designs solved for a smaller window are validated first; with ``early``, the
    first :data:`MIN_HELDOUT` go in the covering designs' stream (no pause between the
    two; they serve the next window too, should this one be refused).

    With ``every``, validated on every held-out design (its errors stated, not tested).

    Raises
    ------
    LocalityError
        Too many covering designs for the library (:func:`check_training_size`).
    ChainTableError
        A design failed before its first level.
    """
    n, library, solved, say = int(build.model.n_units), build.library, build.solved, build.say
    alphabet = library.alphabet if library is not None else ()
    symmetric = library.symmetric_types if library is not None else ()
    check_training_size(max(1, len(alphabet)), w, len(symmetric), n)
    train = training_designs(n, w, far, build.short, alphabet, symmetric)
    if far:  # every far-field key shown, checked before the solves
        check_far_training(train, w, True, alphabet, symmetric, n, far)
    name = fit_text(w, far)
    say(f"{name}: {len(train)} covering designs")
    tests = heldout_designs(n, build.heldout, exclude=train, seed=build.seed, alphabet=alphabet, symmetric=symmetric)
    tests = sorted(tests, key=lambda d: d not in solved)  # those solved for a smaller window first
    ahead = [d for d in tests[:MIN_HELDOUT] if d not in solved] if build.early else []
    what = f"covering and {len(ahead)} held-out" if ahead else "covering"
    responses = build.solve(train + ahead, what)[: len(train)]
    while True:  # fitted to the levels every design reached; again to fewer if a held-out design reaches fewer
        m = build.levels()
        table = fit_table([first_levels(r, m) for r in responses], w, build.source,
                          library=library if alphabet else None, far=far)
        try:
            val = validate_in_rounds(table, tests, _held_out(build, m), np.inf if every else build.tolerance,
                                     build.early and not every, evaluator_workers(build.evaluator))
            break
        except _FewerLevels:
            continue
    val.update(tolerance_mm=build.tolerance, seed=build.seed)
    worst = max(val["centre_worst_mm"])
    say(f"{name}: worst held-out centre error {worst:.4f} mm over {val['heldout_solved']} held-out "
        f"design(s){stop_note(val, build.tolerance)}, mean at the last level {val['centre_mean_mm'][-1]:.4f} mm")
    for symbol, errs in val.get("per_type", {}).items():
        if errs["centres"]:
            say(f"  unit type {symbol}: worst held-out centre error {max(errs['centre_worst_mm']):.4f} mm "
                f"({errs['centres']} centres)")
    meta = provenance(solves=len(solved), build_wall_s=time.perf_counter() - build.start, fit=name)
    why = f"every design reached ({len(build.reached)} did not converge beyond)" if build.reached else ""
    if m < len(build.model.pressures()):
        say(f"{name}: fitted to the first {m} level(s), {table.pressures[0] * 1e3:.4g}-{table.pressures[-1] * 1e3:.4g}"
            f" kPa of the ramp's {len(build.model.pressures())} (up to {build.model.pressures()[-1] * 1e3:.4g} kPa), "
            f"those {why}")
    source = build.table_source(m, why)
    return ChainTable(**{**table.__dict__, "validation": val, "metadata": meta, "source": source})


def _held_out(build: _Build, levels: int) -> Callable[..., list[Response]]:
    """``build.solve`` for a table of ``levels`` levels: the responses' first ``levels``; :class:`_FewerLevels` if a
    design reached fewer."""
    def solve(designs: list[str], what: str, before: int = 0, total: int | None = None) -> list[Response]:
        out = build.solve(designs, what, before, total)
        if build.levels() < levels:
            raise _FewerLevels
        return [first_levels(r, levels) for r in out]

    return solve

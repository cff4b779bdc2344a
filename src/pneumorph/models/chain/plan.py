"""What building a chain table will cost, said before the first solve: the plan and its time estimate.

:func:`build_plan` counts, without a solve, the covering and held-out designs a build will
solve for each window it may try (those the evaluation cache holds left out), and estimates
the wall time from the measured solve time of the model (:data:`SOLVE_SECONDS`, scaled by the
units and divided among the workers). A run prints :meth:`BuildPlan.text` before it builds, so
no long build starts silently.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from pneumorph.errors import PneumorphError
from pneumorph.io.progress import duration_text, load_factor
from pneumorph.models.chain.fit import (
    DEFAULT_TOLERANCE,
    MAX_WINDOW,
    MIN_HELDOUT,
    check_training_size,
    evaluator_workers,
    fit_candidates,
    fit_text,
    heldout_designs,
    training_designs,
)
from pneumorph.models.chain.model import in_space

#: the full 3D model on the full width (designs with a sideways unit, and a chain in space's training designs):
#: 57.6 s for a 15-unit design on one core on a quiet machine (BENCHMARKS.md, benchmarks/full_model.py)
FULL_WIDTH = "3d full-width"
#: held-out designs that validate a table built on first use
HELDOUT = 20
#: measured wall time of one FE solve of a 15-unit design (:data:`SOLVE_UNITS`) on one core, seconds, per
#: fidelity (BENCHMARKS.md, 2 cores, 24 GB: a random 3D design 14.2-15.8 s; 2D the fit of CPU times over 5 to
#: 30 units, :data:`SOLVE_EXPONENT`; strongly curled designs take up to three times as long); the estimates of a
#: build or a search scale it by the units (:data:`SOLVE_EXPONENT`) and divide it among the workers
SOLVE_SECONDS = {"3d": 15.0, "2d": 0.83, FULL_WIDTH: 60.0}
SOLVE_UNITS = 15
#: how a solve's time grows with the units, ``(n / SOLVE_UNITS) ** exponent``, per fidelity (1 where not
#: measured): in 2D the unknowns grow with the units and the Newton iterations with the curl, which grows with
#: them too; 5 to 30 units of one design pattern took 0.20 to 1.95 s of CPU, fitted by ``0.83 s (n / 15) ** 1.35``
#: within -18 to +15 % (BENCHMARKS.md, "The 2D estimate's growth with the units")
SOLVE_EXPONENT = {"2d": 1.35}


def solve_seconds(fidelity: str, n_units: int) -> float | None:
    """Estimated wall time of one FE solve of ``n_units`` units on one core (s), from :data:`SOLVE_SECONDS`
    scaled by the units to the power :data:`SOLVE_EXPONENT`; None for a model without a measured figure.

    >>> solve_seconds("3d", 15), solve_seconds("3d", 30), round(solve_seconds("2d", 30), 2), solve_seconds("toy", 5)
    (15.0, 30.0, 2.12, None)
    """
    per = SOLVE_SECONDS.get(str(fidelity))
    exponent = SOLVE_EXPONENT.get(str(fidelity), 1.0)
    return None if per is None else per * (int(n_units) / SOLVE_UNITS) ** exponent


#: a volume-controlled ramp's CPU time over the pressure ramp's of the built-in unit (the figure :data:`SOLVE_SECONDS`
#: measures), measured on a 4-unit 2D design (``benchmarks/volume_ramp.py``, BENCHMARKS.md), by how much stiffer the
#: layer is than the body (initial shear moduli): (ratio, the factor to 0.5 V0, its growth per V0 past 0.5 V0). A body
#: much softer than its layer balloons past 0.5 V0, where the ramp needs cut-back after cut-back (Ecoflex 00-30 in
#: Smooth-Sil 950: 82 cut-backs to a change of 1 V0, 546 to 4 V0)
VOLUME_RAMP_COST = ((4.06, 3.4, 0.2), (9.8, 7.3, 86.0), (25.9, 10.8, 173.0), (34.5, 9.2, 169.0))
#: the factor of a volume-controlled ramp beyond which its plan says that it may need many cut-backs
MANY_CUTBACKS = 20.0


def softness(model: Any) -> float | None:
    """How much stiffer a model's layer is than its body (the ratio of their initial shear moduli), or None for a
    model without both.

    >>> from pneumorph.models import make_model
    >>> round(softness(make_model(4, {"fidelity": "2d"})), 2)
    4.06
    >>> round(softness(make_model(4, {"fidelity": "2d", "unit": {"body_material": "ecoflex_00_30"}})), 1)
    34.5
    """
    body, layer = getattr(model, "body", None), getattr(model, "layer", None)
    try:
        return float(layer.shear_modulus) / float(body.shear_modulus)  # type: ignore[union-attr]
    except (AttributeError, TypeError, ValueError, ZeroDivisionError):
        return None


def volume_ramp_factor(model: Any) -> float:
    """A model's solve time over the pressure ramp's of the built-in unit: 1 for a pressure ramp; for a volume
    ramp (``RampSpec.volume``, ``V / V0 - 1``) interpolated in :data:`VOLUME_RAMP_COST` by :func:`softness` (in its
    logarithm, held at the ends): the factor to 0.5 V0 and its growth per V0 past it.

    >>> from pneumorph.models import make_model
    >>> soft = {"fidelity": "2d", "volume_change": 4.0, "unit": {"body_material": "ecoflex_00_30"}}
    >>> volume_ramp_factor(make_model(4, {"fidelity": "2d"})), round(volume_ramp_factor(make_model(4, soft)))
    (1.0, 601)
    """
    volume = getattr(getattr(model, "ramp", None), "volume", None)
    if volume is None:
        return 1.0
    ratios, bases, growths = (np.log([row[k] for row in VOLUME_RAMP_COST]) if k == 0 else
                              np.array([row[k] for row in VOLUME_RAMP_COST]) for k in range(3))
    at = math.log(softness(model) or VOLUME_RAMP_COST[0][0])
    base, growth = float(np.interp(at, ratios, bases)), float(np.interp(at, ratios, growths))
    return base + growth * max(0.0, float(volume) - 0.5)


def model_seconds(model: Any, n_units: int | None = None) -> float | None:
    """Estimated wall time of one FE solve of ``model`` over ``n_units`` units (default its own) on one core (s):
    :func:`solve_seconds` of its :func:`cost_fidelity`, times :func:`volume_ramp_factor`; None without a figure.

    >>> from pneumorph.models import make_model
    >>> model_seconds(make_model(15, {"fidelity": "2d"})), round(model_seconds(make_model(4, {"fidelity": "2d",
    ...     "volume_change": 1.0})), 2)
    (0.83, 0.49)
    """
    seconds = solve_seconds(cost_fidelity(model), int(getattr(model, "n_units", 0) or 0) if n_units is None
                            else int(n_units))
    return None if seconds is None else seconds * volume_ramp_factor(model)


def volume_ramp_note(model: Any) -> str:
    """What a plan says of a volume-controlled ramp that may cost many cut-backs (its walls balloon), or ""."""
    factor, ratio = volume_ramp_factor(model), softness(model)
    if factor < MANY_CUTBACKS or ratio is None:
        return ""
    return (f"volume control of a body {ratio:.3g} times softer than its layer may need many cut-backs where its "
            f"walls balloon (about {factor:.0f} times the built-in unit's pressure ramp, measured in 2D; the count "
            "below gives the real rate)")


#: a pressure ramp's limit point, measured on a 4-unit 2D design of the built-in unit in its Smooth-Sil 950 layer
#: (``benchmarks/volume_ramp.py --pressure``, BENCHMARKS.md): the least :func:`softness` whose walls balloon below
#: 45 kPa (Ecoflex 0030, 14.3, at 24.2 kPa; Dragon Skin 10 medium, 9.8, reaches 45 kPa), the lowest limit point
#: measured (kPa), and the most a ramp that creeps to its limit point cost over the converged ramp's estimate (the
#: softest bodies: 5 to 39 times, cut-back after cut-back until the step is too small). A softer body is no slower
#: below its limit point (Ecoflex 00-30 to 20 kPa: 1.0 times), so the estimate stays the converged ramp's and the
#: plan says what the limit point may cost
LIMIT_POINT = (14.0, 24.0, 40.0)


def limit_point_note(model: Any) -> str:
    """What a plan says of a pressure ramp that may stop at a limit point (a soft body's walls balloon), or "".

    >>> from pneumorph.models import make_model
    >>> soft = {"fidelity": "2d", "unit": {"body_material": "ecoflex_00_30"}}
    >>> limit_point_note(make_model(4, {"fidelity": "2d"})), limit_point_note(make_model(4, {**soft,
    ...                                                                                "pressure_kpa": 20}))
    ('', '')
    >>> print(limit_point_note(make_model(4, soft)))  # doctest: +NORMALIZE_WHITESPACE
    a body 34.5 times softer than its layer may reach a limit point (its walls balloon) past 24 kPa: the ramp then
    creeps to it with cut-backs and stops, which took up to 40 times the estimate (measured in 2D)
    """
    ratio, ramp = softness(model), getattr(model, "ramp", None)
    least, lowest, cost = LIMIT_POINT
    if ratio is None or ratio < least or getattr(ramp, "volume", None) is not None:
        return ""
    try:
        pressure_kpa = float(ramp.pressure) * 1e3  # type: ignore[union-attr]
    except (AttributeError, TypeError, ValueError):
        return ""
    if pressure_kpa <= lowest:
        return ""
    return (f"a body {ratio:.3g} times softer than its layer may reach a limit point (its walls balloon) past "
            f"{lowest:g} kPa: the ramp then creeps to it with cut-backs and stops, which took up to {cost:g} times "
            "the estimate (measured in 2D)")


def ramp_note(model: Any) -> str:
    """What a plan says of a model's ramp beyond its estimate: :func:`volume_ramp_note` or :func:`limit_point_note`.

    >>> from pneumorph.models import make_model
    >>> ramp_note(make_model(4, {"fidelity": "2d"}))
    ''
    """
    return volume_ramp_note(model) or limit_point_note(model)


def cost_fidelity(model: Any) -> str:
    """The key of :data:`SOLVE_SECONDS` a model's build is estimated by: its fidelity, or :data:`FULL_WIDTH` for a 3D
    model over sideways units (its training designs are solved on the full width)."""
    fidelity = str(getattr(model, "fidelity", "?"))
    return FULL_WIDTH if fidelity == "3d" and in_space(model) else fidelity


def estimate_text(solves: int, fidelity: str, n_units: int, workers: int) -> str:
    """The estimated wall time of ``solves`` FE solves of ``n_units`` units among ``workers`` workers, as text.

    >>> estimate_text(33, "3d", 6, 2)
    'estimated 1.7 min with 2 workers (about 6 s a 3d solve of 6 units on one core, from BENCHMARKS.md; an estimate)'
    """
    per = solve_seconds(fidelity, n_units)
    if per is None:
        return f"no measured solve time of the {fidelity} model to estimate the time from"
    workers = max(1, int(workers))
    wall = per * math.ceil(solves / min(workers, max(solves, 1))) if solves else 0.0
    return (f"estimated {duration_text(wall)} with {workers} worker{'s' if workers > 1 else ''} (about "
            f"{per:.2g} s a {fidelity} solve of {n_units} unit{'s' if n_units != 1 else ''} on one core, from "
            "BENCHMARKS.md; an estimate)")


@dataclass(frozen=True)
class BuildPlan:
    """What building a model's chain table will solve, before any solve.

    Attributes
    ----------
    fidelity : str
    unit : str
        The unit (or the unit types of a library) as text.
    pressures : tuple of float
        The reported levels (MPa).
    n_units : int
        Units of the training and held-out designs.
    windows : tuple of int
        The window half-widths tried in turn until the held-out error is within ``tolerance``.
    covering : tuple of int
        Covering designs of each window.
    far : tuple of bool or str
        Per window, whether it is fitted with far-field terms, or their layout (``"split"``;
        empty: none is).
    solves : tuple of int
        Distinct FE solves if the build stops at each window (covering and held-out designs, cumulated).
    fewest : int
        FE solves if the first window is accepted on the fewest held-out designs (all of them,
        unless the validation may stop early).
    heldout : int
    tolerance : float
        Worst held-out centre error allowed (mm).
    cached : int
        Of the designs of the widest window, those the evaluation cache holds already.
    workers : int
    work : tuple of float
        Like ``solves``, in solves of ``n_units`` units: a short design counts by its units (a
        solve's time grows with them).
    fewest_work, cached_work : float
        ``fewest`` and ``cached`` likewise.
    """

    fidelity: str
    unit: str
    pressures: tuple[float, ...]
    n_units: int
    windows: tuple[int, ...]
    covering: tuple[int, ...]
    solves: tuple[int, ...]
    fewest: int = 0
    heldout: int = HELDOUT
    tolerance: float = DEFAULT_TOLERANCE
    cached: int = 0
    workers: int = 1
    far: tuple[bool | str, ...] = ()
    work: tuple[float, ...] = ()
    fewest_work: float = 0.0
    cached_work: float = 0.0

    def cost_text(self) -> str:
        """The FE solves (fewest to most, those cached not counted) and their estimated wall time."""
        lo, hi = (max(s - self.cached, 0) for s in (self.fewest or self.solves[0], self.solves[-1]))
        count = f"{lo} FE solves" if lo == hi else f"{lo}-{hi} FE solves"
        per = solve_seconds(self.fidelity, self.n_units)
        if per is None:
            return f"{count} (no measured solve time of the {self.fidelity} model to estimate the time from)"
        w = max(1, self.workers)
        lo_w, hi_w = (max(s - self.cached_work, 0.0) for s in (self.fewest_work or self.work[0], self.work[-1]))
        lo_s, hi_s = (per * math.ceil(s / w - 1e-9) for s in (lo_w, hi_w))
        when = duration_text(lo_s) if lo == hi else f"{duration_text(lo_s)} to {duration_text(hi_s)}"
        short = ", shorter designs by their units" if self.work[-1] < self.solves[-1] else ""
        return (f"{count}, estimated {when} with {w} worker{'s' if w > 1 else ''} (about {per:.2g} s a {self.fidelity} "
                f"solve of {self.n_units} units on one core{short}, from BENCHMARKS.md; an estimate)")

    def text(self) -> str:
        """The plan as one paragraph: what is built, the windows tried, the solves and the estimate."""
        p = np.asarray(self.pressures) * 1e3
        ramp = f"{p[0]:.4g}-{p[-1]:.4g} kPa in {len(p)} levels" if len(p) > 1 else f"{p[0]:.4g} kPa"
        fars = self.far or (False,) * len(self.windows)
        tries = ", ".join(f"{fit_text(w, f)[len('window '):]} ({c} covering designs)"
                          for w, c, f in zip(self.windows, self.covering, fars, strict=True))
        grow = (f"windows {tries} tried in turn until" if len(self.windows) > 1 else f"window {tries}, checked that")
        cached = f" ({self.cached} designs already in the evaluation cache)" if self.cached else ""
        early = f" ({MIN_HELDOUT} if they are clearly within)" if self.fewest and self.fewest < self.solves[0] else ""
        return (f"building the chain table of the {self.fidelity} model ({self.unit}, {ramp}) on {self.n_units}-unit "
                f"designs: {grow} the worst centre error of {self.heldout} held-out designs{early} is within "
                f"{self.tolerance:g} mm; {self.cost_text()}{cached}")


def unit_text(model: Any) -> str:
    """The unit of a model as text: ``the built-in unit``, ``unit 'name' with wall 2, ...`` or ``unit types a, r``.

    A unit other than the built-in one is named with the dimensions in which it differs from it.

    >>> from pneumorph.geometry.unit import UnitSpec
    >>> from pneumorph.models.factory import make_model
    >>> unit_text(make_model(3)), unit_text(make_model(3, {"library": "builtin"}))
    ('the built-in unit', 'unit types a, e, r, s')
    >>> unit_text(make_model(3, {"unit": {"element_size": 3.0, "layer": 2.5}}))
    'unit with layer 2.5, element_size 3'
    """
    from dataclasses import fields

    from pneumorph.geometry.unit import UnitSpec

    library = getattr(model, "library", None)
    if library is not None and not library.is_single:
        return f"unit types {', '.join(library.symbols)}"
    unit = getattr(model, "unit", None)
    default = UnitSpec()
    if unit is None or unit == default:
        return "the built-in unit"
    differ = []
    for f in fields(UnitSpec):
        value = getattr(unit, f.name)
        if f.name != "name" and not f.name.startswith("filler_") and value != getattr(default, f.name):
            differ.append(f"{f.name} {value:g}" if isinstance(value, float) else f"{f.name} {value}")
    name = "unit" if unit.name == default.name else f"unit {unit.name!r}"
    return f"{name} with {', '.join(differ[:4])}{', ...' if len(differ) > 4 else ''}" if differ else name


def build_plan(model: Any, heldout: int = HELDOUT, workers: int = 1, cached: Callable[[list[str]], int] | None = None,
               window: int | None = None, tolerance: float = DEFAULT_TOLERANCE, short: bool = False,
               first_window: int = 1, early: bool = False, far: bool | str = False) -> BuildPlan:
    """What :func:`~pneumorph.models.chain.fit.build_table` will solve to fit a table to ``model`` (the training
    actuator: its designs have ``model.n_units`` units), counted without a solve.

    Parameters
    ----------
    model : ActuatorModel
        The training model.
    heldout : int
        Held-out designs of each window.
    workers : int
        The evaluator's workers, for the estimate.
    cached : callable, optional
        ``cached(designs)``: how many of the designs the evaluation cache holds already.
    window : int, optional
        A fixed window; by default ``build_table``'s: 1, 2, ... up to
        :data:`~pneumorph.models.chain.fit.MAX_WINDOW` (those a library of several types allows).
    tolerance : float
        The worst held-out centre error the build accepts (mm).
    short : bool
        The build learns the end windows from short actuators (``build_table(short=True)``); the
        estimate takes each short design at its units' share of the full length's time.
    first_window, early, far : int, bool, bool or str
        As :func:`~pneumorph.models.chain.fit.build_table`'s: the first window tried, an early stop
        of the validation, a narrower window with far-field terms first.

    Examples
    --------
    >>> from pneumorph.models.factory import make_model
    >>> plan = build_plan(make_model(15, {"fidelity": "3d", "pressure_kpa": 50}), workers=2)
    >>> plan.windows, plan.covering, plan.solves
    ((1, 2, 3), (2, 8, 32), (22, 29, 59))
    >>> print(plan.text())  # doctest: +NORMALIZE_WHITESPACE
    building the chain table of the 3d model (the built-in unit, 5-50 kPa in 10 levels) on 15-unit designs: windows
    +-1 (2 covering designs), +-2 (8 covering designs), +-3 (32 covering designs) tried in turn until the worst
    centre error of 20 held-out designs is within 0.2 mm; 22-59 FE solves, estimated 2.8 min to 7.5 min with 2
    workers (about 15 s a 3d solve of 15 units on one core, from BENCHMARKS.md; an estimate)
    """
    n_units = int(model.n_units)
    library = getattr(model, "library", None)
    alphabet = library.alphabet if library is not None else ()
    types = max(1, len(alphabet))
    symmetric = library.symmetric_types if library is not None else ()
    seen: set[str] = set()
    widest = max(1, min(MAX_WINDOW, (n_units - 1) // 2))
    first = min(max(1, int(first_window)), widest)
    fewest, fewest_work = 0, 0.0
    rows: list[tuple[int, int, int, float, bool | str]] = []  # window, covering designs, solves, work, far-field terms
    for w, with_far in fit_candidates(n_units, window, first, widest, far):
        try:
            check_training_size(types, w, len(symmetric), n_units)
        except PneumorphError:
            break
        train = training_designs(n_units, w, with_far, short, alphabet, symmetric)
        seen.update(train)
        tests = heldout_designs(n_units, heldout, exclude=train, seed=1, alphabet=alphabet, symmetric=symmetric)
        if not rows:
            first_tests = min(MIN_HELDOUT, len(tests)) if early else len(tests)
            fewest, fewest_work = len(seen) + first_tests, _work(seen, n_units) + first_tests
        seen.update(tests)
        rows.append((w, len(train), len(seen), _work(seen, n_units), with_far))
    if not rows:  # not even the first window fits: the check's own refusal, with its advice
        check_training_size(types, first if window is None else int(window), len(symmetric), n_units)
    held, held_work = _cached(cached, seen, n_units)
    windows, covering, solves, work, fars = (tuple(column) for column in zip(*rows, strict=True))
    return BuildPlan(cost_fidelity(model), unit_text(model),
                     tuple(float(p) for p in model.pressures()), int(n_units), windows, covering, solves, fewest,
                     heldout, float(tolerance), held, max(1, int(workers)), fars, work, fewest_work, held_work)


def _cached(cached: Callable[[list[str]], int] | None, seen: set[str], n_units: int) -> tuple[int, float]:
    """How many of the designs the cache holds, and as solves of ``n_units`` units (:func:`_work`)."""
    if cached is None or not seen:
        return 0, 0.0
    groups = _by_length(seen)
    counts = {length: int(cached(group)) for length, group in groups.items()}
    return sum(counts.values()), sum(c * length / n_units for length, c in counts.items())


def _by_length(designs: set[str]) -> dict[int, list[str]]:
    """Designs grouped by their units (sorted within a group)."""
    out: dict[int, list[str]] = {}
    for d in sorted(designs):
        out.setdefault(len(d), []).append(d)
    return out


def _work(designs: set[str], n_units: int) -> float:
    """Designs counted in solves of ``n_units`` units: each by its units' share."""
    return sum(len(d) for d in designs) / n_units


def cached_counter(evaluator: Any, model: Any) -> Callable[[list[str]], int] | None:
    """``designs -> how many of them the evaluator's cache holds for model`` (None without a cache)."""
    cache = getattr(evaluator, "cache", None)
    if cache is None or not callable(getattr(cache, "designs", None)):
        return None
    fingerprint = model.fingerprint()

    def count(designs: list[str]) -> int:
        return len(set(designs) & set(cache.designs(fingerprint)))

    return count


def solve_estimate(model: Any, count: int, scale: float = 1.0, workers: int | None = None,
                   load: float | None = None, cores: int | None = None) -> str:
    """`` (3d, about 15 s each)``: the wall time of each of ``count`` solves of ``model``, or nothing without a
    measured figure.

    Its CPU time on one core (:func:`model_seconds`: the measured solve time of the model's fidelity, a 3D model
    over sideways units the full width's; times ``scale``, e.g. a finer mesh's cells over the measured mesh's),
    slowed only where the solves share the cores with other runs' processes.

    Parameters
    ----------
    workers : int, optional
        How many of the solves run at once (an evaluator's width); default as many as the solves and the cores
        allow.
    load : float, optional
        The processes of other runs that compute now; default the machine's load average less this run's own
        processes (:func:`pneumorph.io.progress.other_load`: a run's own scoring or workers do not slow its
        estimate of itself).
    cores : int, optional
        The machine's cores (default: :func:`os.cpu_count`).

    Examples
    --------
    >>> from pneumorph.models.fe import Full3D
    >>> solve_estimate(Full3D(17), 2, workers=2, load=0.0, cores=2)  # a machine with nothing else on it
    ' (3d, about 17 s each)'
    >>> solve_estimate(Full3D(17), 2, workers=2, load=2.0, cores=2)  # two busy processes of another run
    ' (3d, about 34 s each)'
    """
    fidelity = cost_fidelity(model)
    seconds = model_seconds(model)
    if not seconds:
        return ""
    each = " each" if count > 1 else ""
    cores = cores or os.cpu_count() or 1
    at_once = min(max(1, count), cores if workers is None else max(1, int(workers)))
    seconds *= scale * load_factor(at_once, load, cores)
    return f" ({fidelity}, about {duration_text(seconds)}{each})"


__all__ = ["HELDOUT", "LIMIT_POINT", "MANY_CUTBACKS", "SOLVE_SECONDS", "SOLVE_UNITS", "VOLUME_RAMP_COST", "BuildPlan",
           "build_plan", "cached_counter", "cost_fidelity", "estimate_text", "evaluator_workers", "limit_point_note",
           "model_seconds", "ramp_note", "softness", "solve_estimate", "solve_seconds", "unit_text",
           "volume_ramp_factor", "volume_ramp_note"]

"""The sensitivity studies of appendices D and E as data: a reference, its variants, their results.

A :class:`Study` is a reference case and the variant cases to compare with it, all for one
design; :func:`run_study` solves them through any evaluator (in parallel, resumable through
a cache) and measures each variant against the reference (:func:`~pneumorph.sensitivity.
compare.shape_difference`). The builders below make the studies of the dissertation for
any model and design:

========================  ==========================================================
:func:`simplifications`   D.1-D.4: air passages between cavities, the base block and
                          its clamp, a 10 degC temperature rise, all three together
:func:`tolerances`        E.2: mould tolerances on the side walls, the Mold Star wall
                          and the Smooth-Sil layer, one-at-a-time extremes and random
                          combinations (Table E.1, Figs E.5-E.6)
:func:`bulk_modulus`      E.1.2: the body's bulk modulus raised by 5 % and 10 %
:func:`calibration`       E.1.1: the body calibrated on tension only; the pressure at
                          which it reaches the reference shape
:func:`temperature`       D.3: a uniform temperature change
========================  ==========================================================
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from pneumorph import checks
from pneumorph.errors import SettingsError
from pneumorph.execution.outcome import Outcome
from pneumorph.geometry.features import PHYSICAL_PASSAGE, BaseBlock
from pneumorph.geometry.orientation import parse_orientation
from pneumorph.models.fe import FEModel, RampSpec
from pneumorph.sensitivity.compare import ShapeDifference, shape_difference
from pneumorph.sensitivity.tolerances import FIELDS, Tolerance, box_units, corner_label
from pneumorph.sensitivity.variants import scaled_bulk_modulus, tension_only

#: The studies ``pneumorph sensitivity`` runs (appendices D and E), by name.
STUDIES = ("simplifications", "tolerances", "bulk-modulus", "calibration", "temperature")

#: what the dissertation reports, for the tables beside pneumorph's (mm, %, kPa)
DISSERTATION: dict[str, dict[str, Any]] = {
    "simplifications": {"passages": (11.7, 4.5, 6.5), "base block": (12.8, 5.8, 8.4),
                        "temperature +10 degC": (2.08, 0.4, 1.79), "all three": (13.85, 9.52, 0.83),
                        "design": "the random design of chapter 5", "columns": "distance mm, X %, Y %"},
    "tolerances": {"minimum curl inputs": (1.578, 1.597, 2.910), "samples": 30, "tolerance_mm": 0.1,
                   "design": "all units aligned"},
    "bulk-modulus": {"factors": (1.05, 1.10), "reference_kpa": 119.0, "design": "all units aligned"},
    "calibration": {"reference_kpa": 45.0, "matching_kpa": 85.0, "design": "all units aligned"},
    "temperature": {"temperature +10 degC": (2.08, 0.4, 1.79), "design": "the random design of chapter 5"},
}


@dataclass(frozen=True)
class Case:
    """One model of a study: a label, the model, and the inputs that make it (for tables)."""

    label: str
    model: FEModel
    inputs: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Study:
    """A reference and its variants for one design.

    ``level`` is the reported level compared (default: the last, the full pressure);
    ``match`` asks :func:`run_study` to find, for every variant, the pressure at which it
    comes closest to the reference's shape (the calibration study: variants ramp further).
    """

    name: str
    design: str
    reference: Case
    cases: tuple[Case, ...]
    level: int = -1
    match: bool = False

    def all_cases(self) -> list[Case]:
        return [self.reference, *self.cases]


@dataclass(frozen=True)
class CaseResult:
    """A solved case: its outcome and, for a variant, its difference from the reference."""

    case: Case
    outcome: Outcome
    difference: ShapeDifference | None = None
    #: the calibration study: the pressure (kPa) where the variant is closest to the reference shape, and how close
    matching_kpa: float | None = None
    matching_mm: float | None = None

    def to_dict(self) -> dict[str, Any]:
        r = self.outcome.response
        out: dict[str, Any] = {"label": self.case.label, "inputs": self.case.inputs, "ok": self.outcome.ok,
                               "fingerprint": self.case.model.fingerprint(), "cached": self.outcome.cached,
                               "wall_time_s": self.outcome.wall_time}
        if not self.outcome.ok:
            out["failure"] = self.outcome.failure
            if self.outcome.reached is not None:
                out["reached_kpa"] = self.outcome.reached * 1e3
        if r is not None and self.outcome.ok:
            out["curl_deg"] = float(r.curl[-1])
            out["tip_mm"] = r.tip[-1].tolist()
        if self.difference is not None:
            out["difference"] = self.difference.to_dict()
        if self.matching_kpa is not None:
            out["matching_kpa"], out["matching_mm"] = self.matching_kpa, self.matching_mm
        return out


@dataclass(frozen=True)
class StudyResult:
    """Every case of a study, solved and measured."""

    study: Study
    reference: CaseResult
    cases: tuple[CaseResult, ...]

    def summary(self) -> dict[str, Any]:
        """The study's headline numbers (for tolerances: the spread of curl and tip, Table E.1)."""
        ok = [c for c in self.cases if c.outcome.ok and c.difference is not None]
        out: dict[str, Any] = {"cases": len(self.cases), "failed": len(self.cases) - len(ok)}
        if not ok:
            return out
        d = np.array([c.difference.distance_mm for c in ok])  # type: ignore[union-attr]
        out["worst_distance_mm"] = float(d.max())
        if self.study.name == "tolerances":
            curl = np.array([c.difference.curl_deg for c in ok])  # type: ignore[union-attr]
            tips = np.array([c.outcome.response.tip[self.study.level] for c in ok])  # type: ignore[union-attr]
            lo, hi = int(np.argmin(curl)), int(np.argmax(curl))
            out.update(
                curl_min_deg=float(curl[lo]), curl_max_deg=float(curl[hi]), curl_mean_deg=float(curl.mean()),
                curl_std_deg=float(curl.std(ddof=1)) if len(curl) > 1 else 0.0,
                tip_spread_mm=float(np.linalg.norm(np.ptp(tips, axis=0))),
                distance_mean_mm=float(d.mean()), distance_p95_mm=float(np.percentile(d, 95)),
                minimum_curl_inputs=ok[lo].case.inputs, maximum_curl_inputs=ok[hi].case.inputs,
            )
            kind = np.array([c.case.label.split()[0] for c in ok])
            kind = np.where(np.isin(kind, ["sample", "corner"]), kind, "extreme")
            sampled = curl[kind == "sample"]
            for name in ("extreme", "corner"):  # do the one-at-a-time extremes, the corners, bracket the samples?
                members = curl[kind == name]
                if members.size and sampled.size:
                    inside = (sampled >= members.min()) & (sampled <= members.max())
                    out[f"samples_within_{name}s"] = int(inside.sum())
        return out

    def to_dict(self) -> dict[str, Any]:
        return {"study": self.study.name, "design": self.study.design,
                "reference": self.reference.to_dict(), "cases": [c.to_dict() for c in self.cases],
                "summary": self.summary(), "dissertation": DISSERTATION.get(self.study.name, {})}


# -- the studies ---------------------------------------------------------------------------------
def _design(model: FEModel, design: str | None) -> str:
    return parse_orientation("0" * model.n_units if design is None else design, model.n_units)


def _needs_3d(model: FEModel, study: str) -> None:
    if model.dim != 3:
        raise SettingsError(f"the {study} study needs the 3D model (--model 3d): its variants are 3D model options")


def simplifications(model: FEModel, design: str | None = None, passage: float = PHYSICAL_PASSAGE,
                    base: BaseBlock | None = None, temperature_change: float = 10.0) -> Study:
    """Appendix D: what the model's simplifications cost, one at a time and together.

    Examples
    --------
    >>> from pneumorph.models.fe import Full3D
    >>> [c.label for c in simplifications(Full3D(15)).cases]
    ['passages', 'base block', 'temperature +10 degC', 'all three']
    """
    _needs_3d(model, "simplifications")
    base = base or BaseBlock()
    t = f"temperature {temperature_change:+g} degC"
    cases = (
        Case("passages", model.variant(passage=passage), {"passage_mm": passage}),
        Case("base block", model.variant(base_block=base), {"base_length_mm": base.length}),
        Case(t, model.variant(temperature_change=temperature_change), {"temperature_change_c": temperature_change}),
        Case("all three", model.variant(passage=passage, base_block=base, temperature_change=temperature_change),
             {"passage_mm": passage, "base_length_mm": base.length, "temperature_change_c": temperature_change}),
    )
    return Study("simplifications", _design(model, design), Case("as modelled", model), cases)


def tolerances(model: FEModel, design: str | None = None, tolerance: Tolerance | None = None, samples: int = 30,
               seed: int = 0, corners: bool = False) -> Study:
    """Appendix E.2: the one-at-a-time extremes, optionally the ``corners`` of the box, and ``samples``
    seeded random combinations.

    All cases, the nominal one included, are meshed with the same cell counts
    (:func:`~pneumorph.sensitivity.tolerances.matched_element_size`): for the built-in
    unit and +-0.1 mm, an element size of 1.71 mm, which meshes the nominal unit exactly as
    its own 1.5 mm does.

    Examples
    --------
    >>> from pneumorph.models.fe import Full3D
    >>> s = tolerances(Full3D(15), samples=2)
    >>> [c.label for c in s.cases][:2], len(s.cases), s.cases[0].inputs
    (['side_wall -0.1', 'side_wall +0.1'], 8, {'side_wall': 1.4, 'wall': 1.5, 'layer': 3.0})
    """
    tolerance = tolerance or Tolerance()
    samples = checks.integer(samples, "samples", 0, 10_000)
    labels = [f"{f} {s}{tolerance.tolerance:g}" for f in tolerance.fields for s in ("-", "+")]
    offsets = [*zip(labels, tolerance.extremes(), strict=True)]
    if corners:  # every thickness at an end: these bracket any combination's curl when it is monotone in each
        offsets += [(corner_label(o), o) for o in tolerance.corners()]
    if samples:
        offsets += [(f"sample {k + 1}", o) for k, o in enumerate(tolerance.samples(samples, seed))]
    # every case on the nominal mesh's cell counts: a change of mesh would be as large as the tolerance's effect
    nominal_unit, units = box_units(model.unit, tolerance, [o for _, o in offsets])
    cases = []
    for (label, _), unit in zip(offsets, units, strict=True):
        inputs = {f: round(float(getattr(unit, f)), 6) for f in tolerance.fields}
        cases.append(Case(label, model.variant(unit=unit), inputs))
    nominal = {f: float(getattr(model.unit, f)) for f in tolerance.fields}
    reference = Case("nominal", model.variant(unit=nominal_unit),
                     {**nominal, "element_size": nominal_unit.element_size})
    return Study("tolerances", _design(model, design), reference, tuple(cases))


def bulk_modulus(model: FEModel, design: str | None = None, factors: Sequence[float] = (1.05, 1.10)) -> Study:
    """Appendix E.1.2: the body silicone's bulk modulus raised by each factor."""
    body = model.body
    cases = tuple(
        Case(f"bulk modulus x{f:g}",
             model.variant(materials={**model.materials, body.name: scaled_bulk_modulus(body, f)}),
             {"bulk_modulus_kpa": body.bulk_modulus.value * f * 1e3})  # type: ignore[union-attr]
        for f in factors
    )
    reference = Case("measured", model, {"bulk_modulus_kpa": body.bulk_modulus.value * 1e3})  # type: ignore[union-attr]
    return Study("bulk-modulus", _design(model, design), reference, cases)


def calibration(model: FEModel, design: str | None = None, reach: float = 2.0, seed: int = 0) -> Study:
    """Appendix E.1.1: the body silicone calibrated on tension only, ramped to ``reach`` x the pressure.

    The variant's ramp keeps the reference's pressure step, so its level ``k`` is the
    reference's level ``k`` and it goes on to ``reach`` times the pressure; :func:`run_study`
    compares it at the reference pressure and finds the pressure where it comes closest to
    the reference shape.
    """
    reach = checks.real(reach, "reach", 1.0, 10.0)
    body = model.body
    soft, fitted = tension_only(body, seed=seed)
    steps = model.ramp.steps
    increments = round(steps.increments * reach)
    ramp = RampSpec(pressure=model.ramp.pressure * increments / steps.increments,
                    steps=replace(steps, increments=increments))
    variant = model.variant(materials={**model.materials, body.name: soft}, ramp_spec=ramp)
    inputs = {"top_kpa": ramp.pressure * 1e3, "r2_tension": float(fitted.r2["uniaxial"])}
    cases = (Case("tension-only calibration", variant, inputs),)
    return Study("calibration", _design(model, design), Case("tension and compression", model), cases,
                 level=steps.increments - 1, match=True)


def temperature(model: FEModel, design: str | None = None, changes: Sequence[float] = (10.0,)) -> Study:
    """Appendix D.3: uniform temperature changes (degC) from the casting temperature."""
    _needs_3d(model, "temperature")
    cases = tuple(Case(f"temperature {c:+g} degC", model.variant(temperature_change=c), {"temperature_change_c": c})
                  for c in changes)
    return Study("temperature", _design(model, design), Case("as cast", model), cases)


#: The function that sets up each study of :data:`STUDIES`, by name.
BUILDERS: dict[str, Callable[..., Study]] = {"simplifications": simplifications, "tolerances": tolerances,
                                             "bulk-modulus": bulk_modulus, "calibration": calibration,
                                             "temperature": temperature}


# -- running -----------------------------------------------------------------------------------
def _matching(reference: Any, response: Any, level: int) -> tuple[float, float]:
    """The pressure (kPa) of ``response`` closest to ``reference``'s shape at ``level``, and the distance.

    The distance at every reported level is interpolated by a parabola through the best level
    and its neighbours.
    """
    d = np.array([shape_difference(reference, response, level, j).distance_mm for j in range(response.n_levels)])
    k = int(np.nanargmin(d))
    if k + 1 < len(d) and not np.isfinite(d[k + 1]):  # the last converged level: the match may lie beyond
        return float(response.pressures[k] * 1e3), float(d[k])
    p = response.pressures * 1e3
    if 0 < k < len(d) - 1:
        a, b, c = d[k - 1], d[k], d[k + 1]
        curvature = a - 2 * b + c
        if curvature > 0:
            shift = 0.5 * (a - c) / curvature
            step = p[k + 1] - p[k]
            return float(p[k] + shift * step), float(b - 0.25 * (a - c) * shift)
    return float(p[k]), float(d[k])


def run_study(study: Study, evaluator: Any,
              on_case: Callable[[int, int, CaseResult], None] | None = None) -> StudyResult:
    """Solve every case of ``study`` with ``evaluator`` (``iter_cases``) and measure the variants.

    ``on_case(done, total, result)`` is called as each case finishes (progress). Cases come
    from the evaluator's cache when it has one, so an interrupted study resumes.
    """
    cases = study.all_cases()
    outcomes: list[Outcome | None] = [None] * len(cases)
    for done, (i, outcome) in enumerate(evaluator.iter_cases([(c.model, study.design) for c in cases]), start=1):
        outcomes[i] = outcome
        if on_case is not None:
            on_case(done, len(cases), CaseResult(cases[i], outcome))
    ref_outcome = outcomes[0]
    assert ref_outcome is not None
    reference = CaseResult(study.reference, ref_outcome)
    results = []
    for case, outcome in zip(cases[1:], outcomes[1:], strict=True):
        assert outcome is not None
        diff = matching = close = None
        if outcome.ok and ref_outcome.ok:
            diff = shape_difference(ref_outcome.response, outcome.response, study.level)  # type: ignore[arg-type]
        partial = outcome.response is not None and np.isfinite(outcome.response.curl).any()
        if study.match and ref_outcome.ok and partial:  # a ramp that failed still shows where it came closest
            matching, close = _matching(ref_outcome.response, outcome.response, study.level)
        results.append(CaseResult(case, outcome, diff, matching, close))
    return StudyResult(study, reference, tuple(results))



__all__ = ["BUILDERS", "DISSERTATION", "FIELDS", "STUDIES", "Case", "CaseResult", "Study", "StudyResult",
           "bulk_modulus", "calibration", "run_study", "simplifications", "temperature", "tolerances"]

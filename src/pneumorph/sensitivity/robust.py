"""Robustness of every design to mould tolerances, through the chain model.

A chain table (:mod:`pneumorph.models.chain.model`) holds the chord turns and lengths of every
window of units. Under a mould tolerance each of these moves smoothly with the three
thicknesses of Fig E.4, and the change is local again (a unit's response depends on its
neighbourhood), so it is tabulated the same way, with a narrower window: a
:class:`ToleranceTables` holds window-1 tables of the unit at its nominal thicknesses, at
``-t`` and ``+t`` of each thickness alone, and at the corners of the tolerance box (15
tables for three thicknesses, 2 FE solves each for 15 units).
:meth:`ToleranceTables.perturbed` then gives the chain table of *any* offsets within the
class: the full nominal table plus, read at each window's inner three units, a polynomial
in the offsets that is exact for any quadratic with all products of the thicknesses
(:meth:`ToleranceTables._change`). Scoring every design under ``S`` seeded samples of the
class costs ``S`` chain scorings
(:func:`pneumorph.design.runs.robustness.design_robustness`). The tolerance study's FE
solves of a design check it (``docs/sensitivity.md``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from itertools import combinations
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import ChainTableError
from pneumorph.models.chain.fit import fit_table
from pneumorph.models.chain.model import ChainTable, covering_designs, source_description, source_key
from pneumorph.sensitivity.tolerances import Tolerance, box_units, corner_label

FloatArray = NDArray[np.float64]

#: window of the tolerance tables (2 covering designs)
TOLERANCE_WINDOW = 1
#: the statistics ``--robust`` ranks by
STATISTICS = ("worst", "mean")


def inner_codes(codes: NDArray[np.int64], window: int, inner: int = TOLERANCE_WINDOW) -> NDArray[np.int64]:
    """The codes of the inner ``inner``-windows of ``window``-window codes (same centre unit).

    >>> from pneumorph.models.chain.windows import window_codes
    >>> bits = np.array([[0, 1, 1, 0, 1]])
    >>> bool((inner_codes(window_codes(bits, 3), 3) == window_codes(bits, 1)).all())
    True
    """
    codes = np.asarray(codes, dtype=np.int64)
    shift = 4 ** (window - inner)
    return (codes // shift) % 4 ** (2 * inner + 1)


@dataclass(frozen=True)
class ToleranceTables:
    """Window-1 chain tables at the nominal thicknesses and at ``-t``/``+t`` of each (see the module).

    Attributes
    ----------
    tolerance : Tolerance
    nominal : ChainTable
    minus, plus : tuple of ChainTable
        One per field of the tolerance, in its order.
    corners : tuple of ChainTable
        One per corner of the tolerance box, in :meth:`Tolerance.corners` order (empty: no
        interactions between the thicknesses).
    source : dict
        ``key`` (the chain source key of the nominal model), ``element_size`` (the matched
        mesh size of every table), ``fingerprints`` of the FE models solved.
    """

    tolerance: Tolerance
    nominal: ChainTable
    minus: tuple[ChainTable, ...]
    plus: tuple[ChainTable, ...]
    source: dict[str, Any]
    corners: tuple[ChainTable, ...] = ()

    def perturbed(self, table: ChainTable, offsets: FloatArray) -> ChainTable:
        """``table`` (the nominal unit's, any window >= 1) moved to thickness ``offsets`` (mm, per field).

        Examples
        --------
        >>> tables = shipped_tolerance_tables()
        >>> from pneumorph.models.chain.sources import shipped_path
        >>> nominal = ChainTable.load(shipped_path("3d"))
        >>> same = tables.perturbed(nominal, np.zeros(3))
        >>> bool(np.array_equal(same.turn, nominal.turn))
        True
        """
        offsets = np.asarray(offsets, dtype=float)
        t = self.tolerance.tolerance
        if offsets.shape != (len(self.tolerance.fields),) or not np.isfinite(offsets).all():
            raise ChainTableError(f"offsets must be {len(self.tolerance.fields)} finite numbers (mm), got {offsets!r}")
        if np.abs(offsets).max(initial=0.0) > t + 1e-12:
            raise ChainTableError(f"offsets {offsets.tolist()} lie outside the tolerance tables' +-{t:g} mm")
        if table.window < TOLERANCE_WINDOW:
            raise ChainTableError(f"a chain table of window +-{table.window} is narrower than the tolerance tables'")
        inner, inner_end = inner_codes(table.codes, table.window), inner_codes(table.end_codes, table.window)
        parts = (self.nominal, *self.minus, *self.plus, *self.corners)
        rows = [x.lookup(inner) for x in parts]
        erows = [x.lookup(inner_end, end=True) for x in parts]
        out: dict[str, Any] = {}
        for name, rr in (("turn", rows), ("length", rows), ("end", erows)):
            values = [getattr(x, name)[r] for x, r in zip(parts, rr, strict=True)]
            out[name] = getattr(table, name) + self._change(values, offsets)
        scalars: dict[str, Any] = {}
        for name in ("centre_y", "tip_ref"):
            values = [np.asarray(getattr(x, name), dtype=float) for x in parts]
            v = np.asarray(getattr(table, name), dtype=float) + self._change(values, offsets)
            scalars[name] = tuple(float(x) for x in v)
        given = dict(zip(self.tolerance.fields, offsets.tolist(), strict=True))
        source = {**table.source, "tolerance_offsets_mm": given}
        return replace(table, **out, **scalars, source=source)

    def _change(self, values: list[Any], d: FloatArray) -> Any:
        """The change from the nominal of one tabulated quantity at offsets ``d``.

        ``values`` holds the quantity in the nominal table, the ``-t`` and the ``+t`` tables of
        each field and, if there are any, the corner tables. The model is the polynomial

            sum_f (g_f d_f + c_f d_f^2) + sum_S b_S prod_(f in S) d_f   (S: 2 or more fields)

        with ``g_f``, ``c_f`` from the central differences along each axis (exact at the
        nominal and at the axis points) and the interactions ``b_S`` from the corners,
        ``b_S = sum_corners (prod_(f in S) s_f) value / (2^m t^|S|)``: exact for any
        quadratic in the thicknesses with all their products, as the FE response is to second
        order.
        """
        t, m = self.tolerance.tolerance, len(self.tolerance.fields)
        n0, minus, plus = values[0], values[1:1 + m], values[1 + m:1 + 2 * m]
        total = np.zeros_like(n0)
        for i in range(m):
            lo, hi = minus[i], plus[i]
            total = total + (hi - lo) / (2 * t) * d[i] + (hi + lo - 2 * n0) / (2 * t * t) * d[i] ** 2
        corners = values[1 + 2 * m:]
        if corners:
            signs = np.sign(self.tolerance.corners())  # (2^m, m), the order the corner tables were built in
            for size in range(2, m + 1):
                for subset in combinations(range(m), size):
                    weight = np.prod(signs[:, subset], axis=1)
                    b = sum(w * c for w, c in zip(weight, corners, strict=True)) / (2**m * t**size)
                    total = total + b * np.prod(d[list(subset)])
        return total

    # -- persistence --------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {"kind": "pneumorph tolerance tables", "tolerance_mm": self.tolerance.tolerance,
                "fields": list(self.tolerance.fields), "source": self.source, "nominal": self.nominal.to_dict(),
                "minus": [x.to_dict() for x in self.minus], "plus": [x.to_dict() for x in self.plus],
                "corners": [x.to_dict() for x in self.corners]}

    @classmethod
    def from_dict(cls, data: dict[str, Any], where: str = "tolerance tables") -> ToleranceTables:
        try:
            if data.get("kind") != "pneumorph tolerance tables":
                raise KeyError("kind")
            tolerance = Tolerance(float(data["tolerance_mm"]), tuple(data["fields"]))
            return cls(tolerance, ChainTable.from_dict(data["nominal"], where),
                       tuple(ChainTable.from_dict(x, where) for x in data["minus"]),
                       tuple(ChainTable.from_dict(x, where) for x in data["plus"]), dict(data["source"]),
                       tuple(ChainTable.from_dict(x, where) for x in data.get("corners", [])))
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise ChainTableError(f"{where}: not a tolerance table file ({exc})") from None

    def save(self, path: str | Path) -> Path:
        from pneumorph.io.files import write_json

        return write_json(Path(path), self.to_dict())

    @classmethod
    def load(cls, path: str | Path) -> ToleranceTables:
        from pneumorph.io.reading import read_json

        p = Path(path)
        return cls.from_dict(read_json(p, "tolerance tables", ChainTableError), str(p))


def _variants(model: Any, tolerance: Tolerance, corners: bool = True) -> list[tuple[str, Any]]:
    """The FE models of the tables at the matched element size: nominal, -t and +t of each field, and
    (``corners``) every corner of the box in :meth:`Tolerance.corners` order."""
    m, t = len(tolerance.fields), tolerance.tolerance
    axis = [(f"{f} {sign * t:+g}", sign * t * np.eye(m)[i])
            for sign in (-1.0, 1.0) for i, f in enumerate(tolerance.fields)]
    points = axis + ([(corner_label(o), o) for o in tolerance.corners()] if corners else [])
    nominal, units = box_units(model.unit, tolerance, [o for _, o in points])
    return [("nominal", model.variant(unit=nominal))] + [
        (label, model.variant(unit=unit)) for (label, _), unit in zip(points, units, strict=True)]


def build_tolerance_tables(model: Any, tolerance: Tolerance | None = None, evaluator: Any = None, n_units: int = 15,
                           on_progress: Callable[[str], None] | None = None, corners: bool = True) -> ToleranceTables:
    """Solve the covering designs of the variants of ``model``'s unit (nominal, each thickness at -t and
    +t, and with ``corners`` the 8 corners) and fit their window-1 tables.

    ``model`` is any FE model of the nominal unit (its number of units is replaced by
    ``n_units``, the training actuator). The solves go through ``evaluator.iter_cases``
    (cached: resumable).
    """
    from pneumorph.execution.evaluators import SerialEvaluator

    tolerance = tolerance or Tolerance()
    evaluator = evaluator or SerialEvaluator()
    say = on_progress or (lambda text: None)
    training = model.with_units(n_units)
    variants = _variants(training, tolerance, corners)
    designs = covering_designs(n_units, TOLERANCE_WINDOW)
    cases = [(m, d) for _, m in variants for d in designs]
    responses: list[Any] = [None] * len(cases)
    for done, (i, outcome) in enumerate(evaluator.iter_cases(cases), start=1):
        if not outcome.ok:
            raise ChainTableError(f"tolerance table design {outcome.design} ({variants[i // len(designs)][0]}) did "
                                  f"not converge: {outcome.failure}")
        responses[i] = outcome.response
        say(f"tolerance tables: {done}/{len(cases)} solves")
    tables = []
    for j, (label, m) in enumerate(variants):
        src = {"fidelity": getattr(m, "fidelity", "?"), "key": source_key(m), "fingerprint": m.fingerprint(),
               "n_units": n_units, "description": source_description(m), "variant": label}
        tables.append(fit_table(responses[j * len(designs):(j + 1) * len(designs)], TOLERANCE_WINDOW, src))
    k = len(tolerance.fields)
    source = {"key": source_key(model), "element_size": variants[0][1].unit.element_size,
              "fingerprints": [m.fingerprint() for _, m in variants], "n_units": n_units}
    return ToleranceTables(tolerance, tables[0], tuple(tables[1:1 + k]), tuple(tables[1 + k:1 + 2 * k]), source,
                           tuple(tables[1 + 2 * k:]))


def shipped_tolerance_path(fidelity: str = "3d", tolerance: float = 0.1) -> Path:
    """The shipped tolerance tables of the built-in unit."""
    from importlib import resources

    return Path(str(resources.files("pneumorph.models") / "data" / f"chain-{fidelity}-tolerance-{tolerance:g}.json"))


def shipped_tolerance_tables(fidelity: str = "3d", tolerance: float = 0.1) -> ToleranceTables:
    """The shipped tolerance tables (``ChainTableError`` if there are none for this fidelity and class)."""
    path = shipped_tolerance_path(fidelity, tolerance)
    if not path.is_file():
        raise ChainTableError(f"no shipped tolerance tables for the {fidelity} model and +-{tolerance:g} mm")
    return ToleranceTables.load(path)


def tolerance_file(folder: str | Path, model: Any, tolerance: Tolerance) -> Path:
    """Where the tolerance tables of ``model``'s unit are kept in a table folder."""
    key = source_key(model)
    return Path(folder) / f"chain-{getattr(model, 'fidelity', 'model')}-{key}-tolerance-{tolerance.tolerance:g}.json"


def restrict_tolerance_tables(tables: ToleranceTables, levels: int, key: str) -> ToleranceTables:
    """``tables`` restricted to their first ``levels`` levels (each table by
    :func:`~pneumorph.models.chain.sources.restrict_table`), for the model of source key ``key`` (the
    model remade with the ramp of those levels). A pure function.

    >>> tables = shipped_tolerance_tables("2d")
    >>> short = restrict_tolerance_tables(tables, 3, "k")
    >>> short.nominal.n_levels, len(short.plus), short.source["key"], short.source["restricted_from"]["levels"]
    (3, 3, 'k', 10)
    """
    from pneumorph.models.chain.sources import restrict_table

    def cut(group: tuple[ChainTable, ...]) -> tuple[ChainTable, ...]:
        return tuple(restrict_table(t, levels) for t in group)

    source = {**tables.source, "key": key,
              "restricted_from": {"key": tables.source.get("key"), "levels": tables.nominal.n_levels}}
    return ToleranceTables(tables.tolerance, restrict_table(tables.nominal, levels), cut(tables.minus),
                           cut(tables.plus), source, cut(tables.corners))


def _serving_levels(tables: ToleranceTables, model: Any) -> int | None:
    """How many of the tables' levels are ``model``'s levels, if the tables are of ``model``'s unit with a longer
    ramp of the same step (``model`` reports exactly their first levels); else None."""
    from pneumorph.models.chain.sources import level_pressure, ramp_variant

    nominal = tables.nominal
    k = nominal.n_levels
    p = np.asarray(model.pressures(), dtype=float)
    m = len(p)
    if not 1 <= m <= k or not np.allclose(p, nominal.pressures[:m], rtol=0, atol=1e-12):
        return None
    wide = ramp_variant(model, level_pressure(nominal, k), k)
    if wide is None or source_key(wide) != tables.source.get("key"):
        return None
    return m


def find_tolerance_tables(model: Any, tolerance: Tolerance, folder: str | Path | None = None) -> ToleranceTables | None:
    """The shipped or kept tolerance tables of ``model``'s unit and ramp, or None.

    Tables of a longer ramp of the same step serve a model whose levels are their first ones
    (a model remade by :func:`~pneumorph.models.chain.sources.ramp_variant` for a restricted
    chain table): they are restricted to those levels (:func:`restrict_tolerance_tables`).

    >>> from pneumorph.models.chain.sources import serve_table
    >>> from pneumorph.models.factory import make_model
    >>> served = serve_table(make_model(10, {"fidelity": "3d", "pressure_kpa": 25}))
    >>> find_tolerance_tables(served.model, Tolerance(0.1)).nominal.n_levels
    5
    """
    key = source_key(model)
    fidelity = str(getattr(model, "fidelity", ""))
    candidates = [shipped_tolerance_path(fidelity, tolerance.tolerance)]
    if folder is not None:
        candidates.append(tolerance_file(folder, model, tolerance))
        if Path(folder).is_dir():
            candidates += sorted(Path(folder).glob(f"chain-{fidelity}-*-tolerance-{tolerance.tolerance:g}.json"))
    for path in dict.fromkeys(candidates):
        if not path.is_file():
            continue
        try:
            tables = ToleranceTables.load(path)
        except ChainTableError:
            continue
        if tables.tolerance != tolerance:
            continue
        if tables.source.get("key") == key:
            return tables
        levels = _serving_levels(tables, model)
        if levels is not None:
            return restrict_tolerance_tables(tables, levels, key)
    return None


def tolerance_plan_text(model: Any, tolerance: Tolerance, workers: int = 1, n_units: int = 15,
                        corners: bool = True, what: bool = True) -> str:
    """What building the tolerance tables of ``model``'s unit solves, and the estimated time (before any solve);
    without ``what``, only the tables, solves and estimate.

    >>> from pneumorph.models.factory import make_model
    >>> tolerance_plan_text(make_model(15, {"fidelity": "2d"}), Tolerance(0.1), workers=2)  # doctest: +ELLIPSIS
    'building the tolerance tables of the 2d model (the built-in unit, +-0.1 mm): 15 window-1 tables, 30 FE ...'
    >>> tolerance_plan_text(make_model(15, {"fidelity": "3d"}), Tolerance(0.1), 2, what=False)  # doctest: +ELLIPSIS
    '15 window-1 tables, 30 FE solves of 15-unit designs; estimated 3.8 min with 2 workers (about 15 s a 3d solve ...'
    """
    from pneumorph.models.chain.plan import estimate_text, unit_text

    m = len(tolerance.fields)
    tables = 1 + 2 * m + (2**m if corners else 0)
    solves = tables * len(covering_designs(n_units, TOLERANCE_WINDOW))
    fidelity = str(getattr(model, "fidelity", "?"))
    cost = (f"{tables} window-1 tables, {solves} FE solves of {n_units}-unit designs; "
            f"{estimate_text(solves, fidelity, n_units, workers)}")
    if not what:
        return cost
    return (f"building the tolerance tables of the {fidelity} model ({unit_text(model)}, +-{tolerance.tolerance:g} "
            f"mm): {cost}")


def tolerance_tables_for(model: Any, tolerance: Tolerance, folder: str | Path | None = None, evaluator: Any = None,
                         on_progress: Callable[[str], None] | None = None) -> ToleranceTables:
    """The tolerance tables of ``model``'s unit: shipped, kept in ``folder`` (also of a longer ramp of the same
    step, restricted: :func:`find_tolerance_tables`), or built now (cached) and kept.

    A build first says what it will build and its estimated time (:func:`tolerance_plan_text`),
    and holds a lock on its file (:func:`~pneumorph.models.chain.building.build_once`): another
    process that needs the same tables waits for them and reuses them.
    """
    from pneumorph.models.chain.building import build_once
    from pneumorph.models.chain.plan import evaluator_workers

    found = find_tolerance_tables(model, tolerance, folder)
    if found is not None:
        return found
    say = on_progress or (lambda text: None)

    def build() -> ToleranceTables:
        say(tolerance_plan_text(model, tolerance, evaluator_workers(evaluator)))
        tables = build_tolerance_tables(model, tolerance, evaluator, on_progress=on_progress)
        if folder is not None:
            tables.save(tolerance_file(folder, model, tolerance))
        return tables

    if folder is None:
        return build()
    target = tolerance_file(folder, model, tolerance)
    return build_once(target, lambda: find_tolerance_tables(model, tolerance, folder), build, say,
                      f"tolerance tables {target.name}")


@dataclass(frozen=True)
class Robustness:
    """Every design's objective under ``samples`` offsets of a tolerance class, at its chosen level.

    Attributes
    ----------
    bits : ndarray, shape (m, n)
    level : ndarray, shape (m,)
        The level (pressure) each design is judged at.
    values : ndarray, shape (samples, m)
        The objective of each design under each sample.
    offsets : ndarray, shape (samples, fields)
    sense : {"min", "max"}
    """

    bits: NDArray[np.integer]
    level: NDArray[np.integer]
    values: FloatArray
    offsets: FloatArray
    sense: str

    def statistic(self, name: str) -> FloatArray:
        """``"worst"``, ``"mean"`` or ``"p95"`` (the 95th percentile toward the worse side) per design."""
        v = self.values if self.sense == "min" else -self.values
        if name == "worst":
            out = v.max(axis=0)
        elif name == "mean":
            out = v.mean(axis=0)
        elif name == "p95":
            out = np.percentile(v, 95, axis=0)
        else:
            raise ValueError(f"unknown statistic {name!r}")
        return out if self.sense == "min" else -out

    def summary(self, i: int = 0) -> dict[str, float]:
        """:func:`spread` of design ``i``."""
        return spread(self.values[:, i], self.sense)


def spread(values: Any, sense: str) -> dict[str, float]:
    """Mean, worst, 95th percentile toward the worse side, best, and number of the ``values`` of one
    design under the samples (``sense`` "min": larger is worse).

    >>> spread([1.0, 2.0, 4.0], "min")["worst"], spread([1.0, 2.0, 4.0], "max")["worst"]
    (4.0, 1.0)
    """
    v = np.asarray(values, dtype=float)
    sign = 1.0 if sense == "min" else -1.0
    worse = sign * v
    return {"mean": float(v.mean()), "worst": float(sign * worse.max()), "p95": float(sign * np.percentile(worse, 95)),
            "best": float(sign * worse.min()), "samples": len(v)}


__all__ = ["STATISTICS", "TOLERANCE_WINDOW", "Robustness", "ToleranceTables", "build_tolerance_tables",
           "find_tolerance_tables", "inner_codes", "restrict_tolerance_tables",
           "shipped_tolerance_path", "shipped_tolerance_tables", "spread", "tolerance_file", "tolerance_plan_text",
           "tolerance_tables_for"]

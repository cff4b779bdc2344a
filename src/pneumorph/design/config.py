"""Settings of a design run and their TOML form (read with :mod:`tomllib`, written here).

A config file::

    [design]
    objective = "sin"        # a tip goal, a preset (sin, cos, hook, letter-l, ...), "y = ...", "path", or "stages"
    path = [[0, 6], [90, 6], [120, 40]]   # with objective = "path": ordered points from the base, mm
    amplitude = 10.0         # mm
    periods = 1.0
    units = 15
    search = "certified"     # or "ga", "exhaustive"
    seed = 0
    certify = false          # certified search: verify until no design can beat the winner
    verify = 2               # designs verified by FE per batch (default: one per worker)
    max_open = 100000        # certified search: open prefixes its branch-and-bound keeps (default: what fits 4 GB)
    tolerance = 0.1          # mould tolerance of the winner's robustness report, +- mm (0: none)
    robust = "worst"         # certified search: rank designs by their worst (or mean) error under it
    robust_samples = 30      # seeded samples of the tolerance class (default 30 by the chain, 8 by FE)

    [[design.stage]]         # with objective = "stages": a target at each of several pressures
    pressure_kpa = 18        # a level of the model's ramp
    objective = "curve"      # a profile, a drawn curve or "reach"; its own amplitude, periods,
    curve = [[0, 0], [80, 2], [160, 5]]   # curve, point, anchored, and a weight (default 1)

    [ga]
    population = 100
    generations = 15

    [execution]
    executor = "processes"   # processes (default) | serial | dask
    cache = "evaluations.sqlite"

    [model]                  # handed to the model factory (DesignConfig.make_model)
    fidelity = "3d"          # default: 3d for the certified search, 2d for ga and exhaustive
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

from pneumorph import checks
from pneumorph.design.objectives.contact import clearing
from pneumorph.design.objectives.targets import PRESETS, Objective, make_objective, staged_target
from pneumorph.design.search.exhaustive import MAX_UNITS as EXHAUSTIVE_MAX_UNITS
from pneumorph.design.search.genetic import GAConfig
from pneumorph.design.settings import address, curve_points, flag, integer, real, stage_tables, text, tip_point
from pneumorph.errors import SearchConfigError, TargetExpressionError, UnknownObjectiveError
from pneumorph.execution.evaluators import check_execution
from pneumorph.geometry.unit import UnitSpec
from pneumorph.io.files import read_toml

SEARCHES = ("certified", "ga", "exhaustive")
#: the ``[model]`` keys that name the unit (one of them replaces the others)
UNIT_SOURCES = frozenset({"unit", "unit_file", "library"})
#: what ``robust`` ranks designs by (pneumorph.sensitivity.robust.STATISTICS)
ROBUST = ("worst", "mean")
#: the settings only the certified search reads, at their defaults: the genetic algorithm and the FE exhaustive search
#: read none of them (:meth:`DesignConfig.as_ga` sets them back to these)
CERTIFIED_ONLY: dict[str, Any] = {"certify": False, "verify": None, "margin": 1.0, "epsilon": 0.0, "max_open": None,
                                  "refine": 0.0, "chain_table": None, "robust": None}
#: what the genetic algorithm a certified run falls back to does not do, per setting of :data:`CERTIFIED_ONLY`
#: (``pneumorph design`` names it when it refuses such a setting)
GA_CANNOT = {"certify": "certifies no winner", "verify": "verifies no chain's best designs by FE",
             "margin": "has no chain bound to widen", "epsilon": "has no chain bound to certify within",
             "max_open": "keeps no open prefixes", "refine": "does not refine its designs",
             "chain_table": "scores no design by a chain table", "robust": "ranks no design under the tolerance"}


@dataclass(frozen=True)
class DesignConfig:
    """Everything that defines a design run (the model's own settings go in ``model``).

    The defaults are those of ``pneumorph design``: a 15-unit actuator for the target
    "sin, amplitude 10 mm, one period", the certified search, the solves in a pool of
    processes (``executor = "processes"``, one per core; ``"serial"`` solves in this
    process), and the model of :attr:`fidelity` (3D for the certified search, 2D for the
    others) built by :meth:`make_model`. A script that uses the process pool (or Dask)
    needs an ``if __name__ == "__main__":`` guard: the workers import it.

    Examples
    --------
    >>> c = DesignConfig(objective="cos", amplitude=20.0, units=8)
    >>> DesignConfig.from_dict(c.to_dict()) == c
    True
    >>> DesignConfig(units=0)
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: [design] units must be a whole number >= 1 and <= 100, got 0
    """

    objective: str = "sin"
    amplitude: float = 10.0
    periods: float = 1.0
    point: tuple[float, ...] | None = None
    curve: tuple[tuple[float, ...], ...] | None = None
    path: tuple[tuple[float, ...], ...] | None = None
    anchored: bool = True
    stage: tuple[dict[str, Any], ...] | None = None
    clear: dict[str, Any] | None = None
    units: int = 15
    search: str = "certified"
    seed: int = 0
    certify: bool = False
    verify: int | None = None
    margin: float = 1.0
    epsilon: float = 0.0
    max_open: int | None = None
    refine: float = 0.0
    chain_table: str | None = None
    tolerance: float = 0.1
    robust: str | None = None
    robust_samples: int | None = None
    ga: GAConfig = field(default_factory=GAConfig)
    executor: str = "processes"
    workers: int | None = None
    scheduler: str | None = None
    cache: str | None = None
    model: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        integer(self.units, "[design] units", 1, checks.MAX_UNITS, limit="MAX_UNITS")
        text(self.objective, "[design] objective")
        text(self.search, "[design] search", SEARCHES)
        if self.search == "exhaustive" and self.units > EXHAUSTIVE_MAX_UNITS:
            raise SearchConfigError(
                f"the exhaustive search takes at most {EXHAUSTIVE_MAX_UNITS} units (2^{self.units} = "
                f"{2 ** self.units:,} designs for {self.units}); use the certified search or the genetic algorithm")
        text(self.executor, "[execution] executor", checks.EXECUTORS)
        integer(self.seed, "[design] seed", 0, 2**32 - 1)
        flag(self.certify, "[design] certify")
        flag(self.anchored, "[design] anchored")
        object.__setattr__(self, "amplitude", real(self.amplitude, "[design] amplitude", 0.0, low_open=True,
                                                    unit="mm"))
        object.__setattr__(self, "periods", real(self.periods, "[design] periods", 0.0, 1000.0, low_open=True))
        object.__setattr__(self, "margin", real(self.margin, "[design] margin", 0.0, 1e3, low_open=True))
        object.__setattr__(self, "epsilon", real(self.epsilon, "[design] epsilon", 0.0, 1e3))
        object.__setattr__(self, "refine", real(self.refine, "[design] refine", 0.0, 100.0, unit="mm"))
        object.__setattr__(self, "tolerance", real(self.tolerance, "[design] tolerance", 0.0, 1.0, unit="mm"))
        if self.robust_samples is not None:
            integer(self.robust_samples, "[design] robust_samples", 1, 10_000)
        if self.robust is not None:
            text(self.robust, "[design] robust", ROBUST)
            if self.search != "certified" or self.tolerance == 0:
                raise SearchConfigError("[design] robust ranks every design by the chain model under the mould "
                                        "tolerance: it needs search = \"certified\" and a tolerance > 0")
        if self.search != "certified":
            given = self.certified_settings()
            if given:
                raise SearchConfigError(f"[design] {', '.join(given)} only appl{'y' if len(given) > 1 else 'ies'} "
                                        f"to the certified search, not to search = {self.search!r}; leave them out "
                                        "or set search = \"certified\"")
        if self.verify is not None:
            integer(self.verify, "[design] verify", 1, 1024)
        if self.max_open is not None:
            integer(self.max_open, "[design] max_open", 1, 10**9)
        if self.workers is not None:
            integer(self.workers, "[execution] workers", 1, 1024)
        if self.scheduler is not None:
            address(self.scheduler, "[execution] scheduler")
        check_execution(self.executor, self.workers, self.scheduler,
                        ("[execution] executor", "[execution] workers", "[execution] scheduler"))
        for key in ("chain_table", "cache"):
            if getattr(self, key) is not None:
                text(getattr(self, key), f"[{'design' if key == 'chain_table' else 'execution'}] {key}")
        if not isinstance(self.model, dict):
            raise SearchConfigError(f"[model] must be a table, got {self.model!r}")
        if self.ga.seed != self.seed:
            object.__setattr__(self, "ga", replace(self.ga, seed=self.seed))
        if self.point is not None:
            object.__setattr__(self, "point", tip_point(self.point, "[design] point"))
        if self.curve is not None:
            object.__setattr__(self, "curve", curve_points(self.curve, "[design] curve"))
        if self.path is not None:
            object.__setattr__(self, "path", curve_points(self.path, "[design] path"))
        object.__setattr__(self, "stage", stage_tables(self.objective, self.stage))
        self._check_periods()
        unit = self.model.get("unit", {}) if isinstance(self.model.get("unit", {}), dict) else {}
        pitch = unit.get("pitch", UnitSpec.pitch)  # the inline unit's, else the built-in unit's
        ok = isinstance(pitch, (int, float)) and not isinstance(pitch, bool) and pitch > 0
        try:  # fail early on a bad objective: a profile finite along the actuator
            self.make_objective(length=self.units * (pitch if ok else UnitSpec.pitch))
        except (TargetExpressionError, UnknownObjectiveError, SearchConfigError) as exc:
            if self.stage is not None:
                raise SearchConfigError(f"[[design.stage]]: {exc}") from None
            if isinstance(exc, SearchConfigError):
                raise
            raise SearchConfigError(f"[design] objective: {exc}") from None

    def _check_periods(self) -> None:
        """Refuse a sin or cos target of more periods than its unit centres can show (Eq 4.1 samples the target at
        the ``units`` centres: past ``units / 2`` periods it aliases; one period, the presets' default, always)."""
        presets = [("[design] periods", self.objective, self.periods)] if self.stage is None else [
            (f"[[design.stage]] {i} periods", s["objective"], s.get("periods", 1.0))
            for i, s in enumerate(self.stage, 1)]
        for where, name, periods in presets:
            if name.strip().lower() in PRESETS and periods > max(1.0, self.units / 2):
                raise SearchConfigError(f"{where} = {periods:g}: a {name.strip().lower()} target over {self.units} "
                                        f"unit centres shows at most {max(1.0, self.units / 2):g} periods (Eq 4.1 "
                                        "samples it at the centres); give fewer periods or more units")

    @property
    def fidelity(self) -> str:
        """The model's fidelity: ``[model] fidelity`` if given, else ``"3d"`` for the certified search and
        ``"2d"`` for the genetic algorithm and the exhaustive search (as ``pneumorph design`` chooses).

        >>> DesignConfig().fidelity, DesignConfig(search="ga").fidelity, DesignConfig(model={"fidelity": "2d"}).fidelity
        ('3d', '2d', '2d')
        """
        given = self.model.get("fidelity")
        if given is not None:
            return str(given)
        return "3d" if self.search == "certified" else "2d"

    def model_settings(self) -> dict[str, Any]:
        """``model`` with the :attr:`fidelity` written in: the settings :meth:`make_model` builds from."""
        return {**self.model, "fidelity": self.fidelity}

    def make_model(self) -> Any:
        """The FE model of these settings, as ``pneumorph design`` builds it (:attr:`fidelity`, ``units``).

        Returns
        -------
        pneumorph.models.fe.FEModel

        Raises
        ------
        SearchConfigError
            A model setting that is unknown or out of range (:func:`pneumorph.models.factory.make_model`).

        Examples
        --------
        >>> m = DesignConfig(units=4).make_model()
        >>> m.fidelity, m.n_units
        ('3d', 4)
        """
        from pneumorph.models.factory import make_model

        return make_model(self.units, self.model_settings())

    def samples(self, chain: bool) -> int:
        """Samples of the tolerance class: ``robust_samples``, else 30 by the chain model, 8 by FE solves."""
        return self.robust_samples or (30 if chain else 8)

    def make_objective(self, length: float | None = None) -> Objective:
        """The objective these settings describe (a profile checked along ``length`` mm, if given).

        >>> c = DesignConfig(objective="stages", stage=({"pressure_kpa": 18, "objective": "y = 0.05*x"},
        ...                                            {"pressure_kpa": 45, "objective": "sin", "weight": 2}))
        >>> c.make_objective().label
        'stages: 18 kPa: y = 0.05*x; 45 kPa: sin: y = A*sin(2*pi*1*x/L), A = 10 mm (weight 2)'
        """
        if self.stage is not None:
            return staged_target([
                (s["pressure_kpa"] / 1e3,
                 make_objective(s["objective"], s.get("amplitude", 10.0), s.get("periods", 1.0), s.get("point"),
                                s.get("anchored", True), length, s.get("curve"), s.get("path")),
                 s.get("weight", 1.0)) for s in self.stage])
        return clearing(make_objective(self.objective, self.amplitude, self.periods, self.point, self.anchored,
                                       length, self.curve, self.path), self.clear)

    def with_options(self, design: dict[str, Any], ga: dict[str, Any] | None = None,
                     model: dict[str, Any] | None = None, model_file: dict[str, Any] | None = None) -> DesignConfig:
        """These settings with a front end's over them (a None value: not given), checked as a whole.

        ``design`` holds ``[design]`` and ``[execution]`` keys, ``ga`` those of ``[ga]``;
        ``model_file`` (an identified model's ``[model]`` table) goes over the config's model
        settings and ``model`` over both. A unit source in a layer (``unit``, ``unit_file`` or
        ``library``) replaces the one beneath it.

        >>> c = DesignConfig(model={"unit": {"wall": 1.6}, "pressure_kpa": 40})
        >>> d = c.with_options({"units": 8, "seed": None}, ga={"population": 20}, model={"library": "builtin"})
        >>> d.units, d.seed, d.ga.population, d.model
        (8, 0, 20, {'pressure_kpa': 40, 'library': 'builtin'})
        """
        settings = dict(self.model)
        for layer in (model_file or {}, {k: v for k, v in (model or {}).items() if v is not None}):
            if UNIT_SOURCES & set(layer):
                settings = {k: v for k, v in settings.items() if k not in UNIT_SOURCES}
            settings.update(layer)
        ga_changes = {k: v for k, v in (ga or {}).items() if v is not None}
        changed = replace(self, ga=replace(self.ga, **ga_changes), model=settings,
                          **{k: v for k, v in design.items() if v is not None})
        return DesignConfig.from_dict(changed.to_dict())

    def certified_settings(self) -> tuple[str, ...]:
        """The settings only the certified search reads (:data:`CERTIFIED_ONLY`) that these settings give away from
        their defaults, in that order.

        >>> DesignConfig(refine=1.0, verify=2, margin=1.0).certified_settings()
        ('verify', 'refine')
        """
        return tuple(key for key, default in CERTIFIED_ONLY.items() if getattr(self, key) != default)

    def value_text(self, key: str) -> str:
        """A ``[design]`` setting's value as a message names it after its key: a space and the value (a float in
        its shortest form), nothing for a flag.

        >>> DesignConfig(refine=1.0).value_text("refine"), DesignConfig(certify=True).value_text("certify")
        (' 1', '')
        """
        value = getattr(self, key)
        return "" if isinstance(value, bool) else f" {value:g}" if isinstance(value, float) else f" {value}"

    def as_ga(self) -> DesignConfig:
        """The same settings searched by the GA, the certified search's own (:data:`CERTIFIED_ONLY`) set back to
        their defaults (``DesignConfig().as_ga()``)."""
        return replace(self, search="ga", **CERTIFIED_ONLY)

    def searchable(self) -> tuple[DesignConfig, str | None]:
        """The settings a run can search with, and why the certified search cannot run (None: it can, or was not
        asked for): the chain model does not hold under gravity, so a certified search under gravity is the genetic
        algorithm's, without the certified search's own settings (:meth:`as_ga`; ``pneumorph design`` refuses a run
        that gives any of them, :meth:`certified_settings`).

        >>> DesignConfig(model={"gravity": "hanging"}).searchable()[0].search
        'ga'
        """
        held = "gravity" if self.model.get("gravity") not in (None, "none") else \
            "contact with [[model.obstacle]]" if self.model.get("obstacle") else None
        if self.search == "certified" and held:
            return self.as_ga(), ("the certified search needs a free actuator (its chain model does not hold "
                                  f"under {held})")
        return self, None

    def fallback(self, fidelity_given: bool = False) -> DesignConfig:
        """The GA's settings for a certified run whose model the chain cannot represent (``run_design`` raises
        :class:`~pneumorph.errors.LocalityError` before it writes): on the 2D model unless the fidelity was given.
        """
        ga = self.as_ga()
        return ga if fidelity_given else ga.with_options({}, model={"fidelity": "2d"})

    # -- plain-data form --------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """Nested tables ``design``, ``ga``, ``execution``, ``model`` (None values, ``epsilon = 0`` and
        ``refine = 0`` left out)."""
        design = {
            k: getattr(self, k)
            for k in ("objective", "amplitude", "periods", "point", "curve", "path", "anchored", "stage", "clear",
                      "units", "search", "seed", "certify", "verify", "margin", "epsilon", "max_open", "refine",
                      "chain_table", "tolerance", "robust", "robust_samples")
        }
        for key in ("epsilon", "refine"):  # absent by default: the settings of earlier run folders stay the same
            if design[key] == 0.0:
                design[key] = None
        ga = {k: v for k, v in asdict(self.ga).items() if k != "seed"}
        execution = {k: getattr(self, k) for k in ("executor", "workers", "scheduler", "cache")}

        def clean(d: dict[str, Any]) -> dict[str, Any]:
            def plain(v: Any) -> Any:
                if isinstance(v, dict):
                    return {k: plain(x) for k, x in v.items()}
                return [plain(x) for x in v] if isinstance(v, tuple) else v

            return {k: plain(v) for k, v in d.items() if v is not None}

        return {"design": clean(design), "ga": clean(ga), "execution": clean(execution), "model": dict(self.model)}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> DesignConfig:
        """Settings from nested tables (unknown keys are an error, naming the key)."""
        known_design = {f.name for f in fields(cls)} - {"ga", "model", "executor", "workers", "scheduler", "cache"}
        known_ga = {f.name for f in fields(GAConfig)} - {"seed"}
        known_exec = {"executor", "workers", "scheduler", "cache"}
        tables = {"design": known_design, "ga": known_ga, "execution": known_exec}
        for table in set(data) - {*tables, "model", "provenance"}:
            raise SearchConfigError(f"unknown table [{table}] in the design config; "
                                    "known: design, ga, execution, model")
        for table in ("design", "ga", "execution", "model"):
            if not isinstance(data.get(table, {}), dict):
                raise SearchConfigError(f"[{table}] must be a table of settings, got {data[table]!r}")
        kwargs: dict[str, Any] = {}
        for table, known in tables.items():
            for key in set(data.get(table, {})) - known:
                raise SearchConfigError(f"unknown key {key!r} in [{table}]; known keys: {', '.join(sorted(known))}")
        kwargs.update(data.get("design", {}))
        kwargs.update(data.get("execution", {}))
        ga = GAConfig(**{**data.get("ga", {}), "seed": kwargs.get("seed", 0)})
        return cls(ga=ga, model=dict(data.get("model", {})), **kwargs)

    @classmethod
    def read(cls, path: str | Path) -> DesignConfig:
        """Settings from a TOML file (a run folder's ``config.toml`` works too)."""
        data = read_toml(path, "design config", SearchConfigError)
        return cls.from_dict(data)


# -- a small TOML writer (tables of scalars, lists and one level of sub-tables) -----------
def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def to_toml(tables: dict[str, dict[str, Any]]) -> str:
    """TOML text of ``{table: {key: value or {key: value}}}``.

    >>> print(to_toml({"design": {"units": 8, "point": [1.0, 2.0]}, "provenance": {"deps": {"numpy": "2.0"}}}))
    [design]
    units = 8
    point = [1.0, 2.0]
    <BLANKLINE>
    [provenance]
    <BLANKLINE>
    [provenance.deps]
    numpy = "2.0"
    <BLANKLINE>
    """
    lines: list[str] = []
    for name, table in tables.items():
        lines.append(f"[{name}]")
        subtables = {k: v for k, v in table.items() if isinstance(v, dict)}
        arrays = {k: v for k, v in table.items() if isinstance(v, (list, tuple)) and v
                  and all(isinstance(x, dict) for x in v)}
        lines += [f"{k} = {_value(v)}" for k, v in table.items()
                  if k not in subtables and k not in arrays and v is not None]
        lines.append("")
        for sub, content in subtables.items():
            lines.append(f"[{name}.{sub}]")
            lines += [f"{k} = {_value(v)}" for k, v in content.items() if v is not None]
            lines.append("")
        for sub, entries in arrays.items():  # arrays of tables: [[design.stage]]
            for content in entries:
                lines.append(f"[[{name}.{sub}]]")
                lines += [f"{k} = {_value(v)}" for k, v in content.items() if v is not None]
                lines.append("")
    return "\n".join(lines)

"""The bench's answers: the chain model's certified ranking of every design for a query.

:class:`Bench` holds one FE model and its chain model per fidelity (built as the design
command builds them, so the bench, the CLI and the API share tables, cache entries and
fingerprints) and answers a :class:`~pneumorph.bench.query.Query` with the chain model's
best design, its pressure and error, the designs listed by chain value, and what the
chain's validated error bound proves before any FE solve: the model's optimum is among the
designs whose optimistic value beats the winner's pessimistic one
(:mod:`pneumorph.design.certified.search`). An FE verification (a background job) then certifies
the winner in the model itself.
"""

from __future__ import annotations

import json
import re
import threading
import time
from collections import OrderedDict
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.bench.contact import contact_answer, parse_obstacle
from pneumorph.bench.query import MODELS, Query, QueryError, choice, parse_query
from pneumorph.bench.samples import centrelines, path_samples, profiles, stage_samples, target_samples, uses_path
from pneumorph.bench.shapes import chain_placement, surface
from pneumorph.design.certified.planegrowth import designs_of
from pneumorph.design.certified.search import best_scores
from pneumorph.design.certified.spacegrowth import check_space_objective, space_scores
from pneumorph.design.objectives.targets import StagedTarget, TipGoal
from pneumorph.errors import PneumorphError, SearchConfigError
from pneumorph.geometry.unit import UnitSpec
from pneumorph.io.files import atomic_write_text
from pneumorph.models.chain.model import ChainModel, ChainTable
from pneumorph.models.chain.sources import cut_from, find_table, served_as_built
from pneumorph.models.chain.windows import design_numbers
from pneumorph.models.factory import make_model

#: memory a query's branch-and-bound in space may hold (bytes): within the 1.5 GB a bench worker may use, with
#: the worker's own ~0.2 GB (Python, the models and tables) and room to spare
QUERY_MEMORY = 750 * 10**6
#: memory one open prefix of a bench query in space holds, all its children and levels together (bytes; not the
#: certified search's per child and level, :data:`~pneumorph.design.certified.branching.SPACE_PREFIX_BYTES`): the
#: spatial library's 15 units, 4 children a prefix, 10 levels, peak resident memory 309 MB over 10,000 open
#: prefixes and 809 MB over 50,000 (BENCHMARKS.md, "Slow queries under a budget"), 12.5 kB a prefix, as the
#: search's 310 bytes x 4 children x 10 levels (12.4 kB); rounded up to 16 kB
QUERY_PREFIX_BYTES = 16_000
#: the open prefixes a query of a chain in space keeps (46,875): more stay open, the best are kept and the
#: certificate says how much better an unlisted design could be; the default (500,000) held 6 GB
QUERY_NODES = QUERY_MEMORY // QUERY_PREFIX_BYTES
BUILTIN = "builtin"
LIBRARIES = {"spatial": "spatial library: a, l (sideways)"}
"""The built-in unit libraries the bench serves, by id (their shipped 3D tables), and their names."""
UNIT_ID = re.compile(r"u[0-9a-f]{15,16}")
"""An uploaded unit's id: ``u`` and 16 random hex digits (15: the hashed ids of earlier versions)."""


class Bench:
    """Models, chain models and a memo of answers, shared by every request (thread-safe).

    Parameters
    ----------
    units : int
        Units of the actuator (15, as the shipped tables).
    table_dir : path, optional
        Where chain tables built by the bench (or by design runs on the same cache) are kept.
    memo : int
        Answers kept for repeated queries (a page reload, a pressure slider).
    settings : dict, optional
        Model settings under every model (an identified model's ``[model]`` table,
        ``serve --model-file``): its unit is the bench's built-in unit, its material scales
        apply to every unit; the fidelity stays the query's.

    Examples
    --------
    >>> from pneumorph.bench.query import parse_query
    >>> bench = Bench()
    >>> q = parse_query({"target": {"kind": "preset", "name": "sin"}, "model": "3d"}, bench.length("3d"))
    >>> bench.answer(q)["winner"]["design"]
    '001111010001001'
    """

    def __init__(self, units: int = 15, table_dir: str | Path | None = None, memo: int = 256,
                 unit_dir: str | Path | None = None, settings: dict[str, Any] | None = None) -> None:
        self.units = int(units)
        self.settings = {k: v for k, v in (settings or {}).items() if k != "fidelity"}
        self.table_dir = None if table_dir is None else Path(table_dir)
        self.unit_dir = None if unit_dir is None else Path(unit_dir)
        self._specs: dict[str, UnitSpec] = {BUILTIN: UnitSpec()}
        self._models: dict[tuple[str, str], Any] = {}
        self._cut: dict[tuple[str, str], ChainTable] = {}  # tables fitted to fewer levels than the ramp, by model
        self._chains: dict[tuple[str, str], ChainModel] = {}
        self._memo: OrderedDict[str, dict[str, Any]] = OrderedDict()
        self._memo_size = int(memo)
        self._meshes: OrderedDict[str, Any] = OrderedDict()
        self._lock = threading.RLock()
        self.shape_dir: Path | None = None  # where FE shapes of verified designs are kept (set by the app)
        if self.unit_dir is not None and self.unit_dir.is_dir():
            for path in sorted(self.unit_dir.glob("*.toml")):
                try:
                    self._specs[path.stem] = UnitSpec.from_toml(path)
                except Exception:  # a unit file this version cannot read: not offered
                    continue

    # -- units --------------------------------------------------------------------------
    @property
    def unit_ids(self) -> tuple[str, ...]:
        """The units queries may name: ``"builtin"``, the built-in libraries and the uploaded units."""
        return (BUILTIN, *LIBRARIES, *(u for u in self._specs if u != BUILTIN))

    def knows(self, unit: str) -> bool:
        """True for a unit queries may name (one added by another process is read from ``unit_dir``)."""
        if not isinstance(unit, str):
            return False
        if unit in self._specs or unit in LIBRARIES:
            return True
        if self.unit_dir is None or UNIT_ID.fullmatch(unit) is None:
            return False
        path = self.unit_dir / f"{unit}.toml"
        if not path.is_file():
            return False
        with self._lock:
            self._specs[unit] = UnitSpec.from_toml(path)
        return True

    def unit_spec(self, unit: str = BUILTIN) -> UnitSpec:
        return self._specs[unit]

    def add_unit(self, spec: UnitSpec, unit_id: str | None = None) -> str:
        """Offer a unit to queries (kept in ``unit_dir``) under ``unit_id`` (default: a random id).

        The built-in unit's parameters are the built-in unit. Ids are ``u`` and 16 hex
        digits (:data:`UNIT_ID`), random so that nobody can name another's unit by guessing.

        Examples
        --------
        >>> bench = Bench()
        >>> bench.add_unit(UnitSpec()), bench.add_unit(UnitSpec(layer=2.5), "u0123456789abcdef")
        ('builtin', 'u0123456789abcdef')
        """
        import secrets

        if spec == UnitSpec():
            unit_id = BUILTIN
        unit_id = unit_id or "u" + secrets.token_hex(8)
        if unit_id != BUILTIN and UNIT_ID.fullmatch(unit_id) is None:
            raise QueryError("unit", f"a unit id is u and 16 hex digits, got {unit_id[:40]!r}")
        with self._lock:
            if unit_id not in self._specs:
                if self.unit_dir is not None:
                    from pneumorph.design.config import to_toml

                    self.unit_dir.mkdir(parents=True, exist_ok=True)
                    atomic_write_text(self.unit_dir / f"{unit_id}.toml", to_toml({"unit": spec.to_dict()}))
                self._specs[unit_id] = spec
        return unit_id

    # -- models -------------------------------------------------------------------------
    def model_settings(self, fidelity: str, unit: str = BUILTIN) -> dict[str, Any]:
        """The model settings of a fidelity and unit: the bench's ``settings`` with the fidelity, and an
        uploaded unit in place of their unit.

        >>> Bench(settings={"fidelity": "2d", "body_bulk_scale": 1.06}).model_settings("3d")
        {'body_bulk_scale': 1.06, 'fidelity': '3d'}
        """
        settings: dict[str, Any] = {**self.settings, "fidelity": fidelity}
        if unit != BUILTIN:
            settings = {k: v for k, v in settings.items() if k not in ("unit", "unit_file", "library")}
            if unit in LIBRARIES:
                settings["library"] = unit
            else:
                settings["unit"] = self._specs[unit].to_dict()
        return settings

    def model(self, fidelity: str, unit: str = BUILTIN) -> Any:
        """The FE model of a fidelity and unit, as ``pneumorph design --model <fidelity>`` builds it; remade with the
        levels of its chain table when the table was fitted to those every design reached
        (:func:`~pneumorph.models.chain.sources.served_as_built`), so that verifications report the chain's levels."""
        with self._lock:
            if (fidelity, unit) not in self._models:
                made = make_model(self.units, self.model_settings(fidelity, unit))
                table = find_table(made, self.table_dir)
                if table is not None and cut_from(table, made):
                    made = served_as_built(table, made).model
                    self._cut[fidelity, unit] = table
                self._models[fidelity, unit] = made
            return self._models[fidelity, unit]

    def chain(self, fidelity: str, unit: str = BUILTIN) -> ChainModel:
        """The chain model of a fidelity and unit (the shipped table or one kept in ``table_dir``).

        Raises
        ------
        QueryError
            No table exists for the model (field ``model``).
        """
        if unit in LIBRARIES and fidelity != "3d":
            raise QueryError("model", f"the {unit} library's units bend out of the plane: choose the 3D model")
        model = self.model(fidelity, unit)
        with self._lock:
            if (fidelity, unit) not in self._chains:
                table = self._cut.get((fidelity, unit)) or find_table(model, self.table_dir)
                if table is not None and cut_from(table, model):  # built since the model was made
                    self._models[fidelity, unit] = served_as_built(table, model).model
                if table is None and unit == BUILTIN and self.settings:
                    raise QueryError("model", f"no chain table for the {fidelity} model of the served model file "
                                              f"yet; build it once with `pneumorph design --model-file FILE --model "
                                              f"{fidelity}` on the same cache")
                if table is None:
                    raise QueryError("model", f"no chain table for the {fidelity} model of this unit yet; "
                                              "upload the unit to build one")
                self._chains[fidelity, unit] = ChainModel(table, self.units)
            return self._chains[fidelity, unit]

    def length(self, fidelity: str = "3d", unit: str = BUILTIN) -> float:
        """The undeformed actuator length (mm), the ``L`` of profile targets."""
        return self.chain(fidelity, unit).length

    # -- answers ------------------------------------------------------------------------
    def parse(self, body: Any, units: tuple[str, ...] | None = None) -> Query:
        """A query's JSON body checked against its model and unit (:func:`parse_query`).

        Parameters
        ----------
        body : dict
        units : tuple of str, optional
            The units the query may name (a session's own); default: every unit known here.

        Raises
        ------
        QueryError
        """
        model = choice(body.get("model", "3d") if isinstance(body, dict) else "3d", MODELS, "model", "model")
        unit = body.get("unit", BUILTIN) if isinstance(body, dict) else BUILTIN
        if not isinstance(unit, str) or (units is not None and unit not in units) or not self.knows(unit):
            raise QueryError("unit", f"unknown unit {str(unit)[:40]!r}; upload its TOML file to build its chain "
                                     "table first")
        chain = self.chain(model, unit)
        length = chain.length
        query = parse_query(body, length, self.unit_ids if units is None else units, float(chain.table.tip_ref[1]))
        objective = query.objective(length)
        if chain.table.axes == 3:  # a chain in space scores fewer kinds of target
            try:
                check_space_objective(objective)
            except SearchConfigError:
                raise QueryError("target", f"the {unit} library's chain scores profiles, space curves, paths and "
                                           "tip goals other than the curl, not this target") from None
        if isinstance(objective, StagedTarget):  # each stage at a level of the ramp
            try:
                objective.levels(chain.pressures(), how="")
            except SearchConfigError as exc:
                raise QueryError("stages", str(exc)) from None
        circle = parse_obstacle(body.get("obstacle"), length)
        if circle is not None and model != "2d":
            raise QueryError("obstacle", "an object is solved by the 2D FE model with contact: choose the 2D model")
        return query if circle is None else replace(query, obstacle=circle)

    def slow(self, query: Query) -> bool:
        """Whether ``query`` is answered by the branch-and-bound of a chain in space (seconds to a minute, within
        :data:`QUERY_MEMORY`) or has its winner solved against an object by FE (:mod:`pneumorph.bench.contact`):
        the bench answers such queries on a worker of their own.

        >>> from pneumorph.bench.query import Query
        >>> bench = Bench()
        >>> bench.slow(Query("preset", "sin")), bench.slow(Query("tip", "max-x", unit="spatial"))
        (False, True)
        """
        return query.obstacle is not None or self.chain(query.model, query.unit).table.axes == 3

    def recall(self, query: Query) -> dict[str, Any] | None:
        """A remembered answer to ``query`` (marked ``memo``), or None."""
        key = query.key()
        with self._lock:
            hit = self._memo.get(key)
            if hit is None:
                return None
            self._memo.move_to_end(key)
        return {**hit, "elapsed_ms": 0.0, "memo": True}

    def remember(self, query: Query, answer: dict[str, Any]) -> None:
        """Keep an answer for the next equal query (the oldest ones go first)."""
        with self._lock:
            self._memo[query.key()] = answer
            while len(self._memo) > self._memo_size:
                self._memo.popitem(last=False)

    def answer(self, query: Query) -> dict[str, Any]:
        """The chain model's answer to ``query`` as plain JSON-ready data (remembered).

        Keys: ``query_id``, ``label``, ``model``, ``units``, ``length_mm``,
        ``pressures_kpa``, ``sense``, ``value_unit``, ``winner`` (design, value, level,
        pressure_kpa), ``certificate`` (bound, candidates, designs, scored, complete,
        statement), ``top`` (rank, design, value, pressure_kpa, optimistic), ``target``
        (curve samples or None), ``point``, ``profiles`` (the winner's base, centres and tip
        at every level, heights above the undeformed axis), ``stages``, ``path`` (a path's
        polyline placed on the actuator, mm, or None), ``axis_mm`` (the undeformed axis above
        the bottom face), ``centrelines`` (for a path or stages with one: the winner's base,
        centres and tip at every level as the model reports them, the path's frame, as with an object on the page;
        else None; :mod:`pneumorph.bench.samples`), ``elapsed_ms`` and ``memo``; with an object on the page,
        ``contact``: the winner solved against it by the 2D FE model (:func:`~pneumorph.bench.contact.contact_answer`).
        """
        hit = self.recall(query)
        if hit is not None:
            return hit
        out = self.compute(query)
        self.remember(query, out)
        return out

    def compute(self, query: Query) -> dict[str, Any]:
        """The answer to ``query``, computed (no memo)."""
        start = time.perf_counter()
        out = self._answer(query)
        out["elapsed_ms"] = round(1e3 * (time.perf_counter() - start), 3)
        out["memo"] = False
        return out

    def _answer(self, query: Query) -> dict[str, Any]:
        chain = self.chain(query.model, query.unit)
        length, axis = chain.length, float(chain.table.tip_ref[1])
        objective = query.objective(length)
        if chain.table.axes == 3:  # within the query's memory budget (QUERY_NODES)
            scores = space_scores(chain, objective, max_nodes=QUERY_NODES)
        else:
            scores = best_scores(chain, objective, top=query.top)
        sign = 1.0 if objective.sense == "min" else -1.0
        k = min(query.top, len(scores.cost))
        top = np.argpartition(scores.cost, k - 1)[:k]
        numbers = design_numbers(scores.bits[top], scores.choices)
        top = top[np.lexsort((numbers, scores.cost[top]))]  # ties: the smaller design first
        designs = chain.table.texts(scores.bits[top])
        kpa = chain.pressures() * 1e3
        best = int(top[0])
        worst_case = float(scores.cost[best] + scores.bound[best])  # the winner's FE value is at least this good
        candidates = int(np.count_nonzero(scores.optimistic < worst_case))
        winner = designs[0]
        response = chain.evaluate(winner)
        level = int(scores.level[best])
        unit = objective.unit
        every = round(designs_of(chain))
        # the designs left unlisted are bounded below by the floor: at or above the winner's worst case, none of
        # them can beat it; below it (a branch-and-bound that had to drop open prefixes) the answer is not certain
        certain = bool(scores.floor >= worst_case)
        certificate = {
            "bound": float(scores.bound[best]),
            "candidates": candidates,
            "designs": every,
            "scored": len(scores.cost),  # the others are bounded above the threshold (floor)
            "complete": bool(scores.complete),
            "certified": certain,
            "statement": _statement(query.model, float(scores.bound[best]), unit, candidates, every, certain,
                                    sign * float(scores.floor)),
        }
        out = {
            "query_id": key_id(query.key()),
            "label": objective.label,
            "model": query.model,
            "units": self.units,
            "length_mm": length,
            "pressures_kpa": [round(float(p), 9) for p in kpa],
            "sense": objective.sense,
            "value_unit": unit,
            "winner": {"design": winner, "value": sign * float(scores.cost[best]), "level": level,
                       "pressure_kpa": float(kpa[level])},
            "certificate": certificate,
            "top": [{"rank": i + 1, "design": d, "value": sign * float(scores.cost[j]),
                     "pressure_kpa": float(kpa[int(scores.level[j])]), "optimistic": sign * float(scores.optimistic[j])}
                    for i, (d, j) in enumerate(zip(designs, top, strict=False))],
            "target": target_samples(objective, length),
            "point": list(objective.point) if isinstance(objective, TipGoal) and objective.point is not None else None,
            "profiles": profiles(response),
            "stages": stage_samples(objective, chain.pressures(), length, axis),
            "path": path_samples(objective, length, axis),
            "axis_mm": axis,
            "centrelines": centrelines(response) if uses_path(objective) or query.obstacle is not None else None,
        }
        if query.obstacle is not None:  # the winner solved against the object: its force and contact
            out["contact"] = contact_answer(self.model("2d", query.unit), winner, query.obstacle)
        return out

    def chain_lines(self, design: str, fidelity: str, unit: str = BUILTIN) -> dict[str, Any]:
        """A design's predicted lines at every level: ``profiles`` (heights above the axis, :func:`profiles`) and
        ``centrelines`` (as the model reports them, a path's frame, :func:`~pneumorph.bench.samples.centrelines`)."""
        chain = self.chain(fidelity, unit)
        response = chain.evaluate(_design(chain, design))
        return {"profiles": profiles(response), "centrelines": centrelines(response)}

    def chain_shape(self, design: str, fidelity: str, level: int, unit: str = BUILTIN) -> dict[str, Any]:
        """The 3D surface of a design at ``level``: its FE solution if one was kept, else laid along its
        predicted centreline."""
        chain = self.chain(fidelity, unit)
        design = _design(chain, design)
        k = len(chain.pressures())
        if isinstance(level, bool) or not isinstance(level, int) or not 0 <= level < k:
            raise QueryError("level", f"level must be a whole number from 0 to {k - 1}, got {level!r}")
        fe = self.fe_shape_file(design, unit)
        if fe is not None and fidelity == "3d":
            data = json.loads(fe.read_text(encoding="utf-8"))
            return {"source": "fe", "indices": data["indices"], **data["levels"][level]}
        mesh = self._mesh(design, unit)
        return {"source": "chain", **surface(mesh, chain_placement(mesh, chain.evaluate(design), level))}

    # -- FE shapes of verified designs --------------------------------------------------
    def _mesh(self, design: str, unit: str) -> Any:
        """The 3D mesh of a design as its 3D model meshes it: the half width where the design is planar (the last
        few kept: a pressure slider asks for the same one)."""
        key = f"{unit}:{design}"
        with self._lock:
            mesh = self._meshes.get(key)
        if mesh is None:
            mesh = self.model("3d", unit).mesh(design)
            with self._lock:
                self._meshes[key] = mesh
                while len(self._meshes) > 16:
                    self._meshes.popitem(last=False)
        return mesh

    def fe_shape_file(self, design: str, unit: str = BUILTIN) -> Path | None:
        """The kept 3D FE surface of a design (every level), if one was solved."""
        if self.shape_dir is None:
            return None
        path = self.shape_dir / f"{self.model('3d', unit).fingerprint()}-{design}.json"
        return path if path.is_file() else None

    def add_fe_shape(self, design: str, shape: dict[str, Any], unit: str = BUILTIN) -> Path:
        """Keep a design's 3D FE surface (from :func:`pneumorph.bench.jobs.fe_solve_shape`)."""
        if self.shape_dir is None:
            raise RuntimeError("the bench keeps no shapes (no shape_dir)")
        self.shape_dir.mkdir(parents=True, exist_ok=True)
        path = self.shape_dir / f"{self.model('3d', unit).fingerprint()}-{design}.json"
        atomic_write_text(path, json.dumps(shape))
        return path


def _statement(model: str, bound: float, unit: str, candidates: int, every: int, certain: bool, floor: float) -> str:
    """What the chain proves about the winner, in words: certain, or how far an unlisted design could go."""
    within = f"Within the chain's validated error bound ({bound:.3g} {unit}), the {model.upper()} model's optimum is "
    if certain:
        return (f"{within}{'this design' if candidates == 1 else f'one of {candidates} designs'} of all {every:,}; "
                "an FE verification certifies it.")
    return (f"Not certified: too many of all {every:,} designs come within the chain's error bound ({bound:.3g} "
            f"{unit}) to list; the search kept the best and bounds the others only by {floor:.4g} {unit}, so an "
            "unlisted design could still beat this one. An FE verification checks the listed ones.")


def _design(chain: ChainModel, design: str) -> str:
    """A design's canonical text over the chain's units (0/1, or letters of a library).

    Raises
    ------
    QueryError
        Field ``design``: a design of the wrong length or with characters that are no units.
    """
    try:
        return chain.table.texts(chain.table.designs(design, chain.n_units))[0]
    except PneumorphError as exc:  # the message names the bad character or length
        raise QueryError("design", str(exc)) from None


def key_id(key: str) -> str:
    """A short stable id of a query key."""
    import hashlib

    return hashlib.sha256(key.encode()).hexdigest()[:16]


__all__ = ["Bench", "profiles"]

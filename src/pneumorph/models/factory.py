"""Build a model from plain settings (a design config's ``[model]`` table, CLI options)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from pneumorph import checks
from pneumorph.errors import GeometryError, SearchConfigError, SettingsError
from pneumorph.fem import StepSettings
from pneumorph.fem.body import quadrature_scheme
from pneumorph.geometry.features import BaseBlock
from pneumorph.geometry.library import BUILTIN_LIBRARIES, UnitLibrary, builtin_library
from pneumorph.geometry.meshsize import available_memory, check_mesh
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.fe import FEModel, Full3D, RampSpec, Reduced2D
from pneumorph.models.fe.base import CELL_TYPES
from pneumorph.models.fe.gravity import gravity_vector
from pneumorph.models.fe.obstacles import check_obstacles
from pneumorph.models.fe.ramp import MAX_VOLUME_CHANGE, MIN_VOLUME_CHANGE, check_volume_steps
from pneumorph.models.fe.volumetric import FORMULATIONS

MODEL_KEYS = ("fidelity", "pressure_kpa", "increments", "substeps", "unit", "unit_file", "gravity",
              "temperature_change", "passage", "base_block", "library", "body_bulk_scale", "body_shear_scale",
              "formulation", "volume_change", "obstacle", "quadrature")
#: the range of ``body_shear_scale`` (a factor on the body silicone's Ogden moduli), and of the identified scales
SCALE_RANGE = (0.1, 10.0)
#: the range of ``body_bulk_scale``: up to a nearly incompressible body (x1000 gives Mold Star 15 a Poisson's ratio of
#: 0.4994; the u-p-J form integrates it without locking, :mod:`pneumorph.fem.fast.mixed`)
BULK_SCALE_RANGE = (0.1, 1000.0)
#: the range of each body scale
SCALE_RANGES = {"body_bulk_scale": BULK_SCALE_RANGE, "body_shear_scale": SCALE_RANGE}


def load_unit_library(value: Any, where: str = "[model] library",
                 error: type[SettingsError] = SearchConfigError) -> UnitLibrary:
    """A unit library named by a setting: a built-in one (``"builtin"``, ``"spatial"``, ``"modes"``) or a library file.

    Raises
    ------
    SearchConfigError (or ``error``)
        Not a text, or the file is unreadable or no valid library (duplicate symbols, units
        that cannot be joined, ...): one line naming ``where`` and the file's problem.

    Examples
    --------
    >>> load_unit_library("builtin").symbols, load_unit_library("spatial").symbols
    (('a', 'e', 'r', 's'), ('a', 'l'))
    >>> load_unit_library("no-such-library.toml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: [model] library: ...no-such-library.toml...
    """
    name = checks.text(value, where, error=error)
    if name in BUILTIN_LIBRARIES:
        return builtin_library(name)
    try:
        return UnitLibrary.from_toml(Path(name))
    except GeometryError as exc:
        raise error(f"{where}: {exc}") from None


def read_model_file(path: str | Path) -> dict[str, Any]:
    """The ``[model]`` table of a TOML file (an identified model, ``pneumorph identify``; a design config).

    Other tables (``[provenance]``, a config's ``[design]``) are left aside; the settings are
    checked when the model is built (:func:`make_model`).

    Raises
    ------
    SearchConfigError
        Unreadable, not TOML, or without a ``[model]`` table: one line naming the file.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "identified.toml"
    >>> _ = p.write_text("[model]\\nbody_bulk_scale = 1.06\\n[model.unit]\\nwall = 1.58\\n"
    ...                  "[provenance]\\npneumorph = 'x'\\n")
    >>> read_model_file(p)
    {'body_bulk_scale': 1.06, 'unit': {'wall': 1.58}}
    """
    from pneumorph.io.files import read_toml

    data = read_toml(path, "model file", SearchConfigError)
    table = data.get("model")
    if not isinstance(table, dict):
        raise SearchConfigError(f"model file {path}: no [model] table (an identified model from pneumorph identify, "
                                "or a design config with one)")
    if "fidelity" in table:  # checked whatever the command line says: a bad value is refused, not overridden
        checks.text(table["fidelity"], f"model file {path}: [model] fidelity", ("2d", "3d"), error=SearchConfigError)
    return dict(table)


def make_model(units: int, settings: Mapping[str, Any] | None = None) -> FEModel:
    """A 2D or 3D FE model of ``units`` units from plain settings.

    Parameters
    ----------
    units : int
        Number of articulating units.
    settings : mapping, optional
        ``fidelity`` ("2d" default, or "3d"; this factory serves every command and has no
        search to choose by: a design run's default, 3D for the certified search as on the
        command line, is :attr:`pneumorph.design.DesignConfig.fidelity`, built by
        :meth:`~pneumorph.design.DesignConfig.make_model`), ``pressure_kpa`` (45), ``increments`` (10),
        ``substeps`` (the model class's default: 1), ``gravity`` (none; ``"hanging"``, ``"horizontal"`` or a vector in
        mm/s^2, :func:`pneumorph.models.fe.gravity.gravity_vector`), and the unit: ``unit`` (a
        table of UnitSpec parameters) or ``unit_file`` (a TOML file with a ``[unit]`` table);
        the features of appendix D: ``temperature_change`` (degC, 3D), ``passage`` (the
        diameter of the holes between cavities, mm, 3D) and ``base_block`` (a table of
        :class:`~pneumorph.geometry.features.BaseBlock` parameters: ``length``, ``margin``,
        ``material``); or, instead of the unit, ``library``: ``"builtin"`` or the path of a
        unit library TOML file (:func:`load_unit_library`): designs over its symbols, the
        model's fingerprint then holding the library (unless it has one type only); the
        body silicone's moduli scaled, as an identified model has them
        (``pneumorph identify``, docs/identify.md): ``body_bulk_scale`` (its bulk modulus,
        :func:`~pneumorph.materials.library.scaling.scaled_bulk_modulus`) and
        ``body_shear_scale`` (its Ogden moduli,
        :func:`~pneumorph.materials.library.scaling.scaled_shear_modulus`), each in its
        :data:`SCALE_RANGES` (default 1: the library's silicone, the same fingerprint);
        ``formulation``: how the silicones' volumetric term is integrated (``"auto"``, the default:
        the u-p-J form for a nearly incompressible silicone; ``"displacement"``; ``"u-p-J"``;
        :meth:`~pneumorph.models.fe.base.FEModel.element_volume`); ``volume_change`` (RampSpec's ``volume``);
        ``quadrature``: the cells' rule (``"full"``, default; ``"reduced"``; ``"irons"``, 3D: ``quadrature_scheme``);
        ``obstacle``: a list of rigid obstacles (``[[model.obstacle]]`` tables,
        :func:`pneumorph.models.fe.obstacles.check_obstacles`).

    Examples
    --------
    >>> m = make_model(4, {"pressure_kpa": 30, "unit": {"slit_width": 1.0, "slit_depth": 5.0}})
    >>> m.fidelity, m.n_units, round(m.ramp.pressure, 6), m.unit.slit_width
    ('2d', 4, 0.03, 1.0)
    >>> make_model(4, {"library": "builtin"}).library.symbols
    ('a', 'e', 'r', 's')
    >>> m = make_model(4, {"body_bulk_scale": 1.06})
    >>> round(m.body.bulk_modulus.value / make_model(4).body.bulk_modulus.value, 12)
    1.06
    >>> make_model(4, {"body_shear_scale": 0})
    Traceback (most recent call last):
    ...
    pneumorph.errors.SearchConfigError: [model] body_shear_scale must be a finite number >= 0.1 and <= 10, got 0
    """
    checks.integer(units, "units", 1, checks.MAX_UNITS, limit="MAX_UNITS", error=SearchConfigError)
    s = dict(settings or {})
    unknown = sorted(set(s) - set(MODEL_KEYS))
    if unknown:
        raise SearchConfigError(f"unknown model setting(s) {', '.join(unknown)}; known: {', '.join(MODEL_KEYS)}")
    unit, library = unit_or_library(s)
    fidelity = checks.text(s.get("fidelity", "2d"), "[model] fidelity", ("2d", "3d"), error=SearchConfigError)
    Model: type[Reduced2D | Full3D] = Reduced2D if fidelity == "2d" else Full3D
    free = available_memory()
    block = _base_block(s.get("base_block"))  # its mesh counts too
    for spec in ([unit] if unit is not None else list(library.units) if library is not None else []):
        check_mesh(spec, units, Model.dim, memory=free, base=block)  # before any mesh: the estimate in the message
        _check_quadrature(s.get("quadrature", "full"), Model.dim, spec)
    ramp = _ramp(s, Model.default_steps)
    try:
        gravity = gravity_vector(s.get("gravity"), Model.dim)
    except (ValueError, TypeError) as exc:
        raise SearchConfigError(f"[model] gravity: {exc}") from None
    change = checks.real(s.get("temperature_change", 0.0), "[model] temperature_change", -100.0, 100.0, unit="degC",
                         error=SearchConfigError)
    passage = checks.real(s.get("passage", 0.0), "[model] passage", 0.0, 100.0, unit="mm", error=SearchConfigError)
    extra = {**_model_options(s, unit, library, block), **_obstacles(s.get("obstacle"), Model.dim)}
    if change != 0.0 or passage != 0.0:
        if Model is not Full3D:
            what = "temperature_change" if change != 0.0 else "passage"
            raise SearchConfigError(f"[model] {what} is a 3D model option (fidelity = \"3d\")")
        try:
            return Full3D(units, unit, ramp, gravity=gravity, temperature_change=change, passage=passage, **extra)
        except GeometryError as exc:
            raise SearchConfigError(f"[model] passage: {exc}") from None
    return Model(units, unit, ramp, gravity=gravity, **extra)


def _model_options(s: Mapping[str, Any], unit: UnitSpec | None, library: UnitLibrary | None,
                   block: BaseBlock | None) -> dict[str, Any]:
    """The model class's keyword arguments the settings give beyond the ramp and the loads: the base block, the
    volumetric formulation, the unit library and the scaled body silicone."""
    extra: dict[str, Any] = {"base_block": block} if block is not None else {}
    if "formulation" in s:
        extra["formulation"] = checks.text(s["formulation"], "[model] formulation", FORMULATIONS,
                                           error=SearchConfigError)
    if "quadrature" in s:
        extra["quadrature"] = s["quadrature"]  # checked against the model's cells by make_model
    if library is not None:
        extra["library"] = library
    body = _scaled_body(s, unit if unit is not None else library.units[0] if library is not None else UnitSpec())
    if body is not None:
        extra["materials"] = {body.name: body}
    return extra


def _check_quadrature(rule: Any, dim: int, spec: UnitSpec) -> None:
    """Refuse a ``[model] quadrature`` that is no rule of the cells of ``spec`` in ``dim`` dimensions."""
    try:
        quadrature_scheme(CELL_TYPES[dim, spec.element_order], rule)
    except SettingsError as exc:
        raise SearchConfigError(f"[model] {exc}") from None


def unit_or_library(s: Mapping[str, Any]) -> tuple[UnitSpec | None, UnitLibrary | None]:
    """The unit (``unit``, ``unit_file`` or the default) or the unit library (``library``) of the settings.

    Raises
    ------
    SearchConfigError
        Both a unit and a library, or a unit both inline and as a file; a unit or a library
        that cannot be read.
    """
    if "unit" in s and "unit_file" in s:
        raise SearchConfigError("give the unit either inline ([model.unit]) or as unit_file, not both")
    if "library" in s:
        if "unit" in s or "unit_file" in s:
            raise SearchConfigError("give either a unit ([model.unit] or unit_file) or a unit library ([model] "
                                    "library), not both: the library names its units")
        return None, load_unit_library(s["library"])  # the model's unit: the library's first type
    if "unit_file" in s:
        try:
            return UnitSpec.from_toml(Path(checks.text(s["unit_file"], "[model] unit_file",
                                                       error=SearchConfigError))), None
        except GeometryError as exc:
            raise SearchConfigError(f"[model] unit_file: {exc}") from None
    if not isinstance(s.get("unit", {}), Mapping):
        raise SearchConfigError(f"[model.unit] must be a table of unit parameters, got {s['unit']!r}")
    return UnitSpec.from_dict(dict(s.get("unit", {})), source="[model.unit]"), None


def _ramp(s: Mapping[str, Any], defaults: StepSettings) -> RampSpec:
    """The ramp of ``pressure_kpa``, ``increments`` and ``substeps``, else the model class's tuned ``defaults``.

    The class's tuned ramp (one substep per level, its iteration limit) unless asked
    otherwise, so that API and CLI runs of the same design share their cache entries.

    Raises
    ------
    SearchConfigError
        A setting out of its range.
    """
    pressure = checks.real(s.get("pressure_kpa", 45.0), "[model] pressure_kpa", 0.0, checks.MAX_PRESSURE_KPA,
                           low_open=True, unit="kPa", limit="MAX_PRESSURE_KPA", error=SearchConfigError)
    increments = checks.integer(s.get("increments", defaults.increments), "[model] increments", 1,
                                checks.MAX_INCREMENTS, limit="MAX_INCREMENTS", error=SearchConfigError)
    substeps = checks.integer(s.get("substeps", defaults.substeps), "[model] substeps", 1, checks.MAX_SUBSTEPS,
                              limit="MAX_SUBSTEPS", error=SearchConfigError)
    volume = s.get("volume_change")
    if volume is not None:
        volume = checks.real(volume, "[model] volume_change", MIN_VOLUME_CHANGE, MAX_VOLUME_CHANGE,
                             error=SearchConfigError)
        check_volume_steps(volume, increments, ("[model] volume_change", "[model] increments"), SearchConfigError)
    return RampSpec(pressure=pressure / 1e3, steps=replace(defaults, increments=increments, substeps=substeps),
                    volume=volume)


def _obstacles(tables: Any, dim: int) -> dict[str, Any]:
    """``{"obstacles": ...}`` of the ``[[model.obstacle]]`` tables, or nothing (none given).

    Raises
    ------
    SearchConfigError
        A table that is no valid obstacle.
    """
    if tables is None:
        return {}
    try:
        return {"obstacles": check_obstacles(tables, dim)}
    except SettingsError as exc:
        raise SearchConfigError(str(exc)) from None


def _base_block(block: Any) -> BaseBlock | None:
    """The ``[model.base_block]`` table as a :class:`BaseBlock` (None: no block).

    Raises
    ------
    SearchConfigError
        Not a table, an unknown key, or a block that is no valid :class:`BaseBlock`.
    """
    if block is None:
        return None
    if not isinstance(block, Mapping):
        raise SearchConfigError(f"[model.base_block] must be a table (length, margin, material), got {block!r}")
    unknown = sorted(set(block) - {"length", "margin", "material"})
    if unknown:
        raise SearchConfigError(f"unknown base block setting(s) {', '.join(unknown)}; known: length, margin, "
                                "material")
    try:
        return BaseBlock(**block)
    except GeometryError as exc:
        raise SearchConfigError(f"[model.base_block] {exc}") from None


def _scaled_body(settings: Mapping[str, Any], unit: UnitSpec) -> Any:
    """The body silicone of ``unit`` with ``body_bulk_scale`` and ``body_shear_scale`` applied, or None (both 1)."""
    scales = [checks.real(settings.get(key, 1.0), f"[model] {key}", *SCALE_RANGES[key], error=SearchConfigError)
              for key in ("body_bulk_scale", "body_shear_scale")]
    if scales == [1.0, 1.0]:
        return None  # the library's material: every earlier fingerprint stays valid
    from pneumorph.materials import get
    from pneumorph.materials.library.scaling import scaled_bulk_modulus, scaled_shear_modulus

    body = get(unit.body_material)
    if scales[0] != 1.0:
        body = scaled_bulk_modulus(body, scales[0])
    if scales[1] != 1.0:
        body = scaled_shear_modulus(body, scales[1])
    return body

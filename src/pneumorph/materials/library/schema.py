"""Parsing and validation of material TOML files (the schema of ``data/materials.toml``)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from pneumorph.errors import MaterialDataError
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.materials.laws.hyperelastic import (
    HyperelasticModel,
    MooneyRivlin,
    NeoHooke,
    Ogden,
    Yeoh,
)
from pneumorph.materials.library.material import (
    KINDS,
    POSITIVE_PROPERTIES,
    PROPERTIES,
    FitRecord,
    Library,
    Material,
    ModelRecord,
    Quantity,
    normalise,
)
from pneumorph.materials.library.units import INTERNAL_UNITS, UNITS, to_internal

_MODEL_PARAMETERS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    # type: (required, optional)
    "ogden": (("mu", "alpha"), ()),
    "neo-hooke": (("c10",), ()),
    "mooney-rivlin": (("c10", "c01"), ("c11",)),
    "yeoh": (("c",), ()),
}
_ENTRY_KEYS = {"display_name", "kind", "source", "aliases", "description", "model", "r_squared", "fit", "matrix"}
#: what an entry with ``matrix = "<key>"`` takes from that entry: its kind, law, density and bulk modulus
_INHERITED = ("kind", "model", "density", "bulk_modulus")
_FIT_KEYS = {"data", "attribution", "mode", "stretch_range", "points", "method", "caveats"}
_ENTRY_KEYS |= set(PROPERTIES)


class _Where:
    """Formats error messages that name the file and the entry."""

    def __init__(self, path: str, entry: str) -> None:
        self.path, self.entry = path, entry

    def error(self, message: str) -> MaterialDataError:
        return MaterialDataError(f"{self.path}: [{self.entry}]: {message}")

    def table(self, data: dict[str, Any], key: str, required: bool = True) -> dict[str, Any] | None:
        if key not in data:
            if required:
                raise self.error(f"missing table '{key}'")
            return None
        value = data[key]
        if not isinstance(value, dict):
            raise self.error(f"'{key}' must be a table, got {type(value).__name__}")
        return value

    def text(self, data: dict[str, Any], key: str, required: bool = True) -> str | None:
        if key not in data:
            if required:
                raise self.error(f"missing key '{key}'")
            return None
        value = data[key]
        if not isinstance(value, str) or not value.strip():
            raise self.error(f"'{key}' must be a non-empty string, got {value!r}")
        return value

    def number(self, data: dict[str, Any], key: str) -> float:
        if key not in data:
            raise self.error(f"missing key '{key}'")
        return self.check_number(data[key], key)

    def check_number(self, value: Any, what: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise self.error(f"'{what}' must be a finite number, got {value!r}")
        return value

    def numbers(self, data: dict[str, Any], key: str) -> tuple[float, ...]:
        if key not in data:
            raise self.error(f"missing key '{key}'")
        value = data[key]
        if not isinstance(value, list) or not value:
            raise self.error(f"'{key}' must be a non-empty list of numbers, got {value!r}")
        return tuple(self.check_number(v, f"{key}[{i}]") for i, v in enumerate(value))

    def unit(self, data: dict[str, Any], key: str, dimension: str) -> str:
        unit = self.text(data, key)
        assert unit is not None
        if unit not in UNITS[dimension]:
            raise self.error(
                f"unit {unit!r} of '{key}' is not a {dimension.replace('_', ' ')} unit; "
                f"expected one of {', '.join(UNITS[dimension])}"
            )
        return unit

    def no_extra(self, data: dict[str, Any], allowed: set[str]) -> None:
        extra = sorted(set(data) - allowed)
        if extra:
            raise self.error(f"unknown key(s) {', '.join(extra)}; allowed: {', '.join(sorted(allowed))}")


def _quantity(where: _Where, name: str, data: dict[str, Any]) -> Quantity:
    dimension = PROPERTIES[name]
    w = _Where(where.path, f"{where.entry}.{name}")
    w.no_extra(data, {"value", "unit", "source", "assumed", "reason"})
    printed = w.number(data, "value")
    unit = w.unit(data, "unit", dimension)
    source = w.text(data, "source")
    assumed = data.get("assumed", False)
    if not isinstance(assumed, bool):
        raise w.error(f"'assumed' must be true or false, got {assumed!r}")
    reason = w.text(data, "reason", required=assumed)
    value = to_internal(printed, unit, dimension)
    if name in POSITIVE_PROPERTIES and value <= 0.0:
        raise w.error(f"{name.replace('_', ' ')} must be positive, got {printed} {unit}")
    if name == "poisson_ratio" and not -1.0 < value < 0.5:
        raise w.error(f"Poisson's ratio must lie in (-1, 0.5), got {printed}")
    assert source is not None
    return Quantity(name, value, INTERNAL_UNITS[dimension], printed, unit, source, assumed, reason)


def _model(where: _Where, data: dict[str, Any]) -> tuple[HyperelasticModel, ModelRecord]:
    w = _Where(where.path, f"{where.entry}.model")
    kind = w.text(data, "type")
    if kind not in _MODEL_PARAMETERS:
        raise w.error(f"unknown model type {kind!r}; expected one of {', '.join(_MODEL_PARAMETERS)}")
    required, optional = _MODEL_PARAMETERS[kind]
    w.no_extra(data, {"type", "convention", "unit", "source", *required, *optional})
    unit = w.unit(data, "unit", "stress")
    source = w.text(data, "source")
    convention = "marc" if kind != "ogden" else w.text(data, "convention")
    if convention != "marc":
        raise w.error(
            f"Ogden convention {convention!r} is not supported; write the parameters in the "
            "'marc' convention W = sum mu_n/alpha_n (l1^a + l2^a + l3^a - 3)"
        )
    printed: dict[str, float | tuple[float, ...]] = {}
    for key in (*required, *(k for k in optional if k in data)):
        printed[key] = w.numbers(data, key) if key in ("mu", "alpha", "c") else w.number(data, key)

    def stress(x: float) -> float:
        return to_internal(x, unit, "stress")

    model: HyperelasticModel
    if kind == "ogden":
        mu, alpha = printed["mu"], printed["alpha"]
        assert isinstance(mu, tuple) and isinstance(alpha, tuple)
        if len(mu) != len(alpha):
            raise w.error(f"'mu' has {len(mu)} terms but 'alpha' has {len(alpha)}; they must match")
        if any(a == 0 for a in alpha):
            raise w.error(f"Ogden exponents alpha must be non-zero, got {list(alpha)}")
        model = Ogden(mu=tuple(stress(m) for m in mu), alpha=alpha)
    elif kind == "neo-hooke":
        model = NeoHooke(c10=stress(printed["c10"]))  # type: ignore[arg-type]
    elif kind == "mooney-rivlin":
        c11 = printed.get("c11", 0.0)
        model = MooneyRivlin(stress(printed["c10"]), stress(printed["c01"]), stress(c11))  # type: ignore[arg-type]
    else:
        model = Yeoh(c=tuple(stress(c) for c in printed["c"]))  # type: ignore[union-attr]
    if not model.shear_modulus > 0.0:
        raise w.error(
            f"the initial shear modulus of the {kind} model must be positive, "
            f"got {model.shear_modulus:.6g} MPa"
        )
    assert source is not None and convention is not None
    return model, ModelRecord(kind, convention, unit, tuple(printed.items()), source)


def _fit_record(where: _Where, data: dict[str, Any]) -> FitRecord:
    """The ``[materials.<key>.fit]`` table: the test data a model was fitted to, and how."""
    w = _Where(where.path, f"{where.entry}.fit")
    w.no_extra(data, _FIT_KEYS)
    texts = {k: w.text(data, k) for k in ("data", "attribution", "mode", "method")}
    rng = w.numbers(data, "stretch_range")
    if len(rng) != 2:
        raise w.error(f"'stretch_range' must be [lower, upper], got {list(rng)}")
    points = data.get("points")
    caveats = data.get("caveats", [])
    if not isinstance(caveats, list) or not all(isinstance(c, str) and c.strip() for c in caveats):
        raise w.error(f"'caveats' must be a list of texts, got {caveats!r}")
    try:
        return FitRecord(stretch_range=(rng[0], rng[1]), points=points, caveats=tuple(caveats),  # type: ignore[arg-type]
                         **texts)  # type: ignore[arg-type]
    except MaterialDataError as exc:
        raise w.error(str(exc)) from None


def _with_matrix(path: str, key: str, data: Any, entries: dict[str, Any]) -> Any:
    """``data`` with its matrix's kind, law, density and bulk modulus under its own keys.

    An entry's own table with a number (``value``, or a model's ``type``) replaces the matrix's; one
    without (``source``, ``assumed``, ``reason``) keeps the matrix's number and says where it comes
    from. The matrix is an entry of the same file with a law of its own (no matrix of its own).
    """
    if not isinstance(data, dict) or "matrix" not in data:
        return data
    where = _Where(path, f"materials.{key}")
    name = where.text(data, "matrix")
    assert name is not None  # required: text() raised otherwise
    matrix = entries.get(name)
    if name == key:
        raise where.error(f"matrix {name!r} is the entry itself; a matrix is another entry of the file")
    if not isinstance(matrix, dict):
        raise where.error(f"matrix {name!r} is not an entry of {path}; known: {', '.join(entries)}")
    if "matrix" in matrix:
        raise where.error(f"matrix {name!r} has a matrix of its own ({matrix['matrix']!r}); "
                          "a matrix is an entry with its own law")
    if matrix.get("kind") != "hyperelastic":
        raise where.error(f"matrix {name!r} is not a hyperelastic entry; a matrix gives its law (model)")
    out = {k: v for k, v in data.items() if k != "matrix"}
    for part in _INHERITED:
        own, theirs = data.get(part), matrix.get(part)
        if theirs is None:
            continue
        if own is None:
            out[part] = theirs
        elif isinstance(own, dict) and isinstance(theirs, dict) and not own.keys() & {"value", "type"}:
            out[part] = theirs | own
    return out


def _material(path: str, key: str, data: Any) -> Material:
    where = _Where(path, f"materials.{key}")
    if not isinstance(data, dict):
        raise where.error("must be a table")
    if normalise(key) != key:
        raise where.error(f"key must be lower case letters, digits and '_' (e.g. {normalise(key)!r})")
    where.no_extra(data, _ENTRY_KEYS)
    display_name = where.text(data, "display_name")
    kind = where.text(data, "kind")
    if kind not in KINDS:
        raise where.error(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")
    source = where.text(data, "source")
    aliases = data.get("aliases", [])
    if not isinstance(aliases, list) or not all(isinstance(a, str) and a.strip() for a in aliases):
        raise where.error(f"'aliases' must be a list of names, got {aliases!r}")
    description = where.text(data, "description", required=False) or ""
    props: dict[str, Quantity] = {}
    for name in PROPERTIES:
        table = where.table(data, name, required=False)
        if table is not None:
            props[name] = _quantity(where, name, table)
    model = record = fitting = None
    if kind == "hyperelastic":
        for name in ("youngs_modulus", "poisson_ratio"):
            if name in props:
                raise where.error(f"'{name}' belongs to linear-elastic materials; a hyperelastic one uses 'model'")
        table = where.table(data, "model")
        assert table is not None
        model, record = _model(where, table)
        fit_table = where.table(data, "fit", required=False)
        fitting = _fit_record(where, fit_table) if fit_table is not None else None
    else:
        if "model" in data or "fit" in data:
            raise where.error("a linear-elastic material takes youngs_modulus and poisson_ratio, not 'model' or 'fit'")
        for name in ("youngs_modulus", "poisson_ratio"):
            if name not in props:
                raise where.error(f"missing table '{name}' (required for a linear-elastic material)")
    r2: tuple[tuple[str, float], ...] = ()
    r2_source = None
    r2_table = where.table(data, "r_squared", required=False)
    if r2_table is not None:
        w = _Where(path, f"materials.{key}.r_squared")
        r2_source = w.text(r2_table, "source")
        values = []
        for model_name, value in r2_table.items():
            if model_name == "source":
                continue
            r = w.check_number(value, model_name)
            if not r <= 1.0:
                raise w.error(f"R^2 cannot exceed 1, got {model_name} = {r}")
            values.append((model_name, r))
        r2 = tuple(values)
    assert display_name is not None and source is not None
    return Material(
        name=key,
        display_name=display_name,
        kind=kind,  # type: ignore[arg-type]
        source=source,
        model=model,
        model_record=record,
        r_squared=r2,
        r_squared_source=r2_source,
        fitting=fitting,
        aliases=tuple(aliases),
        description=description,
        origin=path,
        **props,
    )


def _filler(path: str, key: str, data: Any) -> FillerLaw:
    where = _Where(path, f"fillers.{key}")
    if not isinstance(data, dict):
        raise where.error("must be a table")
    if normalise(key) != key:
        raise where.error(f"key must be lower case letters, digits and '_' (e.g. {normalise(key)!r})")
    allowed = {"display_name", "source", "coefficients", "modulus_unit", "pressure_unit",
               "calibrated_range", "range_unit", "range_source", "poisson_ratio"}
    where.no_extra(data, allowed)
    display_name = where.text(data, "display_name")
    source = where.text(data, "source")
    printed = where.numbers(data, "coefficients")
    e_unit = where.unit(data, "modulus_unit", "stress")
    p_unit = where.unit(data, "pressure_unit", "stress")
    rng = where.numbers(data, "calibrated_range")
    if len(rng) != 2:
        raise where.error(f"'calibrated_range' must be [lower, upper], got {list(rng)}")
    r_unit = where.unit(data, "range_unit", "stress")
    range_source = where.text(data, "range_source", required=False)
    table = where.table(data, "poisson_ratio")
    assert table is not None
    nu = _quantity(where, "poisson_ratio", table)
    # E[modulus_unit] = sum c_k (P[pressure_unit])^k  ->  E[MPa] = sum c_k f_E / f_P^k P[MPa]^k
    f_e, f_p = to_internal(1.0, e_unit, "stress"), to_internal(1.0, p_unit, "stress")
    coefficients = tuple(c * f_e / f_p**k for k, c in enumerate(printed))
    lower, upper = (to_internal(x, r_unit, "stress") for x in rng)
    try:
        return FillerLaw(
            name=key,
            display_name=display_name or key,
            coefficients=coefficients,
            pressure_range=(lower, upper),
            poisson_ratio=nu.value,
            source=source or "",
            range_source=range_source,
            poisson_ratio_source=nu.source,
            poisson_ratio_assumed=nu.assumed,
            poisson_ratio_reason=nu.reason,
            printed=(printed, e_unit, p_unit),
        )
    except MaterialDataError as exc:
        raise where.error(str(exc)) from None


def parse_library(data: dict[str, Any], path: str) -> Library:
    """Validate parsed TOML data and build a :class:`Library` (``path`` names it in errors)."""
    where = _Where(path, "top level")
    where.no_extra(data, {"schema_version", "materials", "fillers"})
    version = data.get("schema_version", 1)
    if version != 1:
        raise where.error(f"schema_version {version!r} is not supported; expected 1")
    materials = where.table(data, "materials", required=False) or {}
    fillers = where.table(data, "fillers", required=False) or {}
    if not materials and not fillers:
        raise where.error("no [materials.<name>] or [fillers.<name>] tables found")
    return Library(
        path=path,
        materials=tuple(_material(path, k, _with_matrix(path, k, v, materials)) for k, v in materials.items()),
        fillers=tuple(_filler(path, k, v) for k, v in fillers.items()),
    )


def load_library(path: str | Path) -> Library:
    """Read and validate a material TOML file (the schema of ``data/materials.toml``).

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    Library

    Raises
    ------
    MaterialDataError
        Unreadable file, TOML syntax error, missing keys, wrong lengths, unknown units,
        non-positive moduli; the message names the file and the entry.
    """
    from pneumorph.io.files import read_toml

    p = Path(path)
    return parse_library(read_toml(p, "material file", MaterialDataError), str(p))


"""The material library: the dissertation's silicones, composites, paper and filler law.

The data live in ``data/materials.toml`` (shipped with the package) with every number as
printed in its source and its unit, convention and source named; users add materials from
their own TOML files with the same schema (:func:`register_toml`, :func:`load_library`).
This module turns them into immutable :class:`Material` objects in the internal units
(MPa, tonne/mm^3, 1/K, mm) - the conversion happens in one place, :func:`to_internal`.

Examples
--------
>>> from pneumorph.materials import library
>>> ms15 = library.get("Mold Star 15")
>>> ms15.name, round(ms15.shear_modulus, 4), ms15.bulk_modulus.value
('mold_star_15', 0.1314, 0.119)
>>> ms15.density.value, ms15.density.printed, ms15.density.printed_unit
(1.139e-09, 1139, 'kg/m^3')
>>> library.get("ecoflex-0030").assumed
('bulk_modulus',)
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Literal

from pneumorph.errors import MaterialDataError, UnknownMaterialError
from pneumorph.materials.filler import FillerLaw
from pneumorph.materials.hyperelastic import (
    HyperelasticModel,
    MooneyRivlin,
    NeoHooke,
    Ogden,
    Yeoh,
    ogden_marc_to_felupe,
)

Kind = Literal["hyperelastic", "linear-elastic"]
KINDS: tuple[str, ...] = ("hyperelastic", "linear-elastic")

#: Accepted units per dimension and their exact factor (numerator, denominator) to the
#: internal unit (the first of each dimension). Factors are kept as integer ratios so that
#: 119 kPa becomes exactly the float 0.119 MPa (119 / 1000, not 119 * 0.001).
UNITS: dict[str, dict[str, tuple[int, int]]] = {
    "stress": {"MPa": (1, 1), "N/mm^2": (1, 1), "kPa": (1, 10**3), "Pa": (1, 10**6), "GPa": (10**3, 1)},
    "density": {"tonne/mm^3": (1, 1), "kg/m^3": (1, 10**12), "g/cm^3": (1, 10**9)},
    "thermal_expansion": {
        "1/K": (1, 1),
        "1/degC": (1, 1),
        "micro-mm/mm/degC": (1, 10**6),
        "micro-strain/K": (1, 10**6),
    },
    "length": {"mm": (1, 1), "m": (10**3, 1), "um": (1, 10**3)},
    "dimensionless": {"-": (1, 1)},
}
INTERNAL_UNITS: dict[str, str] = {dim: next(iter(units)) for dim, units in UNITS.items()}

#: Scalar properties a material may carry, with their dimension.
PROPERTIES: dict[str, str] = {
    "density": "density",
    "bulk_modulus": "stress",
    "thermal_expansion": "thermal_expansion",
    "youngs_modulus": "stress",
    "poisson_ratio": "dimensionless",
    "thickness": "length",
}
_POSITIVE = {"density", "bulk_modulus", "youngs_modulus", "thickness"}
_MODEL_PARAMETERS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    # type: (required, optional)
    "ogden": (("mu", "alpha"), ()),
    "neo-hooke": (("c10",), ()),
    "mooney-rivlin": (("c10", "c01"), ("c11",)),
    "yeoh": (("c",), ()),
}
_ENTRY_KEYS = {"display_name", "kind", "source", "aliases", "description", "model", "r_squared"}
_ENTRY_KEYS |= set(PROPERTIES)
_BUILTIN = "pneumorph built-in library (materials/data/materials.toml)"


def normalise(name: str) -> str:
    """Canonical form of a material name: lower case, runs of other characters -> ``_``.

    Examples
    --------
    >>> normalise("Mold Star 15"), normalise("mold-star-15"), normalise(" Smooth-Sil 950 ")
    ('mold_star_15', 'mold_star_15', 'smooth_sil_950')
    """
    return re.sub(r"[^a-z0-9]+", "_", name.strip().lower()).strip("_")


def to_internal(value: float, unit: str, dimension: str) -> float:
    """Convert a printed value to pneumorph's internal unit of its dimension.

    This is the only place where library units are converted.

    Parameters
    ----------
    value : float
        The number as printed.
    unit : str
        Its unit, one of ``UNITS[dimension]``.
    dimension : str
        ``"stress"``, ``"density"``, ``"thermal_expansion"``, ``"length"`` or
        ``"dimensionless"``.

    Returns
    -------
    float
        The value in ``INTERNAL_UNITS[dimension]``.

    Raises
    ------
    KeyError
        If the unit is not known for the dimension.

    Examples
    --------
    >>> to_internal(119, "kPa", "stress"), to_internal(245.3, "micro-mm/mm/degC", "thermal_expansion")
    (0.119, 0.0002453)
    """
    numerator, denominator = UNITS[dimension][unit]
    return float(value) * numerator / denominator


@dataclass(frozen=True)
class Quantity:
    """A scalar material property, as printed and in internal units.

    Attributes
    ----------
    name : str
        Property name (``"density"``, ``"bulk_modulus"``, ...).
    value : float
        Value in the internal unit ``unit``.
    unit : str
        Internal unit (MPa, tonne/mm^3, 1/K, mm or ``-``).
    printed, printed_unit : float, str
        The number and unit exactly as the source prints them.
    source : str
        Where the number comes from.
    assumed : bool
        True if the source gives no value and this one was chosen.
    reason : str or None
        Why and how an assumed value was chosen.
    """

    name: str
    value: float
    unit: str
    printed: float
    printed_unit: str
    source: str
    assumed: bool = False
    reason: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (JSON-serialisable)."""
        out: dict[str, Any] = {
            "value": self.value,
            "unit": self.unit,
            "printed": self.printed,
            "printed_unit": self.printed_unit,
            "source": self.source,
            "assumed": self.assumed,
        }
        if self.reason is not None:
            out["reason"] = self.reason
        return out


@dataclass(frozen=True)
class ModelRecord:
    """Provenance of a hyperelastic model: its type, convention and printed parameters."""

    type: str
    convention: str
    unit: str
    parameters: tuple[tuple[str, float | tuple[float, ...]], ...]
    source: str

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (JSON-serialisable)."""
        params = {k: list(v) if isinstance(v, tuple) else v for k, v in self.parameters}
        return {
            "type": self.type,
            "convention": self.convention,
            "unit": self.unit,
            "parameters": params,
            "source": self.source,
        }


@dataclass(frozen=True)
class Material:
    """One library material in internal units (MPa, tonne/mm^3, 1/K, mm).

    Attributes
    ----------
    name : str
        Canonical key (``"mold_star_15"``).
    display_name : str
        Name as the source writes it.
    kind : {"hyperelastic", "linear-elastic"}
    source : str
        Citation of the entry as a whole.
    model : HyperelasticModel or None
        Closed-form incompressible model (Ogden in the Marc convention for the library),
        moduli in MPa; ``None`` for linear-elastic materials.
    model_record : ModelRecord or None
        Its printed parameters, unit, convention and source.
    youngs_modulus, poisson_ratio : Quantity or None
        Linear-elastic constants (linear-elastic materials only).
    density, bulk_modulus, thermal_expansion, thickness : Quantity or None
        Further properties where known.
    r_squared : tuple of (str, float)
        Goodness of fit printed by the source, per model; ``r_squared_source`` names it.
    aliases : tuple of str
        Other accepted names.
    description : str
    origin : str
        The file the entry was read from.

    Examples
    --------
    >>> from pneumorph.materials.library import get
    >>> m = get("smooth_sil_950")
    >>> round(m.shear_modulus, 5), [round(x, 5) for x in m.ogden_felupe_mu]
    (0.53338, [0.46833, 0.06505, 0.0])
    """

    name: str
    display_name: str
    kind: Kind
    source: str
    model: HyperelasticModel | None = None
    model_record: ModelRecord | None = None
    youngs_modulus: Quantity | None = None
    poisson_ratio: Quantity | None = None
    density: Quantity | None = None
    bulk_modulus: Quantity | None = None
    thermal_expansion: Quantity | None = None
    thickness: Quantity | None = None
    r_squared: tuple[tuple[str, float], ...] = ()
    r_squared_source: str | None = None
    aliases: tuple[str, ...] = ()
    description: str = ""
    origin: str = _BUILTIN

    @property
    def quantities(self) -> tuple[Quantity, ...]:
        """All scalar properties present, in schema order."""
        found = (getattr(self, name) for name in PROPERTIES)
        return tuple(q for q in found if q is not None)

    @property
    def assumed(self) -> tuple[str, ...]:
        """Names of the properties whose values are assumed, not taken from the source."""
        return tuple(q.name for q in self.quantities if q.assumed)

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus mu0 in MPa.

        Hyperelastic: the model's small-strain modulus (Ogden, Marc convention:
        ``sum mu_n alpha_n / 2``). Linear elastic: ``E / (2 (1 + nu))``.
        """
        if self.model is not None:
            return float(self.model.shear_modulus)
        assert self.youngs_modulus is not None and self.poisson_ratio is not None
        return self.youngs_modulus.value / (2.0 * (1.0 + self.poisson_ratio.value))

    @property
    def ogden_felupe_mu(self) -> tuple[float, ...]:
        """Ogden moduli in FElupe's convention, ``mu_felupe = mu_marc alpha / 2`` (MPa).

        Their sum is the initial shear modulus (FElupe: ``psi = sum 2 mu/alpha^2 (...)``).
        Empty for materials that are not Ogden.
        """
        if isinstance(self.model, Ogden):
            return ogden_marc_to_felupe(self.model.mu, self.model.alpha)
        return ()

    @property
    def initial_poisson_ratio(self) -> float | None:
        """Small-strain Poisson's ratio ``(3K - 2 mu0) / (2 (3K + mu0))``.

        For hyperelastic materials with a bulk modulus; the given value for linear-elastic
        ones; ``None`` otherwise.
        """
        if self.poisson_ratio is not None:
            return self.poisson_ratio.value
        if self.bulk_modulus is None:
            return None
        k, mu = self.bulk_modulus.value, self.shear_modulus
        return (3.0 * k - 2.0 * mu) / (2.0 * (3.0 * k + mu))

    def umat(self, formulation: str = "compressible") -> Any:
        """FElupe constitutive material for this material.

        Parameters
        ----------
        formulation : {"compressible", "nearly-incompressible"}
            Hyperelastic materials: the compressible displacement form of Eq 2.12 or the
            mixed (u/p/J) nearly-incompressible form. Linear-elastic materials accept
            ``"compressible"`` only.

        Returns
        -------
        felupe constitutive material
            From :func:`pneumorph.materials.felupe_models.build_umat` (hyperelastic, with
            the library bulk modulus) or ``build_linear_elastic`` (linear elastic).

        Raises
        ------
        MaterialDataError
            If a hyperelastic material has no bulk modulus, or the formulation does not
            apply.
        """
        from pneumorph.materials import felupe_models  # lazy: FElupe takes ~0.5 s to import

        if self.kind == "linear-elastic":
            if formulation != "compressible":
                raise MaterialDataError(
                    f"{self.name}: a linear-elastic material has only the 'compressible' "
                    f"formulation, got {formulation!r}"
                )
            assert self.youngs_modulus is not None and self.poisson_ratio is not None
            return felupe_models.build_linear_elastic(
                self.youngs_modulus.value, self.poisson_ratio.value
            )
        if self.bulk_modulus is None:
            raise MaterialDataError(
                f"{self.name}: no bulk modulus in the library entry ({self.origin}); "
                "an FE model needs one - add [materials.<key>.bulk_modulus]"
            )
        return felupe_models.build_umat(
            self.model, self.bulk_modulus.value, formulation=formulation
        )

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form for JSON: printed and internal values, sources, assumptions."""
        out: dict[str, Any] = {
            "name": self.name,
            "display_name": self.display_name,
            "kind": self.kind,
            "description": self.description,
            "aliases": list(self.aliases),
            "source": self.source,
            "origin": self.origin,
        }
        if self.model is not None and self.model_record is not None:
            model = self.model_record.to_dict()
            model["parameters_MPa"] = dict(self.model.parameters)
            if isinstance(self.model, Ogden):
                model["felupe_mu_MPa"] = list(self.ogden_felupe_mu)
            out["model"] = model
        mu0: dict[str, Any] = {"value": self.shear_modulus, "unit": "MPa"}
        if isinstance(self.model, Ogden):
            mu0["marc"] = self.shear_modulus
            mu0["felupe"] = math.fsum(self.ogden_felupe_mu)
            mu0["formula"] = "marc: sum mu_n alpha_n / 2; felupe: sum mu_i"
        out["shear_modulus"] = mu0
        out["initial_poisson_ratio"] = self.initial_poisson_ratio
        out["properties"] = {q.name: q.to_dict() for q in self.quantities}
        if self.r_squared:
            out["r_squared"] = {"source": self.r_squared_source, **dict(self.r_squared)}
        out["assumed"] = list(self.assumed)
        return out


@dataclass(frozen=True)
class Library:
    """The materials and filler laws read from one TOML file.

    Examples
    --------
    >>> from pneumorph.materials.library import builtin
    >>> lib = builtin()
    >>> lib.get("Ecoflex 00-30").name, len(lib.names()) >= 7
    ('ecoflex_0030', True)
    """

    path: str
    materials: tuple[Material, ...]
    fillers: tuple[FillerLaw, ...] = ()
    _index: dict[str, str] = field(default_factory=dict, repr=False, compare=False, hash=False)

    def __post_init__(self) -> None:
        index: dict[str, str] = {}
        for m in self.materials:
            for alias in (m.name, m.display_name, *m.aliases):
                key = normalise(alias)
                if index.get(key, m.name) != m.name:
                    raise MaterialDataError(
                        f"{self.path}: [materials.{m.name}]: name {alias!r} is already used "
                        f"by [materials.{index[key]}]"
                    )
                index[key] = m.name
        self._index.update(index)

    def names(self) -> tuple[str, ...]:
        """Canonical material names, in file order."""
        return tuple(m.name for m in self.materials)

    def filler_names(self) -> tuple[str, ...]:
        """Names of the filler laws, in file order."""
        return tuple(f.name for f in self.fillers)

    def find(self, name: str) -> Material | None:
        """The material called ``name`` (any accepted spelling), or None."""
        key = self._index.get(normalise(name))
        return next((m for m in self.materials if m.name == key), None)

    def get(self, name: str) -> Material:
        """The material called ``name``; :class:`UnknownMaterialError` if absent."""
        found = self.find(name)
        if found is None:
            raise UnknownMaterialError(name, self.names())
        return found

    def filler(self, name: str) -> FillerLaw:
        """The filler law called ``name``; :class:`UnknownMaterialError` if absent."""
        key = normalise(name)
        for f in self.fillers:
            if f.name == key:
                return f
        raise UnknownMaterialError(name, self.filler_names())


# ---------------------------------------------------------------------------------------
# parsing and validation
# ---------------------------------------------------------------------------------------


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
    if name in _POSITIVE and value <= 0.0:
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
    model = record = None
    if kind == "hyperelastic":
        for name in ("youngs_modulus", "poisson_ratio"):
            if name in props:
                raise where.error(f"'{name}' belongs to linear-elastic materials; a hyperelastic one uses 'model'")
        table = where.table(data, "model")
        assert table is not None
        model, record = _model(where, table)
    else:
        if "model" in data:
            raise where.error("a linear-elastic material takes youngs_modulus and poisson_ratio, not 'model'")
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
        materials=tuple(_material(path, k, v) for k, v in materials.items()),
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
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise MaterialDataError(f"{p}: cannot read the material file ({exc.strerror})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise MaterialDataError(f"{p}: not valid TOML: {exc}") from None
    return parse_library(data, str(p))


# ---------------------------------------------------------------------------------------
# the registry: built-in library plus user files
# ---------------------------------------------------------------------------------------

_builtin: Library | None = None
_registered: list[Library] = []


def builtin() -> Library:
    """The library shipped with pneumorph (read once, then cached)."""
    global _builtin
    if _builtin is None:
        text = resources.files("pneumorph.materials").joinpath("data/materials.toml").read_text("utf-8")
        _builtin = parse_library(tomllib.loads(text), _BUILTIN)
    return _builtin


def _libraries() -> list[Library]:
    """Registered user libraries (latest first), then the built-in one."""
    return [*reversed(_registered), builtin()]


def names() -> tuple[str, ...]:
    """Canonical names of every available material (built-in first, then registered).

    Examples
    --------
    >>> "mold_star_15" in names()
    True
    """
    seen: list[str] = []
    for lib in reversed(_libraries()):
        seen.extend(n for n in lib.names() if n not in seen)
    return tuple(seen)


def get(name: str) -> Material:
    """The material called ``name`` (case, spaces, hyphens and dots do not matter).

    Registered user materials take precedence over built-in ones of the same name (only
    possible with ``register_toml(..., replace=True)``).

    Raises
    ------
    UnknownMaterialError
        If no library holds the name; the message lists the known ones.

    Examples
    --------
    >>> get("mold-star-15") is get("Mold Star 15")
    True
    """
    for lib in _libraries():
        found = lib.find(name)
        if found is not None:
            return found
    raise UnknownMaterialError(name, names())


def filler_names() -> tuple[str, ...]:
    """Names of every available filler law."""
    seen: list[str] = []
    for lib in reversed(_libraries()):
        seen.extend(n for n in lib.filler_names() if n not in seen)
    return tuple(seen)


def get_filler(name: str = "ellis2020_eq5_2") -> FillerLaw:
    """The filler law called ``name`` (default: Eq 5.2 of the dissertation).

    Examples
    --------
    >>> round(float(get_filler().modulus(0.0)), 4)
    0.0643
    """
    for lib in _libraries():
        if normalise(name) in lib.filler_names():
            return lib.filler(name)
    raise UnknownMaterialError(name, filler_names())


def register_toml(path: str | Path, replace: bool = False) -> Library:
    """Add the materials and fillers of a user TOML file to the library.

    Parameters
    ----------
    path : str or Path
        A file with the schema of ``data/materials.toml``.
    replace : bool
        Allow entries whose names (or aliases) are already taken; the new ones then take
        precedence. Without it, a clash raises :class:`MaterialDataError`.

    Returns
    -------
    Library
        The file's contents.
    """
    lib = load_library(path)
    if not replace:
        for m in lib.materials:
            for alias in (m.name, m.display_name, *m.aliases):
                for other in _libraries():
                    clash = other.find(alias)
                    if clash is not None:
                        raise MaterialDataError(
                            f"{lib.path}: [materials.{m.name}]: name {alias!r} is already used by "
                            f"{clash.name!r} from {other.path}; rename it or pass replace=True"
                        )
        for f in lib.fillers:
            if f.name in filler_names():
                raise MaterialDataError(
                    f"{lib.path}: [fillers.{f.name}]: name already used; rename it or pass replace=True"
                )
    _registered.append(lib)
    return lib


def clear_registered() -> None:
    """Forget every registered user file (the built-in library stays)."""
    _registered.clear()

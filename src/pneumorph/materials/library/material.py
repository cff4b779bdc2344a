"""Immutable material records: printed quantities, constitutive model, provenance."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any, Literal

from pneumorph.checks import MODES
from pneumorph.errors import MaterialDataError, UnknownMaterialError
from pneumorph.materials.laws.filler import FillerLaw
from pneumorph.materials.laws.hyperelastic import (
    HyperelasticModel,
    Ogden,
    StabilityReport,
    drucker_stability,
    ogden_marc_to_felupe,
)

#: Origin recorded for the materials shipped with pneumorph.
BUILTIN_ORIGIN = "pneumorph built-in library (materials/data/materials.toml)"

#: Properties that must be positive (a Poisson's ratio lies in (-1, 0.5) instead).
POSITIVE_PROPERTIES = frozenset({"density", "bulk_modulus", "youngs_modulus", "thickness"})
Kind = Literal["hyperelastic", "linear-elastic"]
KINDS: tuple[str, ...] = ("hyperelastic", "linear-elastic")

#: Scalar properties a material may carry, with their dimension.
PROPERTIES: dict[str, str] = {
    "density": "density",
    "bulk_modulus": "stress",
    "thermal_expansion": "thermal_expansion",
    "youngs_modulus": "stress",
    "poisson_ratio": "dimensionless",
    "thickness": "length",
}


def normalise(name: str) -> str:
    """Canonical form of a material name: lower case, runs of other characters -> ``_``.

    Examples
    --------
    >>> normalise("Mold Star 15"), normalise("mold-star-15"), normalise(" Smooth-Sil 950 ")
    ('mold_star_15', 'mold_star_15', 'smooth_sil_950')
    """
    return re.sub(r"[^a-z0-9]+", "_", name.strip().lower()).strip("_")



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

    def __post_init__(self) -> None:
        for key in ("value", "printed"):
            v = getattr(self, key)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise MaterialDataError(f"{self.name}: {key} must be a finite number, got {v!r}")
        if self.name in POSITIVE_PROPERTIES and self.value <= 0.0:
            raise MaterialDataError(f"{self.name.replace('_', ' ')} must be positive, got {self.printed} "
                                    f"{self.printed_unit}")
        if self.name == "poisson_ratio" and not -1.0 < self.value < 0.5:
            raise MaterialDataError(f"Poisson's ratio must lie in (-1, 0.5), got {self.printed}")
        if not isinstance(self.assumed, bool):
            raise MaterialDataError(f"{self.name}: 'assumed' must be true or false, got {self.assumed!r}")

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
class FitRecord:
    """How a library model was fitted to test data: the data, their licence and caveats, the range.

    Attributes
    ----------
    data : str
        The test data fitted (database, file, test).
    attribution : str
        The attribution line the data's licence asks for.
    mode : str
        The loading mode fitted (one of :data:`~pneumorph.checks.MODES`).
    stretch_range : (float, float)
        Smallest and largest stretch of the points fitted.
    points : int
        Number of points fitted.
    method : str
        Model, settings and the function that made the fit.
    caveats : tuple of str
        What the test does not tell (how the strain was measured, modes not tested, ...).

    Examples
    --------
    >>> r = FitRecord("a curve", "Data: someone", "uniaxial", (1.05, 4.0), 30, "ogden-2")
    >>> r.stability_range
    (0.5, 4.0)
    """

    data: str
    attribution: str
    mode: str
    stretch_range: tuple[float, float]
    points: int
    method: str
    caveats: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise MaterialDataError(f"fit mode must be one of {', '.join(MODES)}, got {self.mode!r}")
        lo, hi = self.stretch_range
        if not 0.0 < lo < hi:
            raise MaterialDataError(f"fit stretch_range must rise from a positive stretch, got [{lo}, {hi}]")
        if isinstance(self.points, bool) or not isinstance(self.points, int) or self.points < 1:
            raise MaterialDataError(f"fit points must be a positive whole number, got {self.points!r}")

    @property
    def stability_range(self) -> tuple[float, float]:
        """Stretches of the Drucker check: the fitted range widened to 0.5-1.5 at least."""
        lo, hi = self.stretch_range
        return min(0.5, lo), max(1.5, hi)

    def stability(self, model: HyperelasticModel) -> StabilityReport:
        """Drucker stability of ``model`` in the three modes over :attr:`stability_range`."""
        return drucker_stability(model, stretch_range=self.stability_range)

    def to_dict(self, model: HyperelasticModel | None = None) -> dict[str, Any]:
        """Plain-data form (JSON-serialisable); with ``model``, its Drucker stability too."""
        out: dict[str, Any] = {
            "data": self.data,
            "attribution": self.attribution,
            "mode": self.mode,
            "stretch_range": list(self.stretch_range),
            "points": self.points,
            "method": self.method,
            "caveats": list(self.caveats),
        }
        if model is not None:
            report = self.stability(model)
            out["drucker_stability"] = {
                "checked": list(self.stability_range),
                "modes": list(MODES),
                "stable": report.is_stable,
                "stable_limits": {k: list(v) for k, v in report.limits().items()},
            }
        return out


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
    fitting : FitRecord or None
        For a model fitted to public test data: the data, attribution, caveats and range.
    aliases : tuple of str
        Other accepted names.
    description : str
    origin : str
        The file the entry was read from.

    Examples
    --------
    >>> from pneumorph.materials.library.builtin import get
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
    fitting: FitRecord | None = None
    aliases: tuple[str, ...] = ()
    description: str = ""
    origin: str = BUILTIN_ORIGIN

    def __post_init__(self) -> None:
        """The rules a library file's entry obeys hold for a material built in code too."""
        where = f"material {self.name!r}"
        if not isinstance(self.name, str) or not self.name or normalise(self.name) != self.name:
            raise MaterialDataError(f"{where}: the name must be lower case letters, digits and '_'")
        if self.kind not in KINDS:
            raise MaterialDataError(f"{where}: kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        for key in ("display_name", "source"):
            if not isinstance(getattr(self, key), str) or not getattr(self, key).strip():
                raise MaterialDataError(f"{where}: {key} must be a non-empty text")
        if self.kind == "hyperelastic":
            if self.model is None:
                raise MaterialDataError(f"{where}: a hyperelastic material needs a model")
            if self.youngs_modulus is not None or self.poisson_ratio is not None:
                raise MaterialDataError(f"{where}: youngs_modulus and poisson_ratio belong to linear-elastic "
                                        "materials")
        elif self.model is not None or self.youngs_modulus is None or self.poisson_ratio is None:
            raise MaterialDataError(f"{where}: a linear-elastic material takes youngs_modulus and poisson_ratio, "
                                    "not a model")
        for name in PROPERTIES:
            q = getattr(self, name)
            if q is not None and (not isinstance(q, Quantity) or q.name != name):
                raise MaterialDataError(f"{where}: {name} must be a Quantity named {name!r}, got {q!r}")
        if self.fitting is not None and (not isinstance(self.fitting, FitRecord) or self.model is None):
            raise MaterialDataError(f"{where}: a fit record (FitRecord) belongs to a hyperelastic material's model")
        for model_name, r in self.r_squared:
            if isinstance(r, bool) or not isinstance(r, (int, float)) or not r <= 1.0:
                raise MaterialDataError(f"{where}: R^2 of {model_name} must be a number <= 1, got {r!r}")

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
            From :func:`pneumorph.materials.laws.felupe_models.build_umat` (hyperelastic, with
            the library bulk modulus) or ``build_linear_elastic`` (linear elastic).

        Raises
        ------
        MaterialDataError
            If a hyperelastic material has no bulk modulus, or the formulation does not
            apply.
        """
        from pneumorph.materials.laws import felupe_models  # lazy: FElupe takes ~0.5 s to import

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
        assert self.model is not None  # a hyperelastic material (checked on construction)
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
        if self.fitting is not None:
            out["fit"] = self.fitting.to_dict(self.model)
        out["assumed"] = list(self.assumed)
        return out


@dataclass(frozen=True)
class Library:
    """The materials and filler laws read from one TOML file.

    Examples
    --------
    >>> from pneumorph.materials.library.builtin import builtin
    >>> lib = builtin()
    >>> lib.get("Ecoflex 0030").name, lib.get("Ecoflex 00-30").name, len(lib.names()) >= 26
    ('ecoflex_0030', 'ecoflex_00_30', True)
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



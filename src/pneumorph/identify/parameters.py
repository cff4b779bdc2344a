"""The model inputs a scan can identify: two material scales and the three mould thicknesses of Fig E.4.

========================  ==========================================================
``body_bulk_scale``       factor on the body silicone's bulk modulus (appendix E.1.2)
``body_shear_scale``      factor on the body silicone's Ogden moduli (its shear modulus)
``side_wall``             the side walls, mm (Fig E.4; the 2D section has none)
``wall``                  the Mold Star wall on both sides of the cavity, mm
``layer``                 the Smooth-Sil layer, mm
========================  ==========================================================

A point of the parameter space is a :class:`ParameterSet`: the nominal unit, the
tolerance box of its thicknesses (the mesh of every unit in it has the nominal cell
counts, :func:`~pneumorph.sensitivity.tolerances.box_units`, so that surface nodes
correspond), and :meth:`ParameterSet.settings` turns values into the model factory's
settings (:func:`pneumorph.models.factory.make_model`): the ``[model]`` table an
identified model is written as.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pneumorph.errors import SettingsError
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.factory import SCALE_RANGE
from pneumorph.sensitivity.tolerances import FIELDS, PRINTED, Tolerance, box_units

FloatArray = NDArray[np.float64]

#: the identified parameters, in the order of every array here; the scales are named as the model
#: factory's settings (the ``[model]`` table ``--model-file`` reads), so one name serves the command's
#: output, identify.json and identified.toml
NAMES = ("body_bulk_scale", "body_shear_scale", *FIELDS)
#: the material scales (dimensionless) and the thicknesses (mm)
SCALES = NAMES[:2]
#: forward-difference steps of the Jacobian: 2 % on a modulus, 0.05 mm on a thickness
STEPS = {"body_bulk_scale": 0.02, "body_shear_scale": 0.02, "side_wall": 0.05, "wall": 0.05, "layer": 0.05}
#: a plausible change of each parameter (5 %, 0.1 mm): the columns' scale, and the yardstick of "not constrained"
SPANS = {"body_bulk_scale": 0.05, "body_shear_scale": 0.05, "side_wall": 0.1, "wall": 0.1, "layer": 0.1}


@dataclass(frozen=True)
class ParameterSet:
    """The nominal model's parameters and the box the fit may move them in.

    Parameters
    ----------
    unit : UnitSpec
        The nominal unit (its thicknesses are the nominal ones).
    tolerance : float
        The thicknesses stay within ``+-tolerance`` mm of nominal (default: the FDM class,
        0.1 mm); every unit in the box is meshed with the nominal unit's cell counts.
    scales : tuple of float
        The nominal material scales (1, 1: the library's silicone).

    Examples
    --------
    >>> p = ParameterSet(UnitSpec(element_size=3.0))
    >>> p.nominal.tolist(), p.element_size
    ([1.0, 1.0, 1.5, 1.5, 3.0], 3.12)
    >>> p.settings(p.nominal + [0.06, 0, 0, 0.08, 0])["unit"]["wall"], p.settings(p.nominal)["body_bulk_scale"]
    (1.58, 1.0)
    """

    unit: UnitSpec
    tolerance: float = PRINTED
    scales: tuple[float, float] = (1.0, 1.0)
    #: the nominal unit at the element size that meshes the whole box alike
    meshed_unit: UnitSpec = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        box = Tolerance(self.tolerance)
        box.check(self.unit)
        nominal, _ = box_units(self.unit, box, [])
        # the 2D model's filler law belongs to the physical unit: a cast with other thicknesses keeps it
        object.__setattr__(self, "meshed_unit", nominal.with_own_filler())

    @property
    def element_size(self) -> float:
        return float(self.meshed_unit.element_size)

    @property
    def nominal(self) -> FloatArray:
        return np.array([*self.scales, *(float(getattr(self.unit, f)) for f in FIELDS)])

    @property
    def lower(self) -> FloatArray:
        return np.array([SCALE_RANGE[0]] * 2 + [float(getattr(self.unit, f)) - self.tolerance for f in FIELDS])

    @property
    def upper(self) -> FloatArray:
        return np.array([SCALE_RANGE[1]] * 2 + [float(getattr(self.unit, f)) + self.tolerance for f in FIELDS])

    def check(self, values: Any) -> FloatArray:
        """``values`` as an array of :data:`NAMES`' length, refused outside the box."""
        v = np.asarray(values, dtype=float)
        if v.shape != (len(NAMES),) or not np.all(np.isfinite(v)):
            raise SettingsError(f"parameter values must be {len(NAMES)} finite numbers ({', '.join(NAMES)}), got "
                                f"{values!r}")
        outside = [f"{n} = {x:g} (allowed {lo:g} to {hi:g})" for n, x, lo, hi
                   in zip(NAMES, v, self.lower, self.upper, strict=True) if not lo - 1e-9 <= x <= hi + 1e-9]
        if outside:
            raise SettingsError(f"parameters outside the identification box: {'; '.join(outside)}")
        return v

    def unit_at(self, values: Any) -> UnitSpec:
        """The unit with the thicknesses of ``values``, meshed as the nominal one."""
        v = self.check(values)
        thick: dict[str, Any] = {f: round(float(x), 9) for f, x in zip(FIELDS, v[2:], strict=True)}
        return replace(self.meshed_unit, **thick)

    def settings(self, values: Any, base: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """The model factory's settings at ``values`` (``base``: the other settings, e.g. fidelity).

        The unit goes in as a table (``[model.unit]``), with the matched element size; the
        scales under their own names (``body_bulk_scale``, ``body_shear_scale``).
        """
        v = self.check(values)
        out = {k: val for k, val in dict(base or {}).items() if k not in ("unit", "unit_file", "library")}
        out["unit"] = self.unit_at(v).to_dict()
        for name, x in zip(SCALES, v[:2], strict=True):
            out[name] = round(float(x), 12)
        return out


def parameter_indices(names: Any) -> list[int]:
    """Indices into :data:`NAMES` of ``names`` (refusing unknown ones).

    >>> parameter_indices(["wall", "body_bulk_scale"])
    [0, 3]
    """
    unknown = [n for n in names if n not in NAMES]
    if unknown:
        raise SettingsError(f"unknown parameter(s) {', '.join(map(str, unknown))}; known: {', '.join(NAMES)}")
    return sorted(NAMES.index(n) for n in names)


__all__ = ["NAMES", "SCALES", "SPANS", "STEPS", "ParameterSet", "parameter_indices"]

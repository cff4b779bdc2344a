"""A silicone with its moduli scaled: the materials of the sensitivity study's variants
(appendix E.1.2) and of an identified model (the ``[model]`` table's ``body_bulk_scale`` and
``body_shear_scale``, :func:`pneumorph.models.factory.make_model`).
"""

from __future__ import annotations

from dataclasses import replace

from pneumorph import checks
from pneumorph.errors import MaterialDataError
from pneumorph.materials.laws.hyperelastic import Ogden
from pneumorph.materials.library.material import Material


def scaled_bulk_modulus(material: Material, factor: float) -> Material:
    """``material`` with its bulk modulus multiplied by ``factor`` (same name, new value).

    Examples
    --------
    >>> from pneumorph.materials import get
    >>> round(scaled_bulk_modulus(get("mold_star_15"), 1.05).bulk_modulus.value * 1e3, 2)   # kPa
    124.95
    """
    factor = checks.real(factor, "bulk modulus factor", 0.0, 1000.0, low_open=True)  # to nearly incompressible
    q = material.bulk_modulus
    if q is None:
        raise MaterialDataError(f"{material.name!r} has no bulk modulus to scale")
    scaled = replace(q, value=q.value * factor, printed=q.printed * factor,
                     source=f"{q.source}, x {factor:g} (sensitivity study, appendix E.1.2)")
    return replace(material, bulk_modulus=scaled)


def scaled_shear_modulus(material: Material, factor: float) -> Material:
    """``material`` with every Ogden modulus ``mu_n`` multiplied by ``factor`` (same name, exponents kept).

    The initial shear modulus ``mu0 = sum mu_n alpha_n / 2`` and every stress of the
    incompressible part scale by ``factor``; the bulk modulus is left as it is
    (:func:`scaled_bulk_modulus` scales that).

    Raises
    ------
    MaterialDataError
        A material whose model is not Ogden's (the FE models' silicones are).

    Examples
    --------
    >>> from pneumorph.materials import get
    >>> ms = get("mold_star_15")
    >>> round(scaled_shear_modulus(ms, 1.1).shear_modulus / ms.shear_modulus, 12)
    1.1
    """
    factor = checks.real(factor, "shear modulus factor", 0.0, 100.0, low_open=True)
    model, record = material.model, material.model_record
    if not isinstance(model, Ogden):
        raise MaterialDataError(f"{material.name!r} has no Ogden model whose moduli could be scaled")
    scaled = Ogden(mu=tuple(m * factor for m in model.mu), alpha=model.alpha)
    note = f"mu_n x {factor:g} (identified scale of the shear modulus)"
    if record is not None:
        params = tuple((k, _times(v, factor) if k == "mu" else v) for k, v in record.parameters)
        record = replace(record, parameters=params, source=f"{record.source}, {note}")
    return replace(material, model=scaled, model_record=record)


def _times(value: float | tuple[float, ...], factor: float) -> float | tuple[float, ...]:
    return tuple(x * factor for x in value) if isinstance(value, tuple) else value * factor


__all__ = ["scaled_bulk_modulus", "scaled_shear_modulus"]

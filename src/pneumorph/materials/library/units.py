"""Units of the material data files and their conversion to pneumorph's internal units.

Data files keep numbers as printed in their source (kPa, kg/m^3, micro-strain per degC);
:func:`to_internal` is the one place where they are converted to MPa, tonne/mm^3, 1/K, mm.
"""

from __future__ import annotations

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


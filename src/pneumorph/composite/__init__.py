"""Bilinear paper-silicone composite (Ellis 2020, chapter 3).

:mod:`~pneumorph.composite.crimp` (analytical transition strain, Eqs 3.1-3.4) is plain
Python; :mod:`~pneumorph.composite.coupon` (plane-strain FE of a crimped coupon) imports
FElupe when a coupon is simulated; :mod:`~pneumorph.composite.gauges` places virtual
strain gauges (Eq 3.5); :mod:`~pneumorph.composite.figures` draws Figs 3.4, 3.5, 3.7, 3.8
analogues.

Examples
--------
>>> from pneumorph.composite import Crimp
>>> round(100 * Crimp.from_ratio(0.3, amplitude=1.5, length=176.25).transition_strain, 1)
54.0
"""

from pneumorph.composite.crimp import (
    Crimp,
    effective_length,
    flute_count,
    flute_length,
    limit_transition_strain,
    transition_strain,
)

__all__ = [
    "Crimp",
    "effective_length",
    "flute_count",
    "flute_length",
    "limit_transition_strain",
    "transition_strain",
]

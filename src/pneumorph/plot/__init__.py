"""Figures (matplotlib, Agg backend: no display needed); PNG or SVG by file extension.

Examples
--------
>>> from pneumorph.plot import plot_fits
"""

from pneumorph.plot.fits import plot_fits

__all__ = ["plot_fits"]

"""Figures of a filler-law calibration: the points and laws (Fig 5.3), profiles per law
(Fig 5.4), constant filler against E(P) (Fig 5.7).

They only draw what they are given: the responses are solved by the workflow
(:func:`~pneumorph.calibration.compare_laws`).

Examples
--------
>>> import tempfile, pathlib
>>> from pneumorph.calibration import FillerPoint, fit_law
>>> pts = tuple(FillerPoint(0, p, "01", 0.05 - p, 0.0, 0.03, 1) for p in (0.01, 0.02, 0.03))
>>> fit = fit_law([p.pressure for p in pts], [p.modulus for p in pts], 1, (0.0, 0.03))
>>> cal = Calibration(pts, fit, fit, fit, (0.0, 0.03), 0.3)
>>> plot_calibration(cal, pathlib.Path(tempfile.mkdtemp()) / "c.png").is_file()
True
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.calibration.method import Calibration
from pneumorph.calibration.validation import centre_distances
from pneumorph.models.response import Response
from pneumorph.plot.figure import new_figure, save_figure


def _figure(size: tuple[float, float]) -> Any:
    return new_figure(*size)


def _finish(fig: Any, ax: Any, title: str, path: str | Path) -> Path:
    """Title, grid and legend, then write the figure (150 dpi)."""
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return save_figure(fig, path, title)


def plot_calibration(cal: Calibration, path: str | Path) -> Path:
    """Fig 5.3: the best modulus per pressure for each run, and both fitted laws."""
    fig = new_figure(6.0, 4.2)
    ax = fig.add_subplot()
    for run in sorted({p.run for p in cal.points}):
        pts = [p for p in cal.points if p.run == run]
        ax.plot([p.pressure * 1e3 for p in pts], [p.modulus for p in pts], "o", label=f"run {run + 1}")
    grid = np.linspace(*cal.pressure_range, 100)
    for fit, style in ((cal.linear, "--"), (cal.quadratic, "-")):
        if fit.coefficients:
            ax.plot(grid * 1e3, np.polynomial.polynomial.polyval(grid, fit.coefficients), style,
                    label=f"degree {fit.degree}, {fit.weighting} weighting, R$^2$ = {fit.r_squared:.4f}")
    ax.set(xlabel="pressure [kPa]", ylabel="filler modulus E [MPa]", title="Filler law calibration (Eq 5.1)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path, "filler law calibration (Fig 5.3)")


def plot_law_profiles(responses: Mapping[str, Response], reference: Response, path: str | Path,
                      level: int = -1) -> Path:
    """Fig 5.4: unit-centre profiles of the 2D model under each law against 3D, at one level.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from pneumorph.models.fe import Reduced2D, RampSpec
    >>> r = Reduced2D(2, ramp_spec=RampSpec(pressure=0.005)).evaluate("01")
    >>> out = plot_law_profiles({"law": r}, r, pathlib.Path(tempfile.mkdtemp()) / "p.png")
    >>> out.is_file()
    True
    """
    fig = _figure((6.4, 4.4))
    ax = fig.add_subplot()
    pressure = reference.pressures[level] * 1e3
    for name, r in responses.items():
        d = centre_distances(r, reference)[level]
        c = r.centres[level]
        ax.plot(c[:, 0], c[:, 1], "o-", ms=3, lw=1, label=f"2D, {name} (mean {d.mean():.2f} mm)")
    c3 = reference.centres[level]
    ax.plot(c3[:, 0], c3[:, 1], "ks--", ms=4, lw=1.2, label="3D")
    ax.plot(reference.reference_centres[:, 0], reference.reference_centres[:, 1], ":", color="0.6",
            label="undeformed")
    ax.set(xlabel="x [mm]", ylabel="y [mm]", aspect="equal")
    return _finish(fig, ax, f"Unit centres at {pressure:.1f} kPa, design {reference.orientation}", path)


def plot_filler_paths(responses: Mapping[str, Response], reference: Response, path: str | Path) -> Path:
    """Fig 5.7: mean and largest 2D-3D unit-centre distance over the ramp, per filler choice.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from pneumorph.models.fe import Reduced2D, RampSpec
    >>> r = Reduced2D(2, ramp_spec=RampSpec(pressure=0.005)).evaluate("01")
    >>> plot_filler_paths({"E(P)": r}, r, pathlib.Path(tempfile.mkdtemp()) / "f.png").is_file()
    True
    """
    fig = _figure((6.4, 4.2))
    ax = fig.add_subplot()
    p = reference.pressures * 1e3
    for i, (name, r) in enumerate(responses.items()):
        d = centre_distances(r, reference)
        colour = f"C{i}"
        ax.plot(p, d.mean(axis=1), "o-", color=colour, label=f"{name}: mean")
        ax.plot(p, d.max(axis=1), "^:", color=colour, label=f"{name}: max")
    ax.set(xlabel="pressure [kPa]", ylabel="2D-3D unit-centre distance [mm]")
    return _finish(fig, ax, f"Constant vs pressure-dependent filler, {reference.orientation}", path)

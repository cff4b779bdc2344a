"""Figures of a filler-law validation: profiles per law (Fig 5.4), constant against E(P) (Fig 5.7).

Both compare the 2D model with a 3D reference of the same design, so they take the 3D
:class:`~pneumorph.models.response.Response` and solve the 2D model as needed.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials.filler import FillerLaw
from pneumorph.models.fe import RampSpec, Reduced2D
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


def centre_distances(r2: Response, r3: Response) -> np.ndarray:
    """(levels, units) distances between matching unit centres of two responses, mm."""
    return np.linalg.norm(r2.centres - r3.centres, axis=-1)


def law_responses(unit: UnitSpec, n_units: int, design: str, ramp: RampSpec,
                  laws: Mapping[str, FillerLaw]) -> dict[str, Response]:
    """The 2D response of one design under each named filler law."""
    return {name: Reduced2D(n_units, unit, ramp, law).evaluate(design) for name, law in laws.items()}


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


def constant_law(law: FillerLaw, pressure: float, name: str) -> FillerLaw:
    """A constant filler law equal to ``law`` at ``pressure`` (MPa), over the same range."""
    return replace(law, name=name, display_name=name, coefficients=(float(law.modulus(pressure)),))

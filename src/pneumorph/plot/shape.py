"""Figures of a solved actuator: the deformed shape coloured by material."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure

from pneumorph import __version__
from pneumorph.geometry.boundary import boundary_facets
from pneumorph.plot.figure import new_figure, save_figure

COLOURS = {"body": "#4daf4a", "layer": "#377eb8", "filler": "#d9d9d9", "base": "#a6d96a"}
LABELS = {"body": "body", "layer": "stiff layer", "filler": "filler (2D model)", "base": "base block"}
#: the bottom walls of other materials (regions ``bottom:<material>``), one colour each in turn
BOTTOM_COLOURS = ("#e41a1c", "#984ea3", "#ff7f00")


def region_style(name: str, regions: Iterable[str]) -> tuple[str, str]:
    """Face colour and legend label of a mesh region (a bottom wall's by its material).

    >>> region_style("layer", ["body", "layer"])
    ('#377eb8', 'stiff layer')
    >>> region_style("bottom:bilinear_0_2", ["body", "bottom:bilinear_0_2"])
    ('#e41a1c', 'bottom wall: bilinear_0_2')
    """
    if name in COLOURS:
        return COLOURS[name], LABELS[name]
    bottoms = [r for r in regions if r.startswith("bottom:")]
    return BOTTOM_COLOURS[bottoms.index(name) % len(BOTTOM_COLOURS)], f"bottom wall: {name.split(':', 1)[1]}"

# quad8 outline through the mid-side nodes; corner faces of a hexahedron
_QUAD8_OUTLINE = [0, 4, 1, 5, 2, 6, 3, 7]


def _section(ax: Any, solution: Any, level: int | None, outline: bool) -> None:
    mesh = solution.mesh
    x = mesh.points if level is None else mesh.points + solution.displacements[level]
    for name, idx in mesh.regions.items():
        order = _QUAD8_OUTLINE if mesh.cells.shape[1] == 8 else [0, 1, 2, 3]
        polys = x[mesh.cells[idx]][:, order]
        colour, label = region_style(name, mesh.regions)
        ax.add_collection(PolyCollection(polys, facecolor=colour, edgecolor="k", lw=0.15, label=label))
    if outline and level is not None:
        ref = mesh.points[mesh.cells][:, order]
        ax.add_collection(PolyCollection(ref, facecolor="none", edgecolor="0.6", lw=0.2))
    c = mesh.unit_centres(None if level is None else solution.displacements[level])
    ax.plot(c[:, 0], c[:, 1], "k.-", ms=3, lw=0.8, label="unit centres")


def _surface(ax: Any, solution: Any, level: int | None) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mesh = solution.mesh
    x = mesh.points if level is None else mesh.points + solution.displacements[level]
    x = x[:, [0, 2, 1]]  # drawn as (x, z, y): the height y points up
    faces, owner = boundary_facets(mesh.cells)
    region_of = np.empty(len(mesh.cells), dtype=object)
    for name, idx in mesh.regions.items():
        region_of[idx] = name
    colours = [region_style(region_of[c], mesh.regions)[0] for c in owner]
    ax.add_collection3d(Poly3DCollection(x[faces], facecolors=colours, edgecolor="k", linewidths=0.05))
    lo, hi = x.min(axis=0), x.max(axis=0)
    span = (hi - lo).max() / 2
    mid = (hi + lo) / 2
    ax.set(xlim=(mid[0] - span, mid[0] + span), ylim=(mid[1] - span, mid[1] + span),
           zlim=(mid[2] - span, mid[2] + span))
    ax.view_init(elev=20, azim=-60)


def plot_shape(
    solution: Any,
    path: str | Path | None = None,
    levels: Sequence[int] | None = None,
    title: str | None = None,
) -> Figure:
    """The deformed actuator at some reported levels, coloured by material.

    2D models show the section with the undeformed mesh in grey; 3D models show the
    outer surface (x along the actuator, y up, z across). The legend, under the sections,
    names the materials and each rigid obstacle with its force at the last level drawn
    and that level's pressure.

    Parameters
    ----------
    solution : pneumorph.models.fe.Solution
        A solved design.
    path : str or Path, optional
        Write the figure there (PNG, SVG or PDF by the extension).
    levels : sequence of int, optional
        Reported levels to draw (default: the last converged one).
    title : str, optional
        Figure title (default: the design and the model).
    """
    resp = solution.response
    done = [k for k in range(resp.n_levels) if not np.isnan(solution.displacements[k]).any()]
    levels = list(levels) if levels is not None else done[-1:]
    dim = solution.mesh.dim
    fig = new_figure(5.5 * max(1, len(levels)), 5.0)
    for i, k in enumerate(levels):
        if dim == 2:
            ax = fig.add_subplot(1, len(levels), i + 1)
            _section(ax, solution, k, outline=True)
            ax.set_aspect("equal")
            ax.autoscale_view()
            _obstacles(ax, resp.metadata.get("contact"), k, resp.pressures[k])
            ax.set_xlabel("x [mm]")
            ax.set_ylabel("y [mm]")
            ax.grid(alpha=0.3)
        else:
            ax = fig.add_subplot(1, len(levels), i + 1, projection="3d")
            _surface(ax, solution, k)
            _obstacles_3d(ax, resp.metadata.get("contact"), k, resp.pressures[k], solution.mesh.points)
            ax.set_xlabel("x [mm]")
            ax.set_ylabel("z [mm]")
            ax.set_zlabel("y [mm]")
        ax.set_title(f"{resp.pressures[k] * 1e3:.4g} kPa, curl {resp.curl[k]:.1f} deg", fontsize=9)
    fig.suptitle(title or f"design {resp.orientation} ({resp.metadata.get('fidelity', '')} model)")
    _legend(fig)
    fig.text(0.01, 0.005, f"pneumorph {__version__} | {resp.metadata.get('fingerprint', '')}", fontsize=6, color="0.4")
    if path is not None:
        save_figure(fig, path, f"design {resp.orientation}")
    return fig


def _legend(fig: Figure) -> None:
    """The legend under the sections, outside the axes, at the right (the provenance line is at the left): it covers
    no part of the actuator and its place is fixed (matplotlib's ``loc="best"`` tests every cell's polygon at each
    draw, about 1.3 s of a save of a 2D figure of two levels). The first section's materials, with the obstacles'
    forces of the last section (the highest level drawn). In rows of two under one section, of up to six under
    more; none where nothing is labelled (a 3D figure without obstacles)."""
    handles, labels = fig.axes[0].get_legend_handles_labels()
    last = fig.axes[-1].get_legend_handles_labels()
    pairs = [(h, t) for h, t in zip(handles, labels, strict=True) if not t.startswith(_OBSTACLE)]
    pairs += [(h, t) for h, t in zip(*last, strict=True) if t.startswith(_OBSTACLE)]
    if pairs:
        handles, labels = (list(x) for x in zip(*pairs, strict=True))
        fig.legend(handles, labels, loc="outside lower right", ncols=min(len(handles), 4 * len(fig.axes) - 2),
                   fontsize=7)


#: how an obstacle's legend entry starts (``obstacle 1: 0.25 N at 45 kPa``)
_OBSTACLE = "obstacle "


def _obstacle_labels(contact: Any, k: int, pressure: float) -> list[str]:
    """Each obstacle's legend entry at level ``k``: its force (N) and the pressure of that level.

    >>> contact = {"obstacles": [{"kind": "plane"}], "levels": [{"obstacles": [{"force_magnitude_n": 0.1234}]}]}
    >>> _obstacle_labels(contact, 0, 0.045)
    ['obstacle 1: 0.123 N at 45 kPa']
    """
    level = contact["levels"][k] if k < len(contact["levels"]) else None
    forces = [level["obstacles"][i]["force_magnitude_n"] if level else float("nan")
              for i in range(len(contact["obstacles"]))]
    return [f"{_OBSTACLE}{i + 1}: {force:.3g} N at {pressure * 1e3:.4g} kPa" for i, force in enumerate(forces)]


def _obstacles(ax: Any, contact: Any, k: int, pressure: float) -> None:
    """The rigid obstacles of a 2D solve (:mod:`pneumorph.models.fe.obstacles`) on the section, each with its force
    at level ``k`` (N, at its ``pressure``, MPa); a plane as its trace across the drawn extent."""
    if not contact:
        return
    from matplotlib.patches import Circle

    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    for obstacle, label in zip(contact["obstacles"], _obstacle_labels(contact, k, pressure), strict=True):
        if obstacle["kind"] == "plane":
            p, n = np.asarray(obstacle["point"][:2]), np.asarray(obstacle["normal"][:2])
            t = np.array([-n[1], n[0]]) * 2 * max(x1 - x0, y1 - y0)
            ax.plot(*np.transpose([p - t, p + t]), color="0.2", lw=2, label=label)
        else:
            (cx, cy), r = obstacle["centre"][:2], obstacle["radius"]
            ax.add_patch(Circle((cx, cy), r, color="0.5", alpha=0.6, label=label))
            x0, x1, y0, y1 = min(x0, cx - r), max(x1, cx + r), min(y0, cy - r), max(y1, cy + r)  # drawn whole
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)


def _obstacles_3d(ax: Any, contact: Any, k: int, pressure: float, points: Any) -> None:
    """The rigid obstacles of a 3D solve as grey surfaces (drawn as (x, z, y), as :func:`_surface`) across the
    actuator's extent, each labelled with its force at level ``k`` (N, at its ``pressure``, MPa)."""
    if not contact:
        return
    lo, hi = points.min(axis=0), points.max(axis=0)
    size = float((hi - lo).max())
    a, b = np.meshgrid(np.linspace(0.0, 2 * np.pi, 33), np.linspace(-0.5, 0.5, 9))
    for obstacle, label in zip(contact["obstacles"], _obstacle_labels(contact, k, pressure), strict=True):
        if obstacle["kind"] == "sphere":
            c, r = np.asarray(obstacle["centre"]), obstacle["radius"]
            u, v = np.meshgrid(np.linspace(0.0, 2 * np.pi, 33), np.linspace(0.0, np.pi, 17))
            xyz = c[:, None, None] + r * np.array([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)])
        else:
            normal = np.asarray(obstacle.get("normal", obstacle.get("axis", [0.0, 0.0, 1.0])), dtype=float)
            e1 = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
            e1 /= np.linalg.norm(e1)
            e2 = np.cross(normal, e1)
            if obstacle["kind"] == "plane":  # a square across the actuator's extent
                c = np.asarray(obstacle["point"])
                xyz = c[:, None, None] + size * (e1[:, None, None] * (a / np.pi - 1.0) + e2[:, None, None] * b)
            else:  # a cylinder: its length along the axis as long as the actuator is wide (or deep)
                c, r = np.asarray(obstacle["centre"]), obstacle["radius"]
                length = float(np.ptp(points @ normal)) or size
                along = np.clip(((lo + hi) / 2 - c) @ normal, -size, size)
                xyz = (c[:, None, None] + r * (e1[:, None, None] * np.cos(a) + e2[:, None, None] * np.sin(a))
                       + normal[:, None, None] * (along + b * length))
        ax.plot_surface(xyz[0], xyz[2], xyz[1], color="0.5", alpha=0.35, linewidth=0, label=label)

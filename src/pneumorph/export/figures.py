"""Drawings of the export: the casting mould's exploded assembly."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from pneumorph import __version__
from pneumorph.export.moulds import Mould
from pneumorph.plot.figure import new_figure, save_figure

__all__ = ["plot_mould"]

_COLOURS = {
    "base_plate": (0.55, 0.62, 0.72),
    "side_walls": (0.40, 0.55, 0.80),
    "lid": (0.70, 0.76, 0.86),
    "core": (0.90, 0.55, 0.25),
    "pin": (0.35, 0.35, 0.35),
    "cast": (0.85, 0.30, 0.35),
}
_LIGHT = np.array([-0.4, -0.5, 0.77]) / np.linalg.norm([-0.4, -0.5, 0.77])


def _colour(name: str) -> tuple[float, float, float]:
    return _COLOURS.get(name, _COLOURS.get(name.split("_")[0], (0.6, 0.6, 0.6)))


def plot_mould(mould: Mould, path: str | Path | None = None, cast: bool = True, title: str | None = None) -> Figure:
    """Draw the mould's parts moved apart along the pull direction, in 3D.

    The base plate at the bottom, the cores on it, the pins, the side walls and the lid
    above, each moved by :attr:`Mould.explode`; faces shaded by their angle to the light.

    Parameters
    ----------
    mould : Mould
        From :func:`~pneumorph.export.moulds.casting_mould`.
    path : str or Path, optional
        Write the figure there (PNG, or the format of the suffix), atomically.
    cast : bool
        Also draw the cast silicone (the open body and the side sheet) between the cores
        and the side walls (moved by ``mould.explode["cast"]``).
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from pneumorph.export.moulds import casting_mould
    >>> from pneumorph.geometry.unit import UnitSpec
    >>> fig = plot_mould(casting_mould(UnitSpec(), "01", check=False))
    >>> len(fig.axes[0].collections[0].get_facecolors()) > 1000   # triangles of the 9 parts
    True
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = new_figure(9, 6, layout=None)
    ax = fig.add_subplot(projection="3d")
    items = [(name, mesh, mould.explode.get(name, (0.0, 0.0, 0.0))) for name, mesh in mould.parts.items()]
    if cast:
        lift = mould.explode.get("cast", (0.0, 0.0, 0.0))
        items += [(f"cast_{name}", mesh, lift) for name, mesh in mould.cast.items()]
    triangles, colours = [], []
    for name, mesh, offset in items:
        normals = np.asarray(mesh.face_normals)
        shade = 0.45 + 0.55 * np.clip(normals @ _LIGHT, 0.0, 1.0)
        triangles.append(np.asarray(mesh.triangles) + np.asarray(offset))
        colours.append(np.clip(shade[:, None] * np.array(_colour(name))[None, :], 0.0, 1.0))
    # one collection, so that matplotlib orders every triangle by depth, across parts
    tri, col = np.concatenate(triangles), np.concatenate(colours)
    ax.add_collection3d(Poly3DCollection(tri, facecolors=col, edgecolors=col, linewidths=0.15))
    lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]),
           xlabel="x (mm)", ylabel="y (mm)", zlabel="z (mm)")
    ax.set_box_aspect(tuple(np.maximum(hi - lo, 1e-9)))
    ax.view_init(elev=22, azim=-58)
    ax.tick_params(labelsize=6)
    spec = mould.spec
    ax.set_title(title or f"mould of design {mould.orientation}: {len(mould.parts)} parts, exploded along z "
                          f"(clearance {spec.clearance:g} mm, draft {spec.draft:g} deg)", fontsize=9)
    fig.text(0.99, 0.01, f"pneumorph {__version__}", ha="right", fontsize=6, color="0.5")
    if path is not None:
        save_figure(fig, path, bbox_inches="tight")
    return fig

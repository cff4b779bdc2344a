"""The scan over the model (Figs 6.15-6.19 of the dissertation): outline, centreline, photo."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure

from pneumorph import __version__
from pneumorph.correlation.compare import Correlation, ModelShape
from pneumorph.plot.figure import new_figure, save_figure


def plot_correlation(result: Correlation, shape: ModelShape, path: str | Path | None = None,
                     photo: Any = None, photo_scale: float | None = None, title: str = "") -> Figure:
    """The aligned scan's outline points over the model's outline and centreline, in the bending plane.

    Parameters
    ----------
    result : Correlation
    shape : ModelShape
    path : str or Path, optional
        Write the figure there (atomically).
    photo : str or Path, optional
        An image in the coordinates the 2D trace was taken in (pixels, rows down), drawn
        under the outlines through the same alignment.
    photo_scale : float, optional
        mm per pixel of the photo (the scan's ``--scale``).
    """
    if not result.outline.count and result.surface.count:  # a design that leaves the plane: its surface only
        return _plot_surface(result, shape, path, title)
    fig = new_figure(8, 4.5, layout=None)
    ax = fig.add_subplot()
    if photo is not None:
        _photo(ax, result, photo, photo_scale or 1.0)
    ax.add_collection(LineCollection(list(shape.outline), colors="k", linewidths=0.8, label="model outline"))
    ax.plot(shape.centres[:, 0], shape.centres[:, 1], "k.--", lw=0.6, ms=3, label="model unit centres")
    pts = result.outline_points
    ax.plot(pts[:, 0], pts[:, 1], ".", color="tab:red", ms=1.5, alpha=0.6, label="scan (aligned)")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set(xlabel="x (mm)", ylabel="y (mm)")
    o, c = result.outline, result.centreline
    ax.set_title(title or f"outline RMS {o.rms:.3g} mm, max {o.max:.3g} mm; centreline RMS {c.rms:.3g} mm, "
                          f"max {c.max:.3g} mm", fontsize=9)
    ax.legend(loc="best", fontsize=7)
    fig.text(0.99, 0.01, f"pneumorph {__version__}", ha="right", fontsize=6, color="0.5")
    if path is not None:
        save_figure(fig, path, bbox_inches="tight")
    return fig


def _plot_surface(result: Correlation, shape: ModelShape, path: str | Path | None, title: str) -> Figure:
    """The aligned scan's points over the model's surface, seen from the side (x, y) and from above (x, z),
    coloured by their distance from the surface (a design that leaves the bending plane)."""
    from scipy.spatial import cKDTree

    dist, _ = cKDTree(shape.surface).query(result.aligned)
    fig = new_figure(8, 6.5, layout=None)
    for k, (j, name) in enumerate(((1, "y"), (2, "z"))):
        ax = fig.add_subplot(2, 1, k + 1)
        ax.plot(shape.surface[:, 0], shape.surface[:, j], ".", color="0.75", ms=1, label="model surface")
        dots = ax.scatter(result.aligned[:, 0], result.aligned[:, j], c=dist, s=2, cmap="viridis",
                          label="scan (aligned)")
        ax.set_aspect("equal")
        ax.set(xlabel="x (mm)", ylabel=f"{name} (mm)")
        ax.legend(loc="best", fontsize=7)
    fig.colorbar(dots, ax=fig.axes, label="distance from the surface (mm)", shrink=0.8)
    s = result.surface
    fig.axes[0].set_title(title or f"surface RMS {s.rms:.3g} mm, max {s.max:.3g} mm (from the side and from above)",
                          fontsize=9)
    fig.text(0.99, 0.01, f"pneumorph {__version__}", ha="right", fontsize=6, color="0.5")
    if path is not None:
        save_figure(fig, path, bbox_inches="tight")
    return fig


#: Largest photo drawn under a trace (pixels): 40 megapixels, about 0.6 GB as the float image matplotlib reads.
MAX_PHOTO_PIXELS = 40_000_000


def check_photo(photo: Any) -> tuple[int, int]:
    """Refuse a photo that is no readable image or too large, from its header, before anything is solved.

    Returns ``(width, height)`` in pixels.

    Raises
    ------
    ScanError
        Not an image Pillow can read, or more than :data:`MAX_PHOTO_PIXELS` pixels.
    """
    from PIL import Image, UnidentifiedImageError

    from pneumorph.errors import ScanError

    try:
        with Image.open(photo) as image:  # reads the header only
            width, height = image.size
    except Image.DecompressionBombError as exc:  # Pillow's own limit, far above ours
        raise ScanError(f"photo {photo}: more than the {MAX_PHOTO_PIXELS:,} pixels (MAX_PHOTO_PIXELS) drawn under "
                        f"a trace ({exc}); scale it down") from None
    except (UnidentifiedImageError, OSError, ValueError) as exc:
        raise ScanError(f"photo {photo}: not a readable image ({type(exc).__name__})") from None
    if width * height > MAX_PHOTO_PIXELS:
        raise ScanError(f"photo {photo}: {width:,} x {height:,} pixels, more than the {MAX_PHOTO_PIXELS:,} "
                        "(MAX_PHOTO_PIXELS) drawn under a trace; scale it down")
    try:  # a header can be whole over a broken body (truncated, corrupt): decode it now, within the limit
        with Image.open(photo) as image:
            image.load()
    except (OSError, ValueError, SyntaxError) as exc:
        raise ScanError(f"photo {photo}: not a readable image ({type(exc).__name__}: {exc})") from None
    return width, height


def _photo(ax: Any, result: Correlation, photo: Any, scale: float) -> None:
    from matplotlib.image import imread
    from matplotlib.transforms import Affine2D

    image = imread(str(photo))
    h, w = image.shape[:2]
    t = result.alignment.transform
    if t.rotation.shape != (2, 2):
        return  # a photo goes with a 2D trace only
    matrix = np.eye(3)
    matrix[:2, :2] = t.scale * t.rotation
    matrix[:2, 2] = t.translation
    shown = ax.imshow(image, extent=(0, w * scale, h * scale, 0), alpha=0.6, zorder=0)
    shown.set_transform(Affine2D(matrix) + ax.transData)

"""The one way pneumorph makes and writes a figure: no display, atomic files, provenance inside.

Every figure of the package is a :class:`matplotlib.figure.Figure` on the Agg canvas, so no
display or pyplot state is involved, and is written by :func:`save_figure`: atomically (a
killed run leaves the old file or none) and with pneumorph's name and version, and a
description, in the file's metadata (PNG text chunks, SVG and PDF document fields).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from pneumorph import __version__
from pneumorph.io.files import atomic_path


def new_figure(width: float, height: float,
               layout: Literal["constrained", "compressed", "tight"] | None = "constrained") -> Figure:
    """A figure of ``width x height`` inches on the Agg canvas (constrained layout by default).

    >>> new_figure(4.0, 3.0).get_size_inches().tolist()
    [4.0, 3.0]
    """
    fig = Figure(figsize=(width, height), layout=layout)
    FigureCanvasAgg(fig)
    return fig


#: the document fields each format keeps (PNG keeps any text)
_FIELDS = {".svg": {"Creator", "Description", "Source", "Title", "Subject"},
           ".pdf": {"Creator", "Subject", "Title"}}


def metadata(path: str | Path, description: str = "", **fields: str) -> dict[str, str]:
    """The metadata of a figure file: ``Creator`` (pneumorph and its version), ``Description``
    (``Subject`` in PDF) and further ``fields``, those that the format of ``path`` keeps.

    >>> metadata("a.png", "design 01")["Creator"].startswith("pneumorph")
    True
    >>> sorted(metadata("a.pdf", "x", Source="data.csv"))
    ['Creator', 'Subject']
    """
    suffix = Path(path).suffix.lower()
    out = {"Creator": f"pneumorph {__version__}", **fields}
    if description:
        out["Subject" if suffix == ".pdf" else "Description"] = description
    if suffix in _FIELDS:
        out = {k: v for k, v in out.items() if k in _FIELDS[suffix]}
    elif suffix != ".png":
        out = {}
    return out


def save_figure(fig: Figure, path: str | Path, description: str = "", dpi: int = 150,
                fields: dict[str, str] | None = None, **options: Any) -> Path:
    """Write ``fig`` to ``path`` atomically (the format from the suffix), with :func:`metadata`.

    ``fields`` are further metadata (``Title``, ``Source``); ``options`` go to
    :meth:`matplotlib.figure.Figure.savefig` (e.g. ``bbox_inches``).
    """
    with atomic_path(path) as tmp:  # the temporary file keeps the suffix, so the format
        fig.savefig(tmp, dpi=dpi, metadata=metadata(path, description, **(fields or {})), **options)
    return Path(path)


__all__ = ["metadata", "new_figure", "save_figure"]

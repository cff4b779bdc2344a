"""A design's scan against its model, from the read scan to the written folder.

:func:`correlate_design` is what ``pneumorph correlate`` does once its options are read: the
scan's length checked against the actuator, the design solved, the units checked, the scan
aligned and measured, and the summary, ``correlation.json`` and ``correlation.png`` written all or
nothing. The command line reads the files and refuses bad options before it; the API and the
command line share this.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from pneumorph.correlation.compare import Correlation, check_length, check_units, correlate, model_shape
from pneumorph.correlation.scans import Scan, align_seconds


def correlate_design(scan: Scan, design: str, model: Any, pressure_kpa: float, *, types: Sequence[Any] = (),
                     planar: bool = True, fit_scale: bool = False, out: str | Path | None = None,
                     photo: str | None = None, photo_scale: float | None = None, source: str = "",
                     say: Callable[[str], None] = lambda text: None) -> tuple[Correlation, dict[str, Any]]:
    """Solve ``design`` with ``model`` (built at ``pressure_kpa``) and align ``scan`` to its inflated shape.

    Parameters
    ----------
    scan : Scan
        The read scan (:func:`~pneumorph.correlation.scans.read_scan`).
    design : str
        The design as the model reads it.
    types : sequence of UnitSpec
        The unit of each position over a unit library (its length is their sum), else the model's unit.
    planar : bool
        The design stays in its plane (no sideways unit): the alignment keeps the plane.
    fit_scale, out, photo, photo_scale
        Fit a scale too; the folder to write (all or nothing); a photo under a 2D trace and its mm per pixel.
    source : str
        The scan's name in the summary.
    say : callable
        Receives a line before each long step.

    Returns
    -------
    Correlation, dict
        The alignment and distances, and the summary that ``correlation.json`` holds.

    Raises
    ------
    ScanError
        The scan's length or units do not match the actuator's, before the solve or right after it.
    """
    from pneumorph.geometry.assembly import unit_starts
    from pneumorph.io.progress import duration_text

    check_length(scan, float(unit_starts(list(types))[-1]) if types else len(design) * model.unit.pitch)
    say(f"solving design {design} at {pressure_kpa:g} kPa ({model.fidelity} model)")
    shape = model_shape(model.solve(design))
    check_units(scan, shape)
    seconds = align_seconds(len(scan.points))
    say(f"aligning {len(scan.points):,} scan points to the model (about {duration_text(seconds)}) ...")
    result = correlate(scan, shape, scale=fit_scale, planar=planar)
    summary = {"scan": source, "design": design, "pressure_kpa": pressure_kpa, "model": model.fidelity,
               "scan_points": len(scan.points), **result.to_dict()}
    if out:
        from pneumorph.correlation.figures import plot_correlation
        from pneumorph.io import provenance, write_json
        from pneumorph.io.files import all_or_nothing

        # stopped while writing (Ctrl-C, a bad photo): no partial output
        with all_or_nothing(out, say=say, what="correlation.json and correlation.png") as folder:
            write_json(folder / "correlation.json",
                       {**summary, "provenance": provenance(model=model.describe(), fingerprint=model.fingerprint())})
            plot_correlation(result, shape, folder / "correlation.png", photo=photo, photo_scale=photo_scale)
    return result, summary


__all__ = ["correlate_design"]

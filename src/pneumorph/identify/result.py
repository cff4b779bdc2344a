"""The identified model as a file: the ``[model]`` table of the fitted settings, with provenance.

``identified.toml`` holds a ``[model]`` table (the fidelity, the unit with the fitted
thicknesses as ``[model.unit]``, ``body_bulk_scale`` and ``body_shear_scale``) that the
model factory builds (:func:`pneumorph.models.factory.make_model`): ``pneumorph design
--model-file identified.toml`` and ``pneumorph simulate --model-file identified.toml`` use
it, and, having no other tables than ``[model]`` and ``[provenance]``, it is a design
config too. ``[provenance]`` names the scans, designs, pressures, the residuals before and
after, each parameter's value, standard error and confounded error, the combinations the scans
did not determine, the further scan advised, and pneumorph's version.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from pneumorph.design.config import to_toml
from pneumorph.identify.fit import Identification
from pneumorph.identify.parameters import NAMES
from pneumorph.io.files import atomic_write_text
from pneumorph.io.provenance import provenance


def identified_toml(result: Identification, **extra: Any) -> str:
    """The TOML text of ``result``'s model and its provenance (``extra``: e.g. the command).

    Examples
    --------
    >>> import tomllib
    >>> from pneumorph.identify.fit import Identification
    >>> r = Identification(np.array([1.06, 1, 1.5, 1.58, 3]), np.array([1.0, 1, 1.5, 1.5, 3]),
    ...     np.array([0.001, np.nan, np.nan, 0.004, 0.01]), np.array([1, 0, 0, 1, 1], bool),
    ...     np.array([1, 0, 0, 1, 1], bool), ("", "fixed", "fixed", "", ""), np.eye(3),
    ...     ("body_bulk_scale", "wall", "layer"), np.array([2.0]), np.array([0.05]), np.array([2.0]),
    ...     np.array([0.05]), 0.05, 2, 12, {"fidelity": "2d", "unit": {"wall": 1.58}, "body_bulk_scale": 1.06}, ("f",))
    >>> data = tomllib.loads(identified_toml(r))
    >>> data["model"]["unit"]["wall"], data["provenance"]["standard_error"]["wall"]
    (1.58, 0.004)
    """
    def plain(v: float) -> float | str:
        return float(v) if np.isfinite(v) else "not fitted"

    model = dict(result.settings)
    meta = provenance(
        what="a model identified from scans of cast actuators (pneumorph identify, docs/identify.md)",
        scans=[o.spec.file for o in result.observations], designs=[o.spec.design for o in result.observations],
        pressures_kpa=[o.spec.pressure_kpa for o in result.observations],
        rms_before_mm=result.rms_before.tolist(), rms_after_mm=result.rms_after.tolist(),
        fit_residual_before_mm=result.residual_before.tolist(), fit_residual_after_mm=result.residual_after.tolist(),
        iterations=result.iterations, solves=result.solves, fingerprints=list(result.fingerprints),
        identified=[n for n, ok in zip(NAMES, result.identified, strict=True) if ok],
        value={n: float(v) for n, v in zip(NAMES, result.values, strict=True)},
        standard_error={n: plain(v) for n, v in zip(NAMES, result.standard_errors, strict=True)},
        confounded_error={n: plain(v) for n, v in zip(NAMES, result.confounded_errors, strict=True)},
        undetermined=[c["combination"] for c in result.combinations], converged=result.converged,
        next_scans=[a["why"] for a in result.advice[:1]],
        **extra)
    deps = meta.pop("dependencies")
    return to_toml({"model": model, "provenance": {**meta, "dependencies": deps}})


def write_identified(result: Identification, folder: str | Path, **extra: Any) -> Path:
    """Write ``identified.toml`` into ``folder`` (atomically) and return its path."""
    return atomic_write_text(Path(folder) / "identified.toml", identified_toml(result, **extra))


__all__ = ["identified_toml", "write_identified"]

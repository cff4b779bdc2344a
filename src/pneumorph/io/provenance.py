"""What every output file records about how it was made."""

from __future__ import annotations

import datetime as _dt
import platform
import sys
from importlib.metadata import PackageNotFoundError, version
from typing import Any

from pneumorph import __version__

#: every package a result can depend on: the solver (PARDISO included), the search, the meshes, the figures
_PACKAGES = ("numpy", "scipy", "felupe", "tensortrax", "pypardiso", "deap", "distributed", "meshio", "trimesh",
             "manifold3d", "matplotlib")


def provenance(**extra: Any) -> dict[str, Any]:
    """pneumorph and dependency versions, Python, platform, UTC time, and ``extra``.

    Examples
    --------
    >>> p = provenance(seed=1)
    >>> sorted(k for k in p if k != "dependencies")
    ['created_utc', 'platform', 'pneumorph', 'python', 'seed']
    """
    deps = {}
    for name in _PACKAGES:
        try:
            deps[name] = version(name)
        except PackageNotFoundError:
            continue
    return {
        "pneumorph": __version__,
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "created_utc": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "dependencies": deps,
        **extra,
    }

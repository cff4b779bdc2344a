"""What every output file records about how it was made."""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
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


def digest(description: Any) -> str:
    """A short stable hash of a JSON-able description: what identifies a model, a unit library
    or a table's source in fingerprints and cache keys (sorted keys; anything else as its text).

    >>> digest({"b": 1, "a": [1.5, None]}) == digest({"a": [1.5, None], "b": 1})
    True
    >>> len(digest({}))
    16
    """
    text = json.dumps(description, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]

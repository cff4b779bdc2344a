"""pneumorph: generative design of soft pneumatic actuators.

The public API is grouped by sub-package:

- :mod:`pneumorph.materials` - hyperelastic models, the material library, fitting and
  characterisation of silicones and paper-silicone composites.

Examples
--------
>>> import pneumorph
>>> pneumorph.__version__
'0.1.0'
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("pneumorph")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]

"""pneumorph: generative design of soft pneumatic actuators.

The public API is grouped by sub-package:

- :mod:`pneumorph.materials` - hyperelastic models, the material library, fitting and
  characterisation of silicones and paper-silicone composites.
- :mod:`pneumorph.geometry` - the articulating unit (``UnitSpec``), designs (orientation
  vectors) and the meshed actuator.
- :mod:`pneumorph.models` - the 2D and 3D FE models, the model factory and the chain model.
- :mod:`pneumorph.design` - targets and tip goals, the certified search, the genetic
  algorithm, exhaustive search, run folders.
- :mod:`pneumorph.execution` - evaluators (serial, processes, Dask) and the evaluation cache.
- :mod:`pneumorph.composite`, :mod:`pneumorph.bimodal` - the bilinear composite and the
  bimodal actuator (chapter 3).
- :mod:`pneumorph.export` - STL parts, casting moulds and CalculiX decks;
  :mod:`pneumorph.correlation` - scans against the model.
- :mod:`pneumorph.sensitivity` - how much to trust a design: the modelling simplifications
  and sensitivities of appendices D and E, and robustness to mould tolerances.
- :mod:`pneumorph.io` - safe writing, VTK and provenance; :mod:`pneumorph.checks` - the
  checks of settings and the limits; :mod:`pneumorph.errors` - the exceptions.

Examples
--------
>>> import pneumorph
>>> pneumorph.__version__
'0.1.0'
"""

from importlib.metadata import PackageNotFoundError, version

try:
    #: The installed package's version.
    __version__ = version("pneumorph")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]

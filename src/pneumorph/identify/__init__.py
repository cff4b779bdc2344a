"""Model identification from scans of cast actuators (``pneumorph identify``, docs/identify.md).

Read the scans and check them against their designs (:func:`read_manifest`,
:func:`load_scans`), fit the body silicone's bulk and shear modulus scales and the three
mould thicknesses of Fig E.4 by least squares on the correlation distances, holding the
combinations the scans do not determine (:func:`identify`, :func:`directions`), weigh the
further scans that would determine them (:func:`candidates`, :mod:`pneumorph.identify.advice`),
and write the identified model as a ``[model]`` table that ``design``
and ``simulate`` take (:func:`identified_toml`).
"""

from pneumorph.identify.advice import candidates
from pneumorph.identify.extent import chain_shape, chain_shapes, rigid_units
from pneumorph.identify.fit import (
    MAX_DIRECTION_ERROR,
    MAX_ITERATIONS,
    MAX_POINTS,
    MAX_SHARE,
    MIN_EIGENVALUE,
    Identification,
    Observation,
    build_probes,
    identify,
    precheck_designs,
)
from pneumorph.identify.linear import Directions, directions
from pneumorph.identify.parameters import NAMES, SPANS, STEPS, ParameterSet, parameter_indices
from pneumorph.identify.probe import SHAPE_REVISION, ShapeProbe, shape_of
from pneumorph.identify.result import identified_toml, write_identified
from pneumorph.identify.scans import MAX_SCANS, SCAN_KEYS, ScanSpec, load_scans, read_manifest

__all__ = [
    "MAX_DIRECTION_ERROR",
    "MAX_ITERATIONS",
    "MAX_POINTS",
    "MAX_SCANS",
    "MAX_SHARE",
    "MIN_EIGENVALUE",
    "NAMES",
    "SCAN_KEYS",
    "SHAPE_REVISION",
    "SPANS",
    "STEPS",
    "Directions",
    "Identification",
    "Observation",
    "ParameterSet",
    "ScanSpec",
    "ShapeProbe",
    "build_probes",
    "candidates",
    "chain_shape",
    "chain_shapes",
    "directions",
    "identified_toml",
    "identify",
    "load_scans",
    "parameter_indices",
    "precheck_designs",
    "read_manifest",
    "rigid_units",
    "shape_of",
    "write_identified",
]

"""Scan correlation: an inflated actuator's scan or photo against the model (section 6.5, 8.5).

Read a scan (:func:`read_scan`), take the model's deformed shape (:func:`model_shape`),
align and measure (:func:`correlate`), draw (:func:`plot_correlation`); all of it for a design,
from its solve to a written folder (:func:`correlate_design`). A synthetic scan of a cast that
differs from the model (:func:`cast_settings`, :func:`synthetic_scan`, :func:`write_scan`) tries
the loop before a real cast.
"""

from pneumorph.correlation.align import Alignment, Transform, fit_transform, icp
from pneumorph.correlation.compare import Correlation, Measure, ModelShape, correlate, model_shape
from pneumorph.correlation.figures import plot_correlation
from pneumorph.correlation.scans import SCAN_UNITS, Scan, read_scan
from pneumorph.correlation.synthetic import CAST_SCALES, ScanNoise, cast_settings, synthetic_scan, write_scan
from pneumorph.correlation.workflow import correlate_design

__all__ = [
    "CAST_SCALES",
    "SCAN_UNITS",
    "Alignment",
    "Correlation",
    "Measure",
    "ModelShape",
    "Scan",
    "ScanNoise",
    "Transform",
    "cast_settings",
    "correlate",
    "correlate_design",
    "fit_transform",
    "icp",
    "model_shape",
    "plot_correlation",
    "read_scan",
    "synthetic_scan",
    "write_scan",
]

"""The fast path: FE systems assembled straight into a fixed sparse pattern, and their Newton method.

The reference path is FElupe's own assembly and ``newtonraphson``
(:class:`pneumorph.fem.stepping.FElupeSubstep`); this one solves the same equations to the
same criterion, an order of magnitude faster:

- :mod:`~pneumorph.fem.fast.system` - :class:`FastSystem`, the one assembler, with its
  plane-strain and 3D hooks (:class:`PlaneStrainSystem`, :class:`SolidSystem3D`);
- :mod:`~pneumorph.fem.fast.kernels` - constitutive kernels with the quadrature points last;
- :mod:`~pneumorph.fem.fast.loads` - dead loads as one nodal vector;
- :mod:`~pneumorph.fem.fast.shapes` - rigid obstacles' geometry (:class:`Plane`, :class:`Cylinder`,
  :class:`Sphere`): gap, normal, curvature;
- :mod:`~pneumorph.fem.fast.contact` - those obstacles against a body's surface nodes, a penalty owner of
  the assembler (:class:`RigidContact`);
- :mod:`~pneumorph.fem.fast.newton` - :class:`FastSubstep`, Newton's method on a system
  (kept factorised tangents, Anderson acceleration), a substep strategy of
  :func:`pneumorph.fem.ramp`;
- :mod:`~pneumorph.fem.fast.volume` - :class:`VolumeControl`, the volume-controlled substeps
  (the cavities' volume drives, the pressure is an unknown and passes its maximum).
"""

from pneumorph.fem.fast.contact import RigidContact
from pneumorph.fem.fast.loads import DeadLoads
from pneumorph.fem.fast.newton import FastSubstep, pattern_solver
from pneumorph.fem.fast.shapes import Cylinder, Plane, Sphere
from pneumorph.fem.fast.system import FastSystem, PlaneStrainSystem, SolidSystem3D
from pneumorph.fem.fast.volume import VolumeControl, volume_control

__all__ = ["Cylinder", "DeadLoads", "FastSubstep", "FastSystem", "Plane", "PlaneStrainSystem", "RigidContact",
           "SolidSystem3D", "Sphere", "VolumeControl", "pattern_solver", "volume_control"]

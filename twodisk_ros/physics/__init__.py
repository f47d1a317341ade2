"""The physics of the rolling two-disk body: pure numpy/scipy, no ROS, plots or files.

One subpackage per concept, each importing only those below it (the physics layers of
.importlinter, checked by the tests; docs/architecture.md); docs/physics.md derives each:

- :mod:`.scenes`: the ground, gravity, drive and dissipation, and a body's motion in them;
- :mod:`.forces`: the contact forces at A and B, and where the rolling model holds;
- :mod:`.motion`: the equation of motion in the phase u on a level plane, and u(t);
- :mod:`.stability`: the equilibria and their stability; :mod:`.mass`: the mass models;
- :mod:`.bodies`: the rolling bodies (the ellipse in closed form, any two laminae through
  their contact solver) and their poses over whole cycles;
- :mod:`.laminae`: the planar laminae (ellipse, superellipse, egg, a fitted outline);
- :mod:`.numerics`: the spectral, table and analytic tools they share.

The names below are the library's public API (also importable from :mod:`twodisk_ros`).
"""

from .bodies.cycle import CycleDisplacement, RollingCycle, RollingState, integrate_contact_trace
from .bodies.ellipse import EllipseBody, PhaseGeometry
from .mass.models import MassProperties, mass_properties
from .motion.dynamics import RollingDynamics
from .motion.simulate import MotionStream, RollingMotion, simulate, simulate_phase
from .stability.equilibria import Equilibrium, equilibria, stability_map

#: The ellipse body's former name (the same class), so that existing scripts run.
TwoDiskBody = EllipseBody

__all__ = [
    'EllipseBody', 'TwoDiskBody', 'PhaseGeometry', 'RollingCycle', 'RollingState', 'CycleDisplacement',
    'integrate_contact_trace', 'Equilibrium', 'equilibria', 'stability_map', 'MassProperties',
    'mass_properties', 'RollingDynamics', 'RollingMotion', 'MotionStream', 'simulate',
    'simulate_phase',
]

"""The physics of the rolling two-disk body: pure numpy/scipy, no ROS, plots or files.

Modules, from geometry to motion (docs/physics.md derives each):

- :mod:`~twodisk_ros.physics.body`: the body and the closed forms, in θ and in the phase u
  (:mod:`~twodisk_ros.physics.body_batch`: the same closed forms for many bodies at once);
- :mod:`~twodisk_ros.physics.cycle`: poses and contact traces over whole cycles;
- :mod:`~twodisk_ros.physics.equilibria`: the eight equilibria and their stability;
- :mod:`~twodisk_ros.physics.mass_models` (with :mod:`~twodisk_ros.physics.hull`): inertia;
- :mod:`~twodisk_ros.physics.dynamics`: the equation of motion in u;
- :mod:`~twodisk_ros.physics.solvers`, :mod:`~twodisk_ros.physics.motion`: u(t);
- :mod:`~twodisk_ros.physics.startup`: what a body's tables will cost, before paying it;
- :mod:`~twodisk_ros.physics.lamina` (with :mod:`~twodisk_ros.physics.lamina_fit`): laminae
  of any symmetric convex shape (ellipse, superellipse, egg, a fitted outline): the
  foundation of general bodies, with :mod:`~twodisk_ros.physics.general_body` (their
  contact geometry from the support function) and
  :mod:`~twodisk_ros.physics.symmetric_stability` (the stability of their symmetric
  equilibria in closed form); :mod:`~twodisk_ros.physics.lamina_body` makes them rolling
  bodies (:mod:`~twodisk_ros.physics.rolling_body`: the protocol the cycle, dynamics, forces
  and equilibria read, which :class:`TwoDiskBody` implements with its closed forms);
- :mod:`~twodisk_ros.physics.analytic`, :mod:`~twodisk_ros.physics.spectral`,
  :mod:`~twodisk_ros.physics.tables`, :mod:`~twodisk_ros.physics.vectors`: the numerical
  tools they share.
"""

from .body import PhaseGeometry, TwoDiskBody
from .cycle import CycleDisplacement, RollingCycle, RollingState, integrate_contact_trace
from .dynamics import RollingDynamics
from .equilibria import Equilibrium, equilibria, stability_map
from .mass_models import MassProperties, mass_properties
from .motion import MotionStream, RollingMotion, simulate, simulate_phase

__all__ = [
    'TwoDiskBody', 'PhaseGeometry', 'RollingCycle', 'RollingState', 'CycleDisplacement',
    'integrate_contact_trace', 'Equilibrium', 'equilibria', 'stability_map', 'MassProperties',
    'mass_properties', 'RollingDynamics', 'RollingMotion', 'MotionStream', 'simulate',
    'simulate_phase',
]

"""twodisk_ros: rolling of a rigid body made of two elliptic disks in perpendicular planes.

The physics (``body``, ``cycle``, ``equilibria``, ``mass_models``, ``dynamics``) is pure
numpy/scipy and imports without rclpy; ``roller`` is the ROS 2 node, ``recording`` the MCAP
layer and ``inspect_mcap`` the offline checker.
"""

from .body import PhaseGeometry, TwoDiskBody
from .cycle import CycleDisplacement, RollingCycle, RollingState, integrate_contact_trace
from .dynamics import RollingDynamics, RollingMotion, simulate
from .equilibria import Equilibrium, equilibria, stability_map
from .mass_models import MassProperties, mass_properties

__version__ = '0.1.0'

__all__ = [
    'TwoDiskBody', 'PhaseGeometry', 'RollingCycle', 'RollingState', 'CycleDisplacement',
    'integrate_contact_trace', 'Equilibrium', 'equilibria', 'stability_map', 'MassProperties',
    'mass_properties', 'RollingDynamics', 'RollingMotion', 'simulate', '__version__',
]

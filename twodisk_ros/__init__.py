"""twodisk_ros: a rigid body of two congruent symmetric laminae (ellipses, superellipses,
eggs, any convex outline) in perpendicular planes, rolling without slipping on a plane.

Folders are the architecture, in layers (README "Layout"; enforced by import-linter,
``.importlinter``), each importing only the ones below it:

- :mod:`twodisk_ros.node` (the ``roller`` node, the only rclpy layer),
  :mod:`twodisk_ros.view` (``twodisk-view``), :mod:`twodisk_ros.sweep` (``twodisk-sweep``);
- :mod:`twodisk_ros.plotting`: figures and animations (matplotlib);
- :mod:`twodisk_ros.inspector`: ``twodisk-inspect``, the offline checks of a recording;
  :mod:`twodisk_ros.runs`: runs to show;
- :mod:`twodisk_ros.run`: the parameters, the body they describe and its simulation;
- :mod:`twodisk_ros.recordings`: MCAP recordings in rosbag2's layout (writer and tolerant reader);
  :mod:`twodisk_ros.model`: the body as a robot description (frames, meshes, URDF);
- :mod:`twodisk_ros.physics`: the bodies, their cycles, equilibria, mass models and dynamics
  (numpy/scipy only).

The physics is re-exported here (imported on first use):
``from twodisk_ros import EllipseBody, simulate`` (``TwoDiskBody``, the ellipse body's former
name, is the same class).
"""

import importlib

_PHYSICS = ('CycleDisplacement', 'EllipseBody', 'Equilibrium', 'MassProperties', 'PhaseGeometry',
            'RollingCycle', 'RollingDynamics', 'RollingMotion', 'RollingState', 'TwoDiskBody',
            'equilibria', 'integrate_contact_trace', 'mass_properties', 'simulate',
            'stability_map')


def __getattr__(name):
    """The physics names, imported on first use (``python -m twodisk_ros.roller`` starts
    without numpy, so its signal handlers are in place within milliseconds)."""
    if name in _PHYSICS:
        return getattr(importlib.import_module('.physics', __name__), name)
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')


__version__ = '0.1.0'

__all__ = [
    'EllipseBody', 'TwoDiskBody', 'PhaseGeometry', 'RollingCycle', 'RollingState',
    'CycleDisplacement', 'integrate_contact_trace', 'Equilibrium', 'equilibria', 'stability_map', 'MassProperties',
    'mass_properties', 'RollingDynamics', 'RollingMotion', 'simulate', '__version__',
]

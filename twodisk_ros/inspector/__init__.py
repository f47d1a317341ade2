"""``twodisk-inspect``: offline checks of a ``roller`` recording (no rclpy needed).

- :mod:`~twodisk_ros.inspector.series`: messages → time series and joined samples;
- :mod:`~twodisk_ros.inspector.model`: the body the recorded parameters describe;
- :mod:`~twodisk_ros.inspector.differences`: velocities and accelerations of the recorded poses;
- :mod:`~twodisk_ros.inspector.checks`: the checks and their tolerances;
- :mod:`~twodisk_ros.inspector.forces`, :mod:`~twodisk_ros.inspector.force_checks`: contact forces
  from the poses (Newton–Euler) against the recorded wrenches, and the model's validity;
- :mod:`~twodisk_ros.inspector.tf_check`: the body frame on /tf against the poses, bit for bit;
- :mod:`~twodisk_ros.inspector.inspection`: :func:`inspect_recording`;
- :mod:`~twodisk_ros.inspector.status`: the verdicts and the exit status of each;
- :mod:`~twodisk_ros.inspector.report`, :mod:`~twodisk_ros.inspector.figure`,
  :mod:`~twodisk_ros.inspector.export`, :mod:`~twodisk_ros.inspector.cli`: the report, the figure
  (``--plot``, matplotlib), the exported states, the command line.
"""

import importlib

__all__ = ['Check', 'Inspection', 'finite_differences', 'format_report', 'inspect_recording']

#: public name → the module that defines it, imported on first use (PEP 562), so that
#: ``twodisk-inspect --help`` does not pay for numpy, scipy and the physics.
_HOMES = {'finite_differences': 'differences', 'inspect_recording': 'inspection',
          'format_report': 'report', 'Check': 'results', 'Inspection': 'results'}


def __getattr__(name):
    if name in _HOMES:
        return getattr(importlib.import_module(f'.{_HOMES[name]}', __name__), name)
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')

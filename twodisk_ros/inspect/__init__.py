"""``twodisk-inspect``: offline checks of a ``roller`` recording (no rclpy needed).

- :mod:`~twodisk_ros.inspect.series`: messages → time series and joined samples;
- :mod:`~twodisk_ros.inspect.model`: the body the recorded parameters describe;
- :mod:`~twodisk_ros.inspect.differences`: velocities and accelerations of the recorded poses;
- :mod:`~twodisk_ros.inspect.checks`: the checks and their tolerances;
- :mod:`~twodisk_ros.inspect.forces`, :mod:`~twodisk_ros.inspect.force_checks`: contact forces
  from the poses (Newton–Euler) against the recorded wrenches, and the model's validity;
- :mod:`~twodisk_ros.inspect.tf_check`: the body frame on /tf against the poses, bit for bit;
- :mod:`~twodisk_ros.inspect.inspection`: :func:`inspect_recording`;
- :mod:`~twodisk_ros.inspect.report`, :mod:`~twodisk_ros.inspect.cli`: output, command line.
"""

from .differences import finite_differences
from .inspection import inspect_recording
from .report import format_report
from .results import Check, Inspection

__all__ = ['Check', 'Inspection', 'finite_differences', 'format_report', 'inspect_recording']

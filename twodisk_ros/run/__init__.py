"""The run: its parameters, the body they describe, and its simulation, below the node.

ROS-free (no rclpy): the node (:mod:`twodisk_ros.node`), the inspector
(:mod:`~twodisk_ros.inspector.model`), the viewer, the sweeps and the animation read it, so
that they all build the same body from the same settings.

- :mod:`~twodisk_ros.run.parameters`: the parameter contract (names, types, units, ranges);
- :mod:`~twodisk_ros.run.params_yaml`: the one bounded loader of parameter files and ``-p``
  values, typed as rcl types them;
- :mod:`~twodisk_ros.run.shape`: the lamina the settings name (``shape``, ``exponent``,
  ``egg_asymmetry``, ``shape_file``), read and checked; a fitted outline in a recording's
  metadata;
- :mod:`~twodisk_ros.run.description`: :class:`~twodisk_ros.run.description.RunDescription`,
  the body (EllipseBody for ellipses, LaminaBody otherwise), its mass model, dynamics and
  motion stream, and the recording's metadata;
- :mod:`~twodisk_ros.run.simulation`, :mod:`~twodisk_ros.run.scene_simulation`: the
  settings' physics objects and the samples they give;
- :mod:`~twodisk_ros.run.schedule`: the sample schedule, tick → time and stamp.

Nothing is imported here: :mod:`~twodisk_ros.run.parameters` imports
:mod:`~twodisk_ros.run.shape`, and the description imports the parameters.
"""

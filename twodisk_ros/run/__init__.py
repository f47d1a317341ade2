"""The description of a run: settings → lamina, body, mass model, dynamics and motion.

One place that the node (:mod:`~twodisk_ros.node.simulation`), the inspector
(:mod:`~twodisk_ros.inspect.model`), the sweeps and the animation read, so that they all build
the same body from the same settings. ROS-free.

- :mod:`~twodisk_ros.run.shape`: the lamina the settings name (``shape``, ``exponent``,
  ``egg_asymmetry``, ``shape_file``), read and checked; a fitted outline in a recording's
  metadata;
- :mod:`~twodisk_ros.run.description`: :class:`~twodisk_ros.run.description.RunDescription`,
  the body (TwoDiskBody for ellipses, LaminaBody otherwise), its mass model, dynamics and
  motion stream, and the recording's metadata.

Nothing is imported here: :mod:`twodisk_ros.node.parameters` imports
:mod:`~twodisk_ros.run.shape`, and the description imports the parameters.
"""

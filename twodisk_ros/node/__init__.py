"""The ``roller`` node: parameters, the simulation they build, and the messages it publishes.

- :mod:`~twodisk_ros.node.parameters`: the parameter contract (names, types, ranges);
- :mod:`~twodisk_ros.node.usage`: ``--help``, ``--version``, arguments outside ``--ros-args``
  (standard library and PyYAML only, before any heavy import);
- :mod:`~twodisk_ros.node.params_yaml`: the one bounded loader of parameter files and ``-p``
  values, typed as rcl types them;
- :mod:`~twodisk_ros.node.arguments`: the command line checked before rclpy parses it;
- :mod:`~twodisk_ros.node.simulation`: the settings and the physics objects (no rclpy);
- :mod:`~twodisk_ros.node.schedule`: the sample schedule, tick → time and stamp (no rclpy;
  ``twodisk-view`` uses it too);
- :mod:`~twodisk_ros.node.messages`: physics states → ROS 2 messages;
- :mod:`~twodisk_ros.node.roller`: the rclpy node and ``main``.
"""

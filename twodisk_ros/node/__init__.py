"""The ``roller`` node: the rclpy layer that turns the run's physics states into messages.

The run itself (parameters, their files, the simulation and the sample schedule) is
:mod:`twodisk_ros.run`, below the node and free of rclpy.

- :mod:`~twodisk_ros.node.usage`: ``--help``, ``--version``, arguments outside ``--ros-args``
  (standard library and PyYAML only, before any heavy import);
- :mod:`~twodisk_ros.node.arguments`: the command line checked before rclpy parses it;
- :mod:`~twodisk_ros.node.descriptors`: the parameters as ROS parameter descriptors;
- :mod:`~twodisk_ros.node.messages`: physics states → ROS 2 messages;
- :mod:`~twodisk_ros.node.roller`: the rclpy node; :mod:`~twodisk_ros.node.main`: ``main``.
"""

"""The ``roller`` node: parameters, the simulation they build, and the messages it publishes.

- :mod:`~twodisk_ros.node.simulation`: the settings and the physics objects (no rclpy);
- :mod:`~twodisk_ros.node.messages`: physics states → ROS 2 messages;
- :mod:`~twodisk_ros.node.roller`: the rclpy node and ``main``.
"""

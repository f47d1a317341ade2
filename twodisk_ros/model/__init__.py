"""The body as a robot description: disk frames, meshes and a URDF (no ROS, no plots).

- :mod:`~twodisk_ros.model.frames`: the two disk frames relative to the body frame;
- :mod:`~twodisk_ros.model.mesh`: triangle meshes of the laminae and of the solid hull;
- :mod:`~twodisk_ros.model.stl`: binary STL, and the content-addressed mesh cache;
- :mod:`~twodisk_ros.model.urdf`: the URDF published on ``robot_description``.
"""

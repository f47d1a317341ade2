"""The body as a robot description: disk frames, meshes and a URDF (no ROS, no matplotlib).

Any body: a EllipseBody (ellipses) or a LaminaBody (any lamina); the frames also a
ContactSolver. The outlines every drawer takes its rims from and the hull's rulings are the
bodies' (:mod:`~twodisk_ros.physics.bodies.outline`, :mod:`~twodisk_ros.physics.bodies.rulings`).

- :mod:`~twodisk_ros.model.frames`: the two disk frames relative to the body frame, and the
  rims placed in them (:func:`~twodisk_ros.model.frames.disk_rims`);
- :mod:`~twodisk_ros.model.mesh`: triangle meshes of the laminae and of the solid hull;
- :mod:`~twodisk_ros.model.stl`: binary STL, and the content-addressed mesh cache;
- :mod:`~twodisk_ros.model.urdf`: the URDF published on ``robot_description``;
- :mod:`~twodisk_ros.model.palette`: the colours of the body, its contacts and forces in
  every picture and marker (plain hex strings).
"""

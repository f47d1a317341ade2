"""The body as a robot description: disk frames, meshes and a URDF (no ROS, no matplotlib).

Any body: a EllipseBody (ellipses), a LaminaBody or a ContactSolver (any lamina).

- :mod:`~twodisk_ros.model.outline`: the laminae's outlines as polygons of a stated error,
  where every drawer (meshes, markers, Foxglove, animation) takes its rims;
- :mod:`~twodisk_ros.model.rulings`: the solid hull of any lamina from its exact rulings;
- :mod:`~twodisk_ros.model.frames`: the two disk frames relative to the body frame, and the
  rims placed in them (:func:`~twodisk_ros.model.frames.disk_rims`);
- :mod:`~twodisk_ros.model.mesh`: triangle meshes of the laminae and of the solid hull;
- :mod:`~twodisk_ros.model.stl`: binary STL, and the content-addressed mesh cache;
- :mod:`~twodisk_ros.model.urdf`: the URDF published on ``robot_description``;
- :mod:`~twodisk_ros.model.palette`: the colours of the body, its contacts and forces in
  every picture and marker (plain hex strings).
"""

"""The free rigid body of ``contact_model:=hybrid`` in MuJoCo (issue 31): no ROS, no plots.

When exact rolling stops holding (a contact would pull on the ground, or needs more friction
than μ), the body goes on as a free rigid body with unilateral contacts and Coulomb friction
in MuJoCo; when it rolls again it is mapped back to the nearest rolling state.

- :mod:`~twodisk_ros.engine.model`: the MJCF of a body (its plates or hull, its mass model,
  μ and the contact parameters, :class:`~twodisk_ros.engine.model.ContactParameters`);
- :mod:`~twodisk_ros.engine.state`: rolling state (u, w, heading, shift) ↔ MuJoCo's
  (qpos, qvel), and the nearest rolling state with its mismatch;
- :mod:`~twodisk_ros.engine.run`: steps the engine from a state, sampled at given times,
  with the contact status of each disk per sample.

Imports the physics and the model (meshes), never the run or the node (.importlinter).
"""

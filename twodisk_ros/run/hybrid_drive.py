"""The torque drive on the hybrid's engine body (issue 31; run/hybrid.py): no ROS here.

The scenes' torque drive is a moment τ ê about the instantaneous axis AB, ê the unit vector
from A to B signed so that ω_u · ê > 0 (docs/physics.md "Scenes": positive in the sense of
ω for increasing u). The free body has no contact line of its own; the drive acts about the
AB of the rolling pose whose ground normal is closest to the engine's (the phase the engine
samples publish, to 2π/:data:`~twodisk_ros.run.hybrid.PHASE_GRID`): M = τ R ê(u), R the
orientation body → world. While the body rolls in the engine (both disks down) that is the
line through its contacts, as in rolling; in the air it is the body-fixed line the contacts
will land on. The speed drive holds a rolling speed, which a free body does not have: in an
engine stretch its motor applies nothing (the body is free), and on the return to rolling
the speed follows the command again from the returned speed with the drive's lag.
"""

import numpy as np

__all__ = ['DriveMoment']


class DriveMoment:
    """M = τ R ê(u) (N m, world) for the engine (:meth:`~twodisk_ros.engine.run.Engine.
    set_moment`), ê over a grid of phases ``cycle`` (rad) whose ground normals are
    ``normals`` (body frame, (n, 3)); τ (N m)."""

    def __init__(self, body, cycle, normals, torque):
        r1, r2 = (np.real(x) for x in body.phase_vectors(cycle)[:2])
        axis = r2 - r1
        axis /= np.linalg.norm(axis, axis=1)[:, None]
        sense = np.einsum('ij,ij->i', body.phase_angular_velocity(cycle), axis)
        self.axes = np.where(sense[:, None] >= 0, axis, -axis)
        self.normals, self.torque = normals, float(torque)

    def __call__(self, qpos, rotation):
        """The moment (3,) (N m, world) at the engine's state (rotation body → world)."""
        k = int(np.argmax(self.normals @ rotation[2]))
        return self.torque * (rotation @ self.axes[k])

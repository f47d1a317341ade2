"""The rolling stretches of the hybrid motion (run/hybrid.py): exact rolling from a state,
free on level ground (:class:`FreeRolling`: the package's MotionStream, the level ground's
contact forces) or in a scene (:class:`SceneRolling`: a slope, viscous damping c, a speed or
torque drive; the scene's stream, closed forms where they hold, and its ground forces from
(u, w, ẇ)); :func:`rolling_source` picks the one of a scene.

Each is placed in the slope frame S (the engine's world; on level ground the world itself)
by a heading φ0 (rad, about the normal: the cycle frame turned by it) and gives, at times
from the stretch's start (s): the state (u rad, u̇ rad/s, w rad/s, ẇ rad/s² or None) with
the work W (J) done against the damping and the drive's work W_d (J) since the stretch's
start; ``drive`` (the scene's drive and command: 'none', 'speed' rad/s or 'torque' N m); the
poses (G, A, B in the
published world frame, m, and the orientation body → world, quaternions x, y, z, w) and the
ground's forces (N, the same frame) at states; the energy E = ½ J w² + V (J), V = M g × G's
height along gravity (the scene's origin: A at u = 0 of the stretch's placement).
"""

from copy import copy
import math

import numpy as np

from ..physics.motion.simulate import MotionStream
from ..physics.scenes.motion import SceneStream, scene_stream

__all__ = ['FreeRolling', 'LOOKAHEAD', 'SceneRolling', 'rolling_source']

#: s: a scene's stream restarted in the hybrid (a return, a command) integrates this far
#: beyond the times asked (the run's first stream: the scene's 0.5 s), as a stretch often
#: ends soon: DOP853 past a switch is wasted (a command that slips at once: 0.5 s of it)
LOOKAHEAD = 0.05


def rolling_source(dynamics, model, terms, scene, u, w, yaw, method, tolerance):
    """The rolling stretch of ``scene`` from (u rad, w rad/s) placed at heading ``yaw`` (rad):
    :class:`FreeRolling` for the flat free scene, else :class:`SceneRolling` of ``terms``
    (SceneTerms of the same slope; turned to yaw) with ``scene``'s drive and dissipation."""
    if scene.flat_free:
        stream = MotionStream(dynamics, u, dynamics.initial_phase_rate(u, w), method=method,
                              tolerance=tolerance, angular_speed=w)
        return FreeRolling(dynamics, model, stream, yaw)
    placed = copy(terms)
    placed.scene = scene
    if yaw != terms.phi0:
        placed = placed.turned(yaw)
    if scene.drive == 'speed':     # (W_d tracked also at a constant command: SceneMotion's)
        stream = SceneStream(placed, u, None, tolerance=tolerance, angular_speed=w,
                             lookahead=LOOKAHEAD)
    else:
        stream = scene_stream(dynamics, placed.scene, u, None, method=method,
                              tolerance=tolerance, terms=placed, angular_speed=w,
                              lookahead=LOOKAHEAD)
    return SceneRolling(dynamics, placed, stream, u, w, model)


def _yaw_matrix(yaw):
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _times_quaternion(yaw, q):
    """q_z(yaw) ⊗ q for quaternions q (n, 4) x, y, z, w."""
    c, s = math.cos(0.5 * yaw), math.sin(0.5 * yaw)
    x, y, z, w = q.T
    return np.stack([c * x - s * y, c * y + s * x, c * z + s * w, c * w - s * z], axis=1)


class FreeRolling:
    """Free rolling on level ground from ``stream`` (a MotionStream), forces of ``model``
    (ContactForceModel, free motion), placed at heading ``yaw`` (rad): exactly the rolling
    run's at yaw 0."""

    slope = 0.0
    drive = ('none', 0.0)

    def __init__(self, dynamics, model, stream, yaw=0.0):
        self.dynamics, self.model, self.stream = dynamics, model, stream
        self.yaw = float(yaw)
        self.initial_energy = stream.initial_energy

    @property
    def window_start(self):
        """The earliest time (s) :meth:`state_at` answers (the latest call's first piece)."""
        return self.stream.window[0]

    def states(self, t):
        """(u, u̇, w, None, W = 0, W_d = 0) at times t (s, increasing, after earlier calls)."""
        u, u_dot, w = self.stream.sample_with_speed(t)
        zero = np.zeros(len(u))
        return u, u_dot, w, None, zero, zero

    def state_at(self, t):
        """(u, u̇, w, None, W = 0, W_d = 0) at times t (s) of the dense solution's window."""
        u, u_dot, w = self.stream.state_at(t)
        zero = np.zeros(len(u))
        return u, u_dot, w, None, zero, zero

    def poses(self, u):
        """(G, A, B, q) at phases u, turned by the heading."""
        poses = self.dynamics.cycle.poses(u)
        rz = _yaw_matrix(self.yaw)
        return (poses.position_g @ rz.T, poses.contact_a @ rz.T, poses.contact_b @ rz.T,
                _times_quaternion(self.yaw, poses.quaternion))

    def forces(self, u, u_dot, w, w_dot):
        """The ground's forces at the states (the free motion's, from u and w; the cycle
        frame's vectors: :meth:`world_forces`)."""
        return self.model.dynamic(u, angular_speed=w)

    def world_forces(self, forces):
        """(F_A, F_B) (N, world) of :meth:`forces`' result: turned by the heading."""
        rz = _yaw_matrix(self.yaw)
        return forces.force_a @ rz.T, forces.force_b @ rz.T

    def energy(self, u, w):
        """E (J) at the states."""
        return self.dynamics.energy_turning(u, w)

    def restart(self, u, w, yaw, method, tolerance):
        """The same rolling from the state (u rad, w rad/s) at heading yaw (rad)."""
        stream = MotionStream(self.dynamics, u, self.dynamics.initial_phase_rate(u, w),
                              method=method, tolerance=tolerance, angular_speed=w)
        return FreeRolling(self.dynamics, self.model, stream, yaw)


class SceneRolling:
    """Rolling in a scene from ``stream`` (of ``terms``, SceneTerms of a slope β, damping c,
    a speed or torque drive; ``model`` the level ground's ContactForceModel, for a restart in
    a flat free scene): its poses (``terms.poses``: the slope frame turned by the terms' φ0,
    then tilted to the gravity frame), forces (from u, w, ẇ: finite also where the body stops
    turning in u), energy (the scene's V) and work W. A restart at another heading takes the
    terms turned to it (:meth:`~twodisk_ros.physics.scenes.terms.SceneTerms.turned`)."""

    #: the bisection stays within the times of the latest :meth:`states` call: its window
    window_start = -np.inf

    def __init__(self, dynamics, terms, stream, u0, w0, model=None):
        self.dynamics, self.terms, self.stream, self.model = dynamics, terms, stream, model
        self.yaw, self.slope = terms.phi0, terms.scene.slope
        scene = terms.scene
        self.drive = (scene.drive, scene.command if scene.drive != 'none' else 0.0)
        self.initial_energy = float(terms.energy_turning(u0, w0))

    @staticmethod
    def _unpack(s):
        return (s.phase, s.phase_rate, s.rolling_speed, s.angular_acceleration,
                np.asarray(s.dissipated, dtype=float), np.asarray(s.drive_work, dtype=float))

    def states(self, t):
        """(u, u̇, w, ẇ, W, W_d) at times t (s, increasing, after earlier calls)."""
        return self._unpack(self.stream.samples(np.asarray(t, dtype=float)))

    def state_at(self, t):
        """(u, u̇, w, ẇ, W, W_d) at times t (s) within the latest call's window."""
        return self._unpack(self.stream.samples_at(np.asarray(t, dtype=float)))

    def poses(self, u):
        """(G, A, B, q) at phases u (the scene's poses in the gravity frame)."""
        return self.terms.poses(u)

    def forces(self, u, u_dot, w, w_dot):
        """The ground's forces (SceneForces, gravity frame) at the states, from (u, w, ẇ)."""
        return self.terms.forces(u, w, w_dot, turning=True)

    @staticmethod
    def world_forces(forces):
        """(F_A, F_B) (N, world) of :meth:`forces`' result (already the gravity frame's)."""
        return forces.force_a, forces.force_b

    def energy(self, u, w):
        """E = ½ J w² + V (J) at the states."""
        return self.terms.energy_turning(u, w)

    def restart(self, u, w, yaw, method, tolerance):
        """The same scene from the state (u rad, w rad/s) at heading yaw (rad): its closed
        forms where they hold (a slope without damping or drive), else DOP853; a speed drive
        starts again from w towards its command (Ω = cmd + (w − cmd) e^(−t/T))."""
        return rolling_source(self.dynamics, self.model, self.terms, self.terms.scene, u, w,
                              yaw, method, tolerance)

"""The rolling stretches of the hybrid motion (run/hybrid.py): exact rolling from a state, on
level ground, free (:class:`FreeRolling`: the package's MotionStream, the level ground's
contact forces) or with viscous damping c (:class:`DampedRolling`: the scene's DOP853
stream and its ground forces, SceneTerms with damping). Both give, at times from the
stretch's start (s): the state (u rad, u̇ rad/s, w rad/s, ẇ rad/s² or None) with the work
W (J) done against the damping since the stretch's start, the ground's forces at states, and
the energy E = ½ J w² + M g z_G (J).
"""

import numpy as np

from ..physics.motion.simulate import MotionStream
from ..physics.scenes.motion import SceneStream

__all__ = ['DampedRolling', 'FreeRolling']


class FreeRolling:
    """Free rolling on level ground from ``stream`` (a MotionStream), forces of ``model``
    (ContactForceModel, free motion): exactly the rolling run's."""

    def __init__(self, dynamics, model, stream):
        self.dynamics, self.model, self.stream = dynamics, model, stream
        self.initial_energy = stream.initial_energy

    @property
    def window_start(self):
        """The earliest time (s) :meth:`state_at` answers (the latest call's first piece)."""
        return self.stream.window[0]

    def states(self, t):
        """(u, u̇, w, None, W = 0) at times t (s, increasing, after earlier calls)."""
        u, u_dot, w = self.stream.sample_with_speed(t)
        return u, u_dot, w, None, np.zeros(len(u))

    def state_at(self, t):
        """(u, u̇, w, None, W = 0) at times t (s) of the dense solution's window."""
        u, u_dot, w = self.stream.state_at(t)
        return u, u_dot, w, None, np.zeros(len(u))

    def forces(self, u, u_dot, w, w_dot):
        """The ground's forces at the states (the free motion's, from u and w)."""
        return self.model.dynamic(u, angular_speed=w)

    def energy(self, u, w):
        """E (J) at the states."""
        return self.dynamics.energy_turning(u, w)

    def restart(self, u, w, method, tolerance):
        """The same rolling from the state (u rad, w rad/s)."""
        stream = MotionStream(self.dynamics, u, self.dynamics.initial_phase_rate(u, w),
                              method=method, tolerance=tolerance, angular_speed=w)
        return FreeRolling(self.dynamics, self.model, stream)


class DampedRolling:
    """Rolling on level ground with the viscous torque −c ω from ``stream`` (a SceneStream of
    ``terms``, SceneTerms of the level ground with damping c): its forces (from u, w, ẇ:
    finite also where the body stops turning in u) and its work W."""

    #: the bisection stays within the times of the latest :meth:`states` call: its window
    window_start = -np.inf

    def __init__(self, dynamics, terms, stream, u0, w0):
        self.dynamics, self.terms, self.stream = dynamics, terms, stream
        self.initial_energy = float(dynamics.energy_turning(u0, w0))

    @staticmethod
    def _unpack(s):
        return (s.phase, s.phase_rate, s.rolling_speed, s.angular_acceleration,
                np.asarray(s.dissipated, dtype=float))

    def states(self, t):
        """(u, u̇, w, ẇ, W) at times t (s, increasing, after earlier calls)."""
        return self._unpack(self.stream.samples(np.asarray(t, dtype=float)))

    def state_at(self, t):
        """(u, u̇, w, ẇ, W) at times t (s) within the latest call's window."""
        return self._unpack(self.stream.samples_at(np.asarray(t, dtype=float)))

    def forces(self, u, u_dot, w, w_dot):
        """The ground's forces (SceneForces) at the states, from (u, w, ẇ)."""
        return self.terms.forces(u, w, w_dot, turning=True)

    def energy(self, u, w):
        """E (J) at the states."""
        return self.dynamics.energy_turning(u, w)

    def restart(self, u, w, method, tolerance):
        """The same rolling from the state (u rad, w rad/s)."""
        stream = SceneStream(self.terms, u, None, tolerance=tolerance, angular_speed=w)
        return DampedRolling(self.dynamics, self.terms, stream, u, w)

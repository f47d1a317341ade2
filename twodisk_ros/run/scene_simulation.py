"""The node's motion in its scene, one stretch at a time (no rclpy here).

:class:`~twodisk_ros.run.simulation.Simulation` samples one motion class,
:class:`SceneMotion`, for every scene: the scene's stream
(:func:`~twodisk_ros.physics.scenes.motion.scene_stream`, or the integrator of the speed
drive), poses and ground forces in the gravity-aligned ``frame_id``
(:class:`~twodisk_ros.physics.scenes.terms.SceneTerms`), and the energy balance
E + W − W_d = E₀ carried across commands, time-outs and runtime scene changes (each continues
the motion from the state of the last published sample, in a new stretch). The flat free
scene from the run's start is a scene like the others with its own fast solver
(:class:`SceneMotion` ``run_start``), and no energy terms: E (|ω| in kinematic mode) is
conserved.

Commands (docs/physics.md "Scenes", README "Driving the body"): the speed drive's command is
the signed angular speed Ω (rad/s; the sign of ``omega0``: + for increasing phase), followed
with the first-order lag dΩ/dt = (Ω_cmd − Ω)/``drive_lag``; the torque drive's is the torque
τ (N m) about the axis AB, positive in the sense of that rotation. Until its first command
the speed drive holds the speed it starts from and the torque drive gives 0 N m.
"""

from copy import copy
from dataclasses import dataclass
import math

import numpy as np

from ..physics.forces.validity import ValidityReport
from ..physics.motion.simulate import MotionStream
from ..physics.scenes.scene import Scene
from ..physics.scenes.motion import SceneStream, scene_stream
from ..physics.scenes.terms import SceneTerms

__all__ = ['REST_ENERGY', 'SPEED_LIMIT', 'TORQUE_LIMIT', 'SceneMotion',
           'SceneValues', 'flat_free', 'frame_metadata', 'ground_normal', 'scene_of']

#: At rest: energy above the stable rest pose at most this × M g L (as physics.scene_events).
REST_ENERGY = 1e-9

#: rad/s: the largest |cmd_speed| (the range of omega0)
SPEED_LIMIT = 1e3
#: N m: the largest |cmd_torque|
TORQUE_LIMIT = 10.0


def flat_free(settings):
    """True if the settings describe the flat free scene: no slope, drive or dissipation."""
    s = settings
    return (s.slope == 0.0 and s.drive == 'none' and s.rolling_resistance == 0.0
            and s.damping == 0.0)


def scene_of(settings, drive=None, command=None, speed=0.0):
    """The :class:`~twodisk_ros.physics.scenes.scene.Scene` of the settings with the drive in force.

    ``drive``: 'none', 'speed' or 'torque' (default ``settings.drive``); ``command``: its
    command (rad/s or N m), None for none yet: the speed drive then holds ``speed`` (the
    signed angular speed it starts from, rad/s), the torque drive gives 0 N m. Mode kinematic
    is the speed drive holding ``omega0``; a torque of 0 N m is free motion.
    """
    s = settings
    drive = s.drive if drive is None else drive
    if command is None:
        command = speed if drive == 'speed' else 0.0
    if s.mode == 'kinematic':
        drive, command = 'speed', s.omega0
    if drive == 'none' or (drive == 'torque' and command == 0.0):
        drive, command = 'none', 0.0
    return Scene(slope=s.slope, heading0=s.heading0, gravity=s.gravity, drive=drive,
                 command=command, lag=s.drive_lag, rolling_resistance=s.rolling_resistance,
                 damping=s.damping, friction=s.friction, speed_limit=SPEED_LIMIT,
                 torque_limit=TORQUE_LIMIT)


def ground_normal(slope):
    """The ground's unit normal (sin β, 0, cos β) in ``frame_id`` (gravity-aligned)."""
    return np.array([math.sin(slope), 0.0, math.cos(slope)])


def frame_metadata(settings):
    """The recording's text entries on the slope frame and the events topic."""
    half = 0.5 * settings.slope
    return {
        'slope_frame': 'x straight downhill in the ground, z the ground normal (up), '
                       'y = z cross x; a slope-frame vector p is R_y(slope) p in frame_id, '
                       'the rotation of slope_to_frame_id; the ground is the plane through '
                       'the origin of frame_id with normal ground_normal',
        'slope_to_frame_id': repr([0.0, math.sin(half), 0.0, math.cos(half)]) +
                             ' (quaternion x, y, z, w)',
        'ground_normal': repr([float(x) for x in ground_normal(settings.slope)]),
        'events_topic': 'events (std_msgs/String: reset, pause, resume, command <drive> '
                        '<value>, timeout, scene <name> <old> -> <new>, restart; stamped '
                        'with the first sample each applies to)',
    }


@dataclass
class SceneValues:
    """The energy terms of a block of samples (arrays over the block, J, N m, W)."""

    energy: np.ndarray          #: E = T + V, V = M g × G's height along gravity (J)
    dissipated: np.ndarray      #: W: work done against damping and rolling resistance (J)
    drive_work: np.ndarray      #: W_d: work done by the drive (J)
    drive_torque: np.ndarray    #: τ about AB (N m); 0 without drive
    power: np.ndarray           #: the drive's power (W)

    @property
    def balance(self):
        """E + W − W_d (J): E₀ along the whole run (between resets)."""
        return self.energy + self.dissipated - self.drive_work


class SceneMotion:
    """One stretch of a scene's motion, from a state, with the work done before it.

    Parameters
    ----------
    dynamics : RollingDynamics
    settings : RollerSettings
    model : ContactForceModel
        Reused by the scene's tables.
    drive, command : str, float or None
        The drive in force and its command (:func:`scene_of`; None: none yet).
    start : PhaseState
        (u (rad), u̇ (rad/s), w (rad/s)) at the stretch's t = 0
        (:class:`~twodisk_ros.physics.motion.dynamics.PhaseState`; the stretch starts from w,
        finite also where the body stops turning in u).
    carry : (float, float, float), optional
        (W, W_d, E₀) (J) at the stretch's start: the work done before it and the energy
        balance's constant; None for the start of a run.
    terms : SceneTerms, optional
        The tables of an earlier stretch with the same slope, heading and gravity (reused).
    run_start : bool
        True if ``start`` is the run's own (``theta0``, ``omega0``): the flat free settings
        (:func:`flat_free`) then take the level ground's fast solver (``level`` True): its
        MotionStream (closed forms, or the kinematic quadrature at |omega0|), the cycle's
        poses and ContactForceModel's forces, exactly as ``simulate``; no SceneValues
        (nothing to balance), scene tables only if asked for (:attr:`terms`).
    """

    def __init__(self, dynamics, settings, model, *, drive=None, command=None, start,
                 carry=None, terms=None, run_start=False):
        u0, u_dot0, speed = (float(x) for x in start)
        self.scene = scene = scene_of(settings, drive, command, speed)
        self.dynamics, self.model = dynamics, model
        self.level = run_start and carry is None and flat_free(settings)
        #: the constant |omega0| (rad/s) of the kinematic mode's level stream, None if free
        self._held = abs(settings.omega0) if settings.mode == 'kinematic' else None
        if terms is not None and (terms.scene.slope, terms.scene.heading0) == (
                scene.slope, scene.heading0):   # the same ground and gravity: the same tables
            terms = copy(terms)
            terms.scene = scene
        elif terms is not None or not self.level:
            terms = SceneTerms(dynamics, scene, model)
        self._terms = terms
        self.standing = (True, '')
        self.rested = math.nan       # the time the body came to rest (s, :meth:`rest`)
        if self.level:
            self.stream = MotionStream(dynamics, u0, u_dot0, mode=settings.mode,
                                       method=settings.method, tolerance=settings.tolerance,
                                       angular_speed=speed)
            self.carry = (0.0, 0.0, self.stream.initial_energy)
        else:
            if scene.drive == 'speed':    # (W, W_d tracked, even at a constant command)
                self.stream = SceneStream(terms, u0, u_dot0, tolerance=settings.tolerance,
                                          angular_speed=speed)
            else:
                self.stream = scene_stream(dynamics, scene, u0, u_dot0,
                                           method=settings.method,
                                           tolerance=settings.tolerance, terms=terms,
                                           angular_speed=speed)
            energy = float(terms.energy_turning(u0, speed))
            self.carry = (0.0, 0.0, energy) if carry is None else tuple(float(x)
                                                                         for x in carry)
            if carry is None and scene.slope != 0.0:
                self.standing = terms.standing()
        self.energy0 = self.carry[2]

    @property
    def terms(self):
        """The scene's :class:`~twodisk_ros.physics.scenes.terms.SceneTerms` (built on first
        use by a :attr:`level` stretch, which samples without them)."""
        if self._terms is None:
            self._terms = SceneTerms(self.dynamics, self.scene, self.model)
        return self._terms

    @property
    def known_terms(self):
        """The scene's tables if they were built (for a later stretch to reuse), else None."""
        return self._terms

    @property
    def solver(self):
        """The stream's solver ('quadrature', 'libration', 'DOP853', ...)."""
        return self.stream.solver

    def sample(self, t):
        """(u, u̇, ü, w, SceneValues, (G, A, B, q)) at times t (s, increasing); w = |ω_u| u̇
        the angular speed about AB (rad/s), finite also where the body stops turning in u.
        A :attr:`level` stretch gives no ü and no SceneValues (None)."""
        t = np.asarray(t, dtype=float)
        if self.level:
            u, u_dot, speed = self.stream.sample_with_speed(t)
            poses = self.dynamics.cycle.poses(u)
            return (u, u_dot, None, speed, None,
                    (poses.position_g, poses.contact_a, poses.contact_b, poses.quaternion))
        w0, wd0, _ = self.carry
        s = self.stream.samples(t)
        u, u_dot, u_ddot, speed = s.phase, s.phase_rate, s.phase_acceleration, s.rolling_speed
        values = SceneValues(s.energy, s.dissipated + w0, s.drive_work + wd0, s.drive_torque,
                             s.power)
        return u, u_dot, u_ddot, speed, values, self.terms.poses(u)

    def forces(self, u, u_dot, u_ddot, speed=None):
        """The ground's forces at the states of :meth:`sample`: the scene's terms' from u̇
        and ü (:class:`~twodisk_ros.physics.scenes.terms.SceneForces`); on a :attr:`level`
        stretch the level ground's (:class:`~twodisk_ros.physics.forces.contact.
        ContactForces`): the motor's at the constant |omega0| in kinematic mode, else the
        free motion's from (u, w = ``speed``), finite also where u̇ is not."""
        if not self.level:
            return self.terms.forces(u, u_dot, u_ddot)
        if self._held is not None:
            return self.model.kinematic(u, self._held)
        return self.model.dynamic(u, angular_speed=speed)

    @property
    def comes_to_rest(self):
        """True for a free scene with losses (drive none, damping or rolling resistance)."""
        scene = self.scene
        return scene.drive == 'none' and bool(scene.damping or scene.rolling_resistance)

    def rest_excess(self, u, energy):
        """E − V(u*) (J) per sample: the energy above the stable rest pose u* within π/4 of u
        (inf where there is none), arrays of the samples' u (rad) and E (J)."""
        u, energy = np.asarray(u, dtype=float), np.asarray(energy, dtype=float)
        excess = np.full(u.shape, np.inf)
        for eq in self.terms.equilibria():
            if eq.stable:
                centre = eq.phase + 2 * np.pi * np.round((u - eq.phase) / (2 * np.pi))
                near = np.abs(u - centre) < np.pi / 4
                gap = energy - self.terms.potential(centre)
                excess = np.where(near & (gap < excess), gap, excess)
        return excess

    def track_rest(self, t, u, u_dot, u_ddot, values):
        """Note the first time (s, the node's) at which a scene with losses is at rest, the
        criterion of :func:`~twodisk_ros.physics.scenes.events.settle`: stuck (rolling
        resistance holds it: u̇ = ü = 0) or E − V(u*) ≤ :data:`REST_ENERGY` × M g L; judged
        at every sample, so to within one sample period. ``values``: the samples'
        :class:`SceneValues`."""
        if not self.comes_to_rest or not math.isnan(self.rested) or not len(t):
            return
        threshold = REST_ENERGY * self.terms.dynamics.energy_scale
        stuck = (np.asarray(u_dot) == 0) & (np.asarray(u_ddot) == 0)
        resting = np.flatnonzero(stuck | (self.rest_excess(u, values.energy) <= threshold))
        if resting.size:
            self.rested = float(np.asarray(t)[resting[0]])

    def standing_report(self):
        """A ValidityReport at t = 0 if the body cannot stand on this slope, else None."""
        ok, why = self.standing
        if ok:
            return None
        return ValidityReport(False, 0.0, 0, 'standing', f'{why} (from t = 0)')

    def equilibrium_values(self):
        """[(key, text)] of the rest poses on the slope, for the diagnostics."""
        values = []
        body = self.terms.dynamics.body
        for k, eq in enumerate(self.terms.equilibria()):
            theta = float(np.real(body.phase_angles_with_rates(eq.phase)[0]))
            period = f', period={eq.period:.9g} s' if math.isfinite(eq.period) else ''
            values.append((f'equilibrium {k}', (
                f'on the slope: u={eq.phase:.9g} rad, theta={theta:.9g} rad, '
                f'{"stable" if eq.stable else "unstable"}, N_A={eq.normal_a:.6g} N, '
                f'N_B={eq.normal_b:.6g} N, mu_required={eq.mu_required:.4g}{period}')))
        return values


"""Rolling state ↔ MuJoCo state of the free body, and the nearest rolling state.

A **rolling state** is the exact motion's state (u, w) (phase, rad; signed angular speed
w = |ω_u| u̇, rad/s: :class:`~twodisk_ros.physics.motion.dynamics.PhaseState`) placed in the
ground plane by a heading ``yaw`` (rad, about Z) and a ``shift`` (m, in the plane): the pose
is Rz(yaw) (the cycle's pose at u, :meth:`~twodisk_ros.physics.bodies.cycle.RollingCycle.poses`)
+ shift. Velocities: ω = ω_u(u) u̇ (body frame), and G moves about the resting contact A,
v_G = ω × (G − A) (world), since rolling without slipping leaves A and B at rest.

MuJoCo's free joint: qpos = (G (world, m), the body → world quaternion (w, x, y, z)), qvel =
(v_G (world, m/s), ω (body frame, rad/s)) — MuJoCo's convention for a free joint, checked in
tests/test_engine_state.py against mj_objectVelocity.

The **nearest rolling state** to an engine state: the ground normal seen in the body,
n_e = Rᵀ e_z, picks the phase u whose resting pose has the closest normal n(u) (the root of
n_e · dn/du = 0 near the closest of a grid, so the pose is matched to rounding when it is a
rolling pose); the heading is the rotation about Z that brings the rolling orientation
closest to R (together they leave only the tilt angle between n(u) and n_e), the shift puts
G over the engine's G; w keeps the engine's energy, ½ J(u) w² + M g z_G(u) = E (J the
moment of inertia about the contact line), signed as ω · ω_u (on a slope: in the slope
frame, with g cos β, :func:`nearest_rolling`). What cannot be matched is reported: the tilt
angle (rad), G's height offset z − z_G(u) (m), the energy added (J, > 0 only when
E < M g z_G(u), then w = 0) and the velocity the rolling state does not keep.
"""

from dataclasses import dataclass
import math

import numpy as np
from scipy.optimize import brentq

from twodisk_ros.physics.numerics.analytic import complex_step

__all__ = ['EngineState', 'NearestRolling', 'engine_state', 'nearest_rolling',
           'quaternion_matrix']

#: Phases sampled per cycle to find the bracket of the closest normal.
_GRID = 512


@dataclass(frozen=True)
class EngineState:
    """MuJoCo's state of the free joint: ``qpos`` (7,), ``qvel`` (6,) (module docstring)."""

    qpos: np.ndarray
    qvel: np.ndarray


@dataclass(frozen=True)
class NearestRolling:
    """The rolling state closest to an engine state, and what it misses.

    phase (rad), angular_speed (rad/s), yaw (rad), shift (m, (2,)): the rolling state.
    angle_mismatch (rad): angle between the engine's ground normal and the rolling pose's.
    height_mismatch (m): the engine's z_G minus the rolling pose's (signed).
    energy_mismatch (J): rolling energy minus the engine's (≥ 0; > 0 only if clamped at w = 0).
    velocity_mismatch (m/s): |v_G − v_G,rolling| (the slip and bounce the map drops).
    """

    phase: float
    angular_speed: float
    yaw: float
    shift: np.ndarray
    angle_mismatch: float
    height_mismatch: float
    energy_mismatch: float
    velocity_mismatch: float


def quaternion_matrix(q):
    """Rotation matrix (3, 3) of the unit quaternion ``q`` = (w, x, y, z) (MuJoCo's order)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _yaw_quaternion(yaw):
    return np.array([math.cos(0.5 * yaw), 0.0, 0.0, math.sin(0.5 * yaw)])


def _multiply(p, q):
    """Hamilton product p ⊗ q, both (w, x, y, z)."""
    pw, pv, qw, qv = p[0], p[1:], q[0], q[1:]
    return np.concatenate([[pw * qw - pv @ qv], pw * qv + qw * pv + np.cross(pv, qv)])


def _rolling_pose(cycle, u, yaw, shift):
    """(G, A, quaternion (w, x, y, z)) of the rolling pose at u, turned by yaw and shifted."""
    poses = cycle.poses(np.array([u]))
    rz = quaternion_matrix(_yaw_quaternion(yaw))
    offset = np.array([shift[0], shift[1], 0.0])
    g = rz @ poses.position_g[0] + offset
    a = rz @ poses.contact_a[0] + offset
    x, y, z, w = poses.quaternion[0]
    return g, a, _multiply(_yaw_quaternion(yaw), np.array([w, x, y, z]))


def _phase_rate(dynamics, u, angular_speed):
    """u̇ = w / |ω_u| (rad/s)."""
    return angular_speed / float(dynamics.angular_speed_per_phase(np.array([u]))[0])


def engine_state(dynamics, phase, angular_speed, yaw=0.0, shift=(0.0, 0.0)):
    """MuJoCo's (qpos, qvel) of a rolling state.

    Parameters
    ----------
    dynamics : RollingDynamics
        The body, its mass model and g; its cycle places the poses.
    phase, angular_speed : float
        u (rad) and w = |ω_u| u̇ (rad/s).
    yaw, shift
        Heading (rad) and ground-plane translation (m, 2) applied to the cycle's pose.

    Returns
    -------
    EngineState
    """
    u = float(phase)
    g, a, q = _rolling_pose(dynamics.cycle, u, float(yaw), shift)
    omega_body = dynamics.body.phase_angular_velocity(np.array([u]))[0] \
        * _phase_rate(dynamics, u, float(angular_speed))
    omega_world = quaternion_matrix(q) @ omega_body
    return EngineState(np.concatenate([g, q]),
                       np.concatenate([np.cross(omega_world, g - a), omega_body]))


def _closest_phase(body, normal, near):
    """The phase u whose ground normal n(u) is closest to ``normal`` (body frame, unit),
    in the 2π-window centred on ``near``."""
    grid = near - math.pi + 2 * math.pi * np.arange(_GRID + 1) / _GRID

    def slope(u):     # d/du (normal · n(u)): zero at the closest normal
        return complex_step(lambda v: body.phase_vectors(v)[2] @ normal, np.asarray(u))

    k = int(np.argmax(body.phase_geometry(grid).ground_normal @ normal))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, _GRID)]
    s_lo, s_hi = float(slope(lo)), float(slope(hi))
    if s_lo == 0.0:
        return float(lo)
    if s_hi == 0.0 or s_lo * s_hi > 0:
        return float(grid[k]) if s_hi != 0.0 else float(hi)
    return brentq(lambda v: float(slope(v)), lo, hi, xtol=1e-15, rtol=8.9e-16)


def nearest_rolling(dynamics, qpos, qvel, near_phase=0.0, slope=0.0):
    """The rolling state closest to MuJoCo's (qpos, qvel), and its mismatch.

    Parameters
    ----------
    dynamics : RollingDynamics
    qpos, qvel : array_like, (7,) and (6,)
        The free joint's state (module docstring).
    near_phase : float
        The phase is sought in [near_phase − π, near_phase + π] (rad): pass the last rolling
        phase to keep u continuous.
    slope : float
        β (rad): (qpos, qvel) are in the slope frame (x downhill in the ground, z its normal;
        gravity g (sin β, 0, −cos β)). The rolling state shares G's downhill coordinate x,
        so the slope's potential M g (z cos β − x sin β) differs between them only by
        M g cos β (z − z_G(u)): w keeps ½ J w² + M g cos β z_G(u) = ½ M v² + ½ ωᵀIω +
        M g cos β z (0: the level ground's balance, bit for bit).

    Returns
    -------
    NearestRolling
    """
    qpos, qvel = np.asarray(qpos, dtype=float), np.asarray(qvel, dtype=float)
    body, mass = dynamics.body, dynamics.mass
    q = qpos[3:7] / np.linalg.norm(qpos[3:7])
    rotation = quaternion_matrix(q)
    normal = rotation[2]                                   # e_z in the body frame (Rᵀ e_z)
    u = _closest_phase(body, normal, float(near_phase))
    n_u = body.phase_geometry(np.array([u])).ground_normal[0]
    angle = math.atan2(np.linalg.norm(np.cross(n_u, normal)), float(n_u @ normal))
    # heading: Rz(yaw) R_c(u) closest to R, max trace(Rz(yaw) N) with N = R_c Rᵀ
    g0, _, q0 = _rolling_pose(dynamics.cycle, u, 0.0, (0.0, 0.0))
    m = quaternion_matrix(q0) @ rotation.T
    yaw = math.atan2(m[0, 1] - m[1, 0], m[0, 0] + m[1, 1])
    rz = quaternion_matrix(_yaw_quaternion(yaw))
    shift = qpos[:2] - (rz @ g0)[:2]
    height = float(qpos[2] - body.phase_height(np.array([u]))[0])
    v, omega = qvel[:3], qvel[3:]
    energy = (0.5 * mass.mass * (v @ v) + 0.5 * omega @ mass.inertia @ omega
              + mass.mass * dynamics.gravity * qpos[2])
    potential = float(dynamics.potential(np.array([u]))[0])
    if slope:
        cos = math.cos(slope)
        energy = (0.5 * mass.mass * (v @ v) + 0.5 * omega @ mass.inertia @ omega
                  + mass.mass * dynamics.gravity * cos * qpos[2])
        potential *= cos
    inertia = float(dynamics.contact_line_inertia(np.array([u]))[0])
    omega_u = body.phase_angular_velocity(np.array([u]))[0]
    speed = math.sqrt(max(2.0 * (energy - potential) / inertia, 0.0))
    w = math.copysign(speed, float(omega @ omega_u))
    rolled = engine_state(dynamics, u, w, yaw, shift)
    return NearestRolling(phase=u, angular_speed=w, yaw=yaw, shift=shift,
                          angle_mismatch=angle, height_mismatch=height,
                          energy_mismatch=max(potential - energy, 0.0),
                          velocity_mismatch=float(np.linalg.norm(v - rolled.qvel[:3])))

"""Stepping the engine from a state, sampled at given times, with each disk's contact status.

Contacts are attributed to the disks by where they are on the body: a contact point p (body
frame) belongs to disk 1 (contact A, plane x3 = 0) if |p·e3| ≤ |p·e1|, else to disk 2
(contact B, plane x1 = 0) — the same rule for the plates and for the hull, whose contacts
are at the rims' vertices. Per sample and disk: whether it touches, its total normal force
(N, MuJoCo's contact force) and the largest slip speed (m/s) of the body's material at its
contact points along the ground (NaN where it does not touch).
"""

from dataclasses import dataclass
import math

import numpy as np

from .model import build_model
from .state import quaternion_matrix

__all__ = ['ContactDetails', 'Engine', 'EngineSamples']


@dataclass(frozen=True)
class EngineSamples:
    """The engine's motion at the sample times (arrays over samples first).

    time (s); qpos (n, 7), qvel (n, 6) (:mod:`~twodisk_ros.engine.state`); touching (n, 2)
    bool, normal_force (n, 2) N, slip_speed (n, 2) m/s (NaN where not touching), for
    (disk 1 / A, disk 2 / B).
    """

    time: np.ndarray
    qpos: np.ndarray
    qvel: np.ndarray
    touching: np.ndarray
    normal_force: np.ndarray
    slip_speed: np.ndarray


@dataclass(frozen=True)
class ContactDetails:
    """The contacts of each disk (A, B) now: touching (2,) bool; force (2, 3) N, the
    ground's total force on the body (world); point (2, 3) m, the force-weighted mean contact
    point (NaN if none pushes); slip (2,) m/s, the largest speed along the ground and normal
    (2,) m/s, the largest speed along the normal of the body's material at its contact points
    (0 where it does not touch)."""

    touching: np.ndarray
    force: np.ndarray
    point: np.ndarray
    slip: np.ndarray
    normal: np.ndarray


class Engine:
    """MuJoCo's free body of one body, mass model, g and :class:`ContactParameters`.

    Parameters as in :func:`~twodisk_ros.engine.model.engine_xml` (``slope`` β, rad: the
    world is the slope frame, gravity tilted in it), and ``damping`` c (N m s, ≥ 0): the
    viscous torque −c ω on the body (the scenes' damping, docs/physics.md "Scenes"), applied
    before every step from that step's ω (explicit: ω decays by the factor 1 − c h / I about a
    principal axis of moment I per step h; MuJoCo's integrator handles contacts and gravity
    as without it). c = 0 and β = 0 leave the engine as it was.

    :meth:`set_moment` adds a moment M (world, N m) computed from the state before every step
    (a drive's torque, run/hybrid.py); ``moment_work`` (J) accumulates its work M · ω h per
    step (explicit, as the moment is applied).
    """

    def __init__(self, body, mass_properties, gravity=9.81, parameters=None, *, slope=0.0,
                 damping=0.0):
        import mujoco
        if isinstance(damping, (bool, str, bytes)) or not np.isscalar(damping) \
                or not (math.isfinite(float(damping)) and float(damping) >= 0):
            raise ValueError(f'damping must be a finite torque per angular speed >= 0 N m s, '
                             f'got {damping!r}')
        self._mujoco = mujoco
        self.model = build_model(body, mass_properties, gravity, parameters, slope)
        self.data = mujoco.MjData(self.model)
        self.timestep = float(self.model.opt.timestep)
        self._ground = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, 'ground')
        self.damping = float(damping)
        self._body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, 'body')
        self._moment = None
        self.moment_work = 0.0       #: J: the work of the moment of :meth:`set_moment`

    def set_moment(self, moment):
        """Apply ``moment(qpos, rotation)`` → M (3,) (N m, world; rotation body → world) before
        every step from now on (None: no moment); ``moment_work`` starts again at 0 J."""
        self._moment, self.moment_work = moment, 0.0
        self.data.xfrc_applied[self._body, 3:6] = 0.0

    def _step(self):
        """One mj_step, with the damping torque −c ω (world frame) of the state before it and
        the moment of :meth:`set_moment`."""
        d = self.data
        if self._moment is not None:
            rotation = quaternion_matrix(d.qpos[3:7] / np.linalg.norm(d.qpos[3:7]))
            omega = rotation @ d.qvel[3:6]
            moment = np.asarray(self._moment(d.qpos, rotation), dtype=float)
            self.moment_work += float(moment @ omega) * float(self.model.opt.timestep)
            d.xfrc_applied[self._body, 3:6] = moment - self.damping * omega
        elif self.damping:
            rotation = quaternion_matrix(d.qpos[3:7] / np.linalg.norm(d.qpos[3:7]))
            d.xfrc_applied[self._body, 3:6] = -self.damping * (rotation @ d.qvel[3:6])
        self._mujoco.mj_step(self.model, d)

    def set_state(self, qpos, qvel, time=0.0):
        """Start from the free joint's (qpos, qvel) at ``time`` (s); the solver's warm start
        is cleared (a state from outside has none)."""
        d = self.data
        d.qpos[:] = qpos
        d.qvel[:] = qvel
        d.time = float(time)
        d.qacc_warmstart[:] = 0.0
        self._mujoco.mj_forward(self.model, d)

    def contacts(self):
        """(touching (2,), normal force (2,) N, slip speed (2,) m/s) now (module docstring)."""
        mujoco, d = self._mujoco, self.data
        touching = np.zeros(2, dtype=bool)
        force = np.zeros(2)
        slip = np.full(2, np.nan)
        rotation = quaternion_matrix(d.qpos[3:7] / np.linalg.norm(d.qpos[3:7]))
        g, v, omega = d.qpos[:3], d.qvel[:3], rotation @ d.qvel[3:6]
        f6 = np.zeros(6)
        for i in range(d.ncon):
            c = d.contact[i]
            if c.efc_address < 0:       # excluded or beyond the margin: no force
                continue
            mujoco.mj_contactForce(self.model, d, i, f6)
            p = rotation.T @ (c.pos - g)
            disk = 0 if abs(p[2]) <= abs(p[0]) else 1
            frame = c.frame.reshape(3, 3)            # rows: normal, two tangents (world)
            velocity = v + np.cross(omega, c.pos - g)
            tangential = velocity - (velocity @ frame[0]) * frame[0]
            touching[disk] = True
            force[disk] += f6[0]
            speed = float(np.linalg.norm(tangential))
            slip[disk] = speed if np.isnan(slip[disk]) else max(slip[disk], speed)
        return touching, force, slip

    def contact_details(self):
        """The contacts now, per disk (A, B): :class:`ContactDetails` (module docstring's
        attribution; the ground's force on the body, world frame). Of the state now: after
        mj_step the contacts and forces in ``data`` are those of the state before the step,
        so mj_forward recomputes them first (it leaves qpos, qvel and the solver's warm
        start as they are: the next step is the same)."""
        mujoco, d = self._mujoco, self.data
        mujoco.mj_forward(self.model, d)
        touching = np.zeros(2, dtype=bool)
        force, point = np.zeros((2, 3)), np.zeros((2, 3))
        slip, normal = np.zeros(2), np.zeros(2)
        rotation = quaternion_matrix(d.qpos[3:7] / np.linalg.norm(d.qpos[3:7]))
        g, v, omega = d.qpos[:3], d.qvel[:3], rotation @ d.qvel[3:6]
        f6 = np.zeros(6)
        for i in range(d.ncon):
            c = d.contact[i]
            if c.efc_address < 0:
                continue
            mujoco.mj_contactForce(self.model, d, i, f6)
            p = rotation.T @ (c.pos - g)
            disk = 0 if abs(p[2]) <= abs(p[0]) else 1
            frame = c.frame.reshape(3, 3)
            on_body = frame.T @ f6[:3] * (1.0 if c.geom1 == self._ground else -1.0)
            velocity = v + np.cross(omega, c.pos - g)
            along = float(velocity @ frame[0])
            touching[disk] = True
            force[disk] += on_body
            point[disk] += max(f6[0], 0.0) * c.pos
            slip[disk] = max(slip[disk], float(np.linalg.norm(velocity - along * frame[0])))
            normal[disk] = max(normal[disk], abs(along))
        weight = np.where(touching & (force[:, 2] > 0), force[:, 2], np.nan)
        return ContactDetails(touching, force, point / weight[:, None], slip, normal)

    def contact_speeds(self):
        """(touching (2,) bool, slip (2,) m/s, normal (2,) m/s) per disk now, as
        :meth:`contact_details` without the forces: vectorised, for a check after every step."""
        d = self.data
        touching, slip, normal = np.zeros(2, dtype=bool), np.zeros(2), np.zeros(2)
        if d.ncon == 0:
            return touching, slip, normal
        con = d.contact
        active = np.asarray(con.efc_address) >= 0
        pos = np.asarray(con.pos).reshape(-1, 3)[active]
        axis = np.asarray(con.frame).reshape(-1, 9)[active, :3]
        rotation = quaternion_matrix(d.qpos[3:7] / np.linalg.norm(d.qpos[3:7]))
        g = d.qpos[:3]
        arm = pos - g
        velocity = d.qvel[:3] + np.cross(rotation @ d.qvel[3:6], arm)
        along = np.einsum('ij,ij->i', velocity, axis)
        local = arm @ rotation
        disk = (np.abs(local[:, 2]) > np.abs(local[:, 0])).astype(int)
        sliding = np.linalg.norm(velocity - along[:, None] * axis, axis=1)
        for k in range(2):
            mine = disk == k
            if mine.any():
                touching[k] = True
                slip[k] = sliding[mine].max()
                normal[k] = np.abs(along[mine]).max()
        return touching, slip, normal

    def step_to(self, t):
        """Step to time ``t`` (s, ≥ now): whole steps, then one shorter step to land on t
        (so a sample is the state at its own time, not at the last step before it)."""
        d, m = self.data, self.model
        while d.time + self.timestep <= t + 1e-12 * max(1.0, abs(t)):
            self._step()
        rest = t - d.time
        if rest > 1e-9 * self.timestep:
            m.opt.timestep = rest
            try:
                self._step()
            finally:
                m.opt.timestep = self.timestep
        d.time = float(t)

    def sample(self, times):
        """Step to each of ``times`` (s, non-decreasing, ≥ the current time), sampling there.

        Each sample is taken at the last step not after its time (steps of ``timestep``).

        Returns
        -------
        EngineSamples
        """
        times = np.asarray(times, dtype=float)
        if times.ndim != 1 or np.any(np.diff(times) < 0) \
                or (times.size and times[0] < self.data.time - 0.5 * self.timestep):
            raise ValueError('times must be a non-decreasing 1-D array from the current time on')
        d = self.data
        n = times.size
        qpos, qvel = np.empty((n, 7)), np.empty((n, 6))
        touching, force, slip = np.empty((n, 2), dtype=bool), np.empty((n, 2)), np.empty((n, 2))
        for k, t in enumerate(times):
            steps = int(np.floor((t - d.time) / self.timestep + 1e-9))
            for _ in range(max(steps, 0)):
                self._step()
            qpos[k], qvel[k] = d.qpos, d.qvel
            touching[k], force[k], slip[k] = self.contacts()
        return EngineSamples(times, qpos, qvel, touching, force, slip)

"""``contact_model:=hybrid`` (issue 31): exact rolling while it holds, MuJoCo's free body after.

The motion is a list of :class:`Stretch` es, each either ``rolling`` (the package's exact
motion, :class:`~twodisk_ros.physics.motion.simulate.MotionStream`) or ``engine`` (MuJoCo's
free rigid body with unilateral contacts and Coulomb friction μ = ``friction``,
:class:`~twodisk_ros.engine.run.Engine`, its defaults :class:`~twodisk_ros.engine.model.
ContactParameters`):

* **rolling → engine.** Along a rolling stretch the contact forces are checked at the
  samples and on a grid of at most :data:`SCAN_STEP` s between them; at the first time t_b
  where a normal force is negative (lift-off) or μ_required > μ (slip), the crossing is
  bisected on the motion's dense solution (``MotionStream.state_at``) between t_b and the
  last good time, to :data:`SWITCH_TOLERANCE` s (the reported switch time is the last
  time at which rolling still holds). A violation that begins and ends within one grid
  step is not seen. The engine starts there from the exact rolling state (pose and
  velocities, :func:`~twodisk_ros.engine.state.engine_state`).
* **engine → rolling.** After every engine step: both disks touch, every contact point's
  slip speed is below ``slip_speed`` and its normal speed below ``normal_speed``
  (:class:`ReturnRule`); once this has held for ``hold`` s the state is mapped to the
  nearest rolling state (:func:`~twodisk_ros.engine.state.nearest_rolling`: phase from the
  orientation, heading and position of G, speed from the energy), and exact rolling resumes
  from it if rolling holds there (else the hold starts again). The mismatch of the map is
  the stretch's ``mismatch``.

On a slope β (a :class:`~twodisk_ros.run.hybrid_rolling.SceneRolling` of a slope scene)
the engine's world is the slope frame S (gravity g (sin β, 0, −cos β)); each rolling stretch
is placed in S by its heading and shift, the return map keeps the slope's potential
(``nearest_rolling(..., slope=β)``) and the next stretch is the scene at the new heading;
everything is published in the gravity frame W = R_y(β) S, E with V = M g × G's height
along gravity (docs/physics.md "The free-body engine").

Engine samples are the engine's state at their own time (a last shorter step lands on it).
They carry the engine's pose, its contact force per disk (0 for a disk in the air) and
contact point (the force-weighted contact point; for a disk in the air its lowest rim
point), and the phase, angular speed and energy-matched w of the nearest rolling state.
"""

from dataclasses import dataclass, field
import math

import numpy as np

from ..engine.model import ContactParameters
from ..engine.run import Engine
from ..engine.state import engine_state, nearest_rolling, quaternion_matrix
from ..model.frames import disk_rims
from ..physics.forces.validity import check_validity
from ..physics.scenes.scene import quaternion_product
from .hybrid_drive import DriveMoment
from .hybrid_rolling import FreeRolling

__all__ = ['HybridMotion', 'HybridSamples', 'ReturnRule', 'SCAN_STEP', 'SWITCH_TOLERANCE',
           'Stretch']

#: s: the rolling motion's forces are checked at least this often between samples
SCAN_STEP = 1e-3
#: s: the switch time is bisected to this on the dense solution
SWITCH_TOLERANCE = 1e-12
#: phases per cycle of the published phase of an engine sample (the closest ground normal)
PHASE_GRID = 4096


@dataclass(frozen=True)
class ReturnRule:
    """When the engine's body rolls again: both disks touch with every contact point's slip
    speed < ``slip_speed`` (m/s) and normal speed < ``normal_speed`` (m/s), for ``hold`` s.

    Defaults (:meth:`for_body`): 1e-2 √(g L) for both speeds (L the body's size: 14 mm/s for
    a 0.2 m body; the engine's rolling creeps at < 2 mm/s, docs/physics.md) and 20 ms.
    """

    slip_speed: float
    normal_speed: float
    hold: float = 0.02

    @classmethod
    def for_body(cls, size, gravity):
        """The default rule of a body of ``size`` (m) under ``gravity`` (m/s²)."""
        speed = 1e-2 * math.sqrt(max(gravity, 1e-6) * size)
        return cls(speed, speed)


@dataclass
class Stretch:
    """One stretch of the motion.

    model: 'rolling' or 'engine'; t_start, t_end (s; t_end inf while it lasts); reason (one
    sentence: why it began). A rolling stretch after the engine has ``mismatch`` (the
    :class:`~twodisk_ros.engine.state.NearestRolling` of the return) and ``engine_state``
    ((qpos, qvel) of the engine there); ``energy`` (J) is the rolling energy at its start
    (of the state handed to the engine, or mapped back); an engine stretch lists its ``flights``: [(t0, t1)]
    step times (s): the states from t0 to before t1 had no active contact.
    """

    model: str
    t_start: float
    t_end: float
    reason: str
    energy: float = math.nan     #: E (J) at its start: the rolling state's (switch, return)
    mismatch: object = None
    engine_state: tuple = None
    flights: list = field(default_factory=list)
    yaw: float = 0.0             #: rad: a rolling stretch's heading in the slope frame
    shift: tuple = (0.0, 0.0)    #: m: and its ground shift there


@dataclass
class HybridSamples:
    """The motion at a block of times (arrays over samples, SI units, world frame).

    engine (n,) bool: the sample is the engine's; phase, phase_rate, angular_speed (rolling:
    the exact motion's; engine: the nearest rolling state's); position_g, contact_a,
    contact_b (n, 3); quaternion (n, 4) x, y, z, w; force_a, force_b (n, 3) N the ground's
    force on the body; normal_a, normal_b, mu_required (n,) (engine: the force's normal part
    and |tangential| / normal, NaN in the air); energy (n,) J; touching (n, 2) bool;
    velocity_g (n, 3) m/s and angular_velocity (n, 3) rad/s (world) of the engine's samples
    (NaN in rolling ones); dissipated (n,) J: the work done against the damping since the
    rolling stretch's start (0 without damping; NaN in engine samples); drive_work (n,) J: the
    drive's work since the stretch's start (rolling: the scene's W_d; engine: the torque
    drive's, :mod:`~twodisk_ros.run.hybrid_drive`; 0 without).
    """

    t: np.ndarray
    engine: np.ndarray
    phase: np.ndarray
    phase_rate: np.ndarray
    angular_speed: np.ndarray
    position_g: np.ndarray
    contact_a: np.ndarray
    contact_b: np.ndarray
    quaternion: np.ndarray
    force_a: np.ndarray
    force_b: np.ndarray
    normal_a: np.ndarray
    normal_b: np.ndarray
    mu_required: np.ndarray
    energy: np.ndarray
    touching: np.ndarray
    velocity_g: np.ndarray
    angular_velocity: np.ndarray
    dissipated: np.ndarray
    drive_work: np.ndarray


def _tilt(slope):
    """R_y(β): slope-frame vectors → the gravity frame (3 × 3; Scene.slope_to_gravity)."""
    c, s = math.cos(slope), math.sin(slope)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


class _Rolling:
    """A rolling stretch: its motion from t0 (:mod:`~twodisk_ros.run.hybrid_rolling`, placed
    at its heading ``source.yaw`` in the slope frame), shifted by ``shift`` (m, (2,), in the
    ground); ``offset`` (J) = −M g sin β shift_x: the slope's potential of the shift, which
    the source's V (origin at its own A(u = 0)) does not hold."""

    def __init__(self, source, t0, shift=(0.0, 0.0), weight=0.0):
        self.source, self.t0 = source, float(t0)
        self.shift = np.array([shift[0], shift[1], 0.0])
        self.yaw = source.yaw
        self.world_shift = self.shift if not source.slope else _tilt(source.slope) @ self.shift
        self.offset = -weight * math.sin(source.slope) * self.shift[0]
        self.checked = float(t0)      # rolling holds up to here (s)

    def energy(self, u, w):
        """E (J) at the states, on the run's potential (origin: the first stretch's A)."""
        energy = self.source.energy(u, w)
        return energy + self.offset if self.offset else energy


class HybridMotion:
    """The hybrid motion from a rolling start (module docstring), sampled in blocks.

    Parameters
    ----------
    dynamics : RollingDynamics
    model : ContactForceModel
        The contact forces of ``dynamics`` (flat ground, free motion).
    stream : MotionStream
        The first rolling stretch from t = 0 (the run's: its samples are the rolling run's).
    mu : float
        Friction coefficient (the rolling model's and the engine's).
    method, tolerance
        Of the rolling stretches after the engine (as the run's).
    parameters : ContactParameters, optional
        The engine's (μ is set to ``mu``).
    rule : ReturnRule, optional
        Default :meth:`ReturnRule.for_body`.
    engine : Engine, optional
        An engine of the same body, mass model, g, parameters and damping to reuse (else
        built at the first switch: 0.5 s for the default mesh).
    rolling : FreeRolling or DampedRolling, optional
        The first rolling stretch's motion (default: ``FreeRolling`` of ``stream``); each
        later one restarts it (:mod:`~twodisk_ros.run.hybrid_rolling`).
    damping : float
        c (N m s): the engine's viscous torque −c ω (that of ``rolling``'s scene).
    shift : (float, float)
        m: the first rolling stretch's ground shift (a continued motion's, in the slope frame).
    engine_start : (qpos, qvel), optional
        Start in the engine from this state (slope frame) at t = 0 (a motion continued from
        an engine sample); ``rolling`` then only gives the kind of rolling to return to.
    reason : str, optional
        The first stretch's reason (default: exact rolling from t = 0 s).
    """

    def __init__(self, dynamics, model, stream, mu, *, method='table', tolerance=1e-10,
                 parameters=None, rule=None, engine=None, rolling=None, damping=0.0,
                 shift=(0.0, 0.0), engine_start=None, reason='exact rolling from t = 0 s'):
        self.dynamics, self.model, self.mu = dynamics, model, float(mu)
        self.method, self.tolerance = method, tolerance
        p = parameters or ContactParameters()
        self.parameters = ContactParameters(**{**p.__dict__, 'mu': self.mu})   # (0, 10]
        self.rule = rule or ReturnRule.for_body(dynamics.body.size, dynamics.gravity)
        self.weight = dynamics.mass.mass * dynamics.gravity
        source = rolling or FreeRolling(dynamics, model, stream)
        self.damping, self.slope = float(damping), float(source.slope)
        self._cos, self._sin = math.cos(self.slope), math.sin(self.slope)
        self._tilt = _tilt(self.slope) if self.slope else None
        self._first = source          # each return restarts its kind of rolling
        self._rolling = _Rolling(source, 0.0, shift, self.weight)
        energy = source.initial_energy + self._rolling.offset
        self.stretches = [Stretch('rolling', 0.0, math.inf, reason, energy=energy,
                                  yaw=source.yaw, shift=tuple(shift))]
        self._engine = engine         # built at the first switch if None
        self._held_since = None       # engine: the return rule holds since (s)
        self._phase = float(source.state_at([0.0])[0][0])
        self._rims = self._normals = None
        if engine_start is not None:
            self.prepare()
            self._start_engine(*engine_start, 0.0)
            self.stretches[0].model, self.stretches[0].energy = 'engine', float(
                self._engine_sample()['energy'])

    @property
    def engine(self):
        """The :class:`~twodisk_ros.engine.run.Engine` (after :meth:`prepare`; to share)."""
        return self._engine

    def set_friction(self, mu):
        """Take the friction coefficient μ (in (0, 10]) from now on: the rolling model is
        judged by it and the engine's contacts have it (MuJoCo's geom friction; a contact
        takes the larger of its two geoms')."""
        self.mu = float(mu)
        self.parameters = ContactParameters(**{**self.parameters.__dict__, 'mu': self.mu})
        if self._engine is not None:
            self._engine.model.geom_friction[:, 0] = self.mu

    def prepare(self):
        """Build now what the first switch needs (the engine: ~0.5 s, the phase grid), so a
        realtime run does not pay it while publishing."""
        if self._engine is None:
            self._engine = Engine(self.dynamics.body, self.dynamics.mass,
                                  self.dynamics.gravity, self.parameters, slope=self.slope,
                                  damping=self.damping)
        if self._normals is None:
            self._cycle = 2 * np.pi * np.arange(PHASE_GRID) / PHASE_GRID
            self._normals = self.dynamics.body.phase_geometry(self._cycle).ground_normal
        return self

    def _start_engine(self, qpos, qvel, t):
        """The engine from (qpos, qvel) (slope frame) at t (s), with this run's μ and, for a
        torque drive, its moment (:mod:`~twodisk_ros.run.hybrid_drive`)."""
        e = self._engine
        e.model.geom_friction[:, 0] = self.mu     # (a shared engine: this run's)
        kind, torque = self._first.drive
        e.set_moment(DriveMoment(self.dynamics.body, self._cycle, self._normals, torque)
                     if kind == 'torque' and torque else None)
        e.set_state(qpos, qvel, t)
        self._held_since, self._rolling = None, None

    # -- rolling --------------------------------------------------------------------------
    def _bad(self, forces):
        return (forces.normal_a < 0) | (forces.normal_b < 0) | (forces.mu_required > self.mu)

    def _crossing(self, good, bad):
        """Bisect the first time rolling fails in (good, bad] on the dense solution: (last
        good time, the failing time's report)."""
        r = self._rolling
        lo, hi = max(good, r.source.window_start + r.t0), bad
        while hi - lo > SWITCH_TOLERANCE:
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            if self._bad(r.source.forces(*r.source.state_at([mid - r.t0])[:4]))[0]:
                hi = mid
            else:
                lo = mid
        state = r.source.state_at([hi - r.t0])[:4]
        return lo, check_validity([hi], r.source.forces(*state), self.mu)

    def _rolling_block(self, ts):
        """Samples at times ts (s, increasing) of the rolling stretch up to the first time it
        fails, checked on the samples and a grid of :data:`SCAN_STEP` from its last checked
        time: (samples dict, (switch time, ValidityReport) or None)."""
        r = self._rolling
        count = max(2, int(math.ceil((ts[-1] - r.checked) / SCAN_STEP)) + 1)
        grid = np.union1d(np.linspace(r.checked, ts[-1], count), ts)
        u, u_dot, w, w_dot, work, drive = r.source.states(grid - r.t0)
        bad = self._bad(r.source.forces(u, u_dot, w, w_dot))
        found, side = None, 'right'
        if bad.any():
            k = int(np.argmax(bad))
            if k == 0:                   # fails at its start (t = 0): the engine's from there
                side = 'left'
                found = float(grid[0]), check_validity(grid[:1], r.source.forces(
                    u[:1], u_dot[:1], w[:1], None if w_dot is None else w_dot[:1]), self.mu)
            else:
                found = self._crossing(float(grid[k - 1]), float(grid[k]))
            r.checked = found[0]
        else:
            r.checked = float(ts[-1])
        end = len(ts) if found is None else int(np.searchsorted(ts, found[0], side))
        at = np.searchsorted(grid, ts[:end])
        return (self._rolling_samples(u[at], u_dot[at], w[at],
                                      None if w_dot is None else w_dot[at], work[at], drive[at])
                if end else None), found

    def _rolling_samples(self, u, u_dot, w, w_dot, work, drive_work):
        r = self._rolling
        g, a, b, q = r.source.poses(u)
        f = r.source.forces(u, u_dot, w, w_dot)
        force_a, force_b = r.source.world_forces(f)
        if len(u):
            self._phase = float(u[-1])
        return dict(engine=np.zeros(len(u), dtype=bool), phase=u, phase_rate=u_dot,
                    angular_speed=w, position_g=g + r.world_shift,
                    contact_a=a + r.world_shift, contact_b=b + r.world_shift, quaternion=q,
                    force_a=force_a, force_b=force_b, normal_a=f.normal_a,
                    normal_b=f.normal_b, mu_required=f.mu_required, energy=r.energy(u, w),
                    touching=np.ones((len(u), 2), dtype=bool),
                    velocity_g=np.full((len(u), 3), np.nan),
                    angular_velocity=np.full((len(u), 3), np.nan), dissipated=work,
                    drive_work=drive_work)

    def _to_engine(self, t_switch, report):
        r = self._rolling
        u, _, w = (float(x[0]) for x in r.source.state_at([t_switch - r.t0])[:3])
        state = engine_state(self.dynamics, u, w, r.yaw, r.shift[:2])
        self.prepare()
        self._start_engine(state.qpos, state.qvel, t_switch)
        self._phase = u
        self.stretches[-1].t_end = t_switch
        what = {'lift-off A': 'lift-off of A: N_A reaches 0 N',
                'lift-off B': 'lift-off of B: N_B reaches 0 N'}.get(
            report.kind, f'slip: mu_required reaches mu = {self.mu:g}')
        what, why = what.split(': ')
        self.stretches.append(Stretch('engine', t_switch, math.inf,
                                      f'{what} at t = {t_switch:.9g} s ({why})',
                                      energy=float(r.energy(u, w))))

    # -- engine ---------------------------------------------------------------------------
    def _advance(self, t):
        """Step the engine to t (s), checking the return rule after each step: the return
        time, or None."""
        e, rule, stretch = self._engine, self.rule, self.stretches[-1]
        while e.data.time < t - 1e-12:
            before = float(e.data.time)    # after mj_step the contacts are this state's
            e.step_to(min(e.data.time + e.timestep, t))
            now = float(e.data.time)
            touching, slip, normal = e.contact_speeds()
            if not touching.any():
                if stretch.flights and stretch.flights[-1][1] == -1.0:
                    pass
                else:
                    stretch.flights.append([before, -1.0])
            elif stretch.flights and stretch.flights[-1][1] == -1.0:
                stretch.flights[-1][1] = before
            if touching.all() and slip.max() < rule.slip_speed \
                    and normal.max() < rule.normal_speed:
                if self._held_since is None:
                    self._held_since = now
                if now - self._held_since >= rule.hold - 1e-12 and self._try_return(now):
                    return now
            else:
                self._held_since = None
        return None

    def _try_return(self, now):
        e = self._engine
        qpos, qvel = e.data.qpos.copy(), e.data.qvel.copy()
        near = nearest_rolling(self.dynamics, qpos, qvel, near_phase=self._phase,
                               slope=self.slope)
        source = self._first.restart(near.phase, near.angular_speed, near.yaw, self.method,
                                     self.tolerance)
        _, u_dot, _, w_dot = source.state_at([0.0])[:4]
        if self._bad(source.forces(np.array([near.phase]), u_dot,
                                   np.array([near.angular_speed]), w_dot))[0]:
            self._held_since = None       # rolling would not hold there: hold again
            return False
        self._rolling = _Rolling(source, now, near.shift, self.weight)
        self._phase = near.phase
        stretch = self.stretches[-1]
        stretch.t_end = now
        if stretch.flights and stretch.flights[-1][1] == -1.0:
            stretch.flights[-1][1] = now
        self.stretches.append(Stretch(
            'rolling', now, math.inf,
            f'rolling again at t = {now:.9g} s (mismatch: tilt {near.angle_mismatch:.3g} rad, '
            f'height {near.height_mismatch:.3g} m, velocity {near.velocity_mismatch:.3g} m/s, '
            f'energy added {near.energy_mismatch:.3g} J)', mismatch=near,
            energy=float(self._rolling.energy(near.phase, near.angular_speed)),
            yaw=near.yaw, shift=(float(near.shift[0]), float(near.shift[1])),
            engine_state=(qpos, qvel)))
        return True

    def _grid_rolling(self, normal, omega, energy):
        """(u, w) published for an engine sample: the phase of :data:`PHASE_GRID` per cycle
        within π of the last one whose rolling pose has the closest ground normal to
        ``normal`` (body frame), and w from E = ½ M v² + ½ ωᵀIω + M g cos β z (J) as the
        return map does (:func:`~twodisk_ros.engine.state.nearest_rolling` solves for u
        exactly: 30 ms)."""
        k0 = int(np.floor(self._phase / (2 * np.pi) * PHASE_GRID))
        ks = k0 + np.arange(-PHASE_GRID // 2, PHASE_GRID // 2 + 1)
        k = int(ks[np.argmax(self._normals[ks % PHASE_GRID] @ normal)])
        u = 2 * np.pi * k / PHASE_GRID
        d = self.dynamics
        twice = 2.0 * (energy - self._cos * float(d.potential(np.array([u]))[0]))
        speed = math.sqrt(max(twice, 0.0) / float(d.contact_line_inertia(np.array([u]))[0]))
        omega_u = d.body.phase_angular_velocity(np.array([u]))[0]
        return u, math.copysign(speed, float(omega @ omega_u))

    def _lowest_rim_point(self, rotation, g, disk):
        if self._rims is None:
            self._rims = disk_rims(self.dynamics.body, closed=False)
        points = self._rims[disk] @ rotation.T + g
        return points[int(np.argmin(points[:, 2]))]

    def _engine_sample(self):
        e, mass = self._engine, self.dynamics.mass
        qpos, qvel = e.data.qpos, e.data.qvel
        q = qpos[3:7] / np.linalg.norm(qpos[3:7])
        rotation = quaternion_matrix(q)
        c = e.contact_details()
        points = [c.point[k] if np.all(np.isfinite(c.point[k]))
                  else self._lowest_rim_point(rotation, qpos[:3], k) for k in range(2)]
        v, omega = qvel[:3], qvel[3:]
        kinetic = 0.5 * mass.mass * (v @ v) + 0.5 * omega @ mass.inertia @ omega
        weight = mass.mass * self.dynamics.gravity
        energy = kinetic + weight * qpos[2]
        if self.slope:      # the slope frame's: V = M g (z cos β − x sin β)
            energy = kinetic + weight * self._cos * qpos[2]
        phase, speed = self._grid_rolling(rotation[2], omega, energy)
        if self.slope:
            energy -= weight * self._sin * qpos[0]
        self._phase = phase
        normal = c.force[:, 2]
        with np.errstate(divide='ignore', invalid='ignore'):
            ratio = np.where(c.touching & (normal > 0),
                             np.linalg.norm(c.force[:, :2], axis=1) / normal, np.nan)
        u_dot = self.dynamics.initial_phase_rate(phase, speed)
        g, force, omega = qpos[:3].copy(), c.force, rotation @ omega
        quaternion = np.array([q[1], q[2], q[3], q[0]])
        if self.slope:      # slope frame → gravity frame (the published world)
            tilt = self._tilt
            g, points, force, v, omega = (x @ tilt.T for x in (g, np.array(points), force, v,
                                                               omega))
            half = 0.5 * self.slope
            quaternion = quaternion_product([0.0, math.sin(half), 0.0, math.cos(half)],
                                            quaternion)
        return dict(engine=True, phase=phase, phase_rate=u_dot,
                    angular_speed=speed, position_g=g,
                    contact_a=points[0], contact_b=points[1],
                    quaternion=quaternion, force_a=force[0],
                    force_b=force[1], normal_a=normal[0], normal_b=normal[1],
                    mu_required=float(np.nanmax(ratio)) if np.any(np.isfinite(ratio))
                    else math.nan, energy=energy, touching=c.touching, velocity_g=v.copy(),
                    angular_velocity=omega, dissipated=math.nan,
                    drive_work=e.moment_work)

    # -- sampling -------------------------------------------------------------------------
    def sample(self, t):
        """:class:`HybridSamples` at times t (s, increasing, after earlier calls)."""
        t = np.asarray(t, dtype=float)
        parts, k = [], 0
        while k < len(t):
            if self._rolling is not None:
                values, found = self._rolling_block(t[k:])
                if values is not None:
                    parts.append(values)
                    k += len(values['phase'])
                if found is not None:
                    self._to_engine(*found)
            else:
                back = self._advance(float(t[k]))
                if back is None:
                    parts.append({key: np.asarray(value)[None] for key, value in
                                  self._engine_sample().items()})
                    k += 1
        keys = HybridSamples.__dataclass_fields__
        joined = {key: np.concatenate([p[key] for p in parts]) if parts
                  else np.zeros((0, 3) if key in ('position_g', 'contact_a', 'contact_b',
                                                   'force_a', 'force_b', 'velocity_g',
                                                   'angular_velocity') else 0)
                  for key in keys if key != 't'}
        if not parts:
            joined['quaternion'] = np.zeros((0, 4))
            joined['touching'] = np.zeros((0, 2), dtype=bool)
        return HybridSamples(t=t, **joined)

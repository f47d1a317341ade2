"""The node's simulation under ``contact_model:=hybrid`` (issue 31): no rclpy here.

:class:`HybridSimulation` is the :class:`~twodisk_ros.run.simulation.Simulation` of the flat
free scene whose samples come from :class:`~twodisk_ros.run.hybrid.HybridMotion`: exact
rolling while it holds, MuJoCo's free body from the instant it stops holding, rolling again
once both contacts roll; on a slope, with damping, and with a drive whose commands continue
the motion from the last sample, rolling or engine (:meth:`HybridSimulation.continued`).
Nothing is marked invalid: ``/diagnostics`` says which model runs
and why (:meth:`HybridSimulation.contact_status`), the node publishes each switch on
``events`` (:meth:`HybridSimulation.switches`).

The invariant: in a rolling stretch the energy E + W − W_d against the stretch's start
(exact rolling keeps it); in an engine stretch only an increase of E − W_d counts, beyond
:data:`ENGINE_SINK` × M g (the soft contact's sinking, whose spring energy E does not hold):
the engine loses energy where the plates' polygons roll over a vertex (docs/physics.md).
"""

from dataclasses import dataclass
import math

import numpy as np

from ..physics.motion.dynamics import PhaseState
from ..physics.scenes.scene import quaternion_product
from .simulation import Sample, Simulation, continuous_quaternions

__all__ = ['ENGINE_SINK', 'HybridForces', 'HybridSimulation', 'SCENE_FIXED', 'simulation_of']

#: the refusal of a runtime scene change (one line)
SCENE_FIXED = ('contact_model hybrid takes no scene changes at run time (set slope, damping '
               'and drive at the start; commands, friction, reset and pause work)')

#: m: an engine stretch's energy may exceed its start by M g × this (G sinks 1.4e-5 m into
#: the ground with the engine's defaults, engine/model.py)
ENGINE_SINK = 2e-5


@dataclass
class HybridForces:
    """The ground's forces of a block (arrays over samples, N, world frame): the rolling
    model's in rolling samples, the engine's contact forces per disk in engine samples (0
    for a disk in the air; ``mu_required`` is then the largest |tangential| / normal used,
    NaN with no contact)."""

    force_a: np.ndarray
    force_b: np.ndarray
    normal_a: np.ndarray
    normal_b: np.ndarray
    mu_required: np.ndarray


def simulation_of(settings, run=None, **kwargs):
    """The Simulation of ``settings``: :class:`HybridSimulation` for ``contact_model``
    hybrid, else :class:`~twodisk_ros.run.simulation.Simulation` (bit for bit as before)."""
    kind = HybridSimulation if settings.contact_model == 'hybrid' else Simulation
    return kind(settings, run, **kwargs)


class HybridSimulation(Simulation):
    """:class:`~twodisk_ros.run.simulation.Simulation` under ``contact_model:=hybrid``.

    ``engine``: an Engine of the same body, mass, g, slope and damping to reuse (a reset's,
    a command's); ``resume``: (yaw rad, shift m, engine state or None, reason) of a motion
    continued from a sample (:meth:`continued`)."""

    def __init__(self, settings, run=None, *, engine=None, resume=None, **kwargs):
        super().__init__(settings, run, **kwargs)
        from .hybrid import HybridMotion   # (MuJoCo and the meshes: only for hybrid runs)
        from .hybrid_rolling import FreeRolling, SceneRolling, rolling_source
        s = self.settings
        rolling, options = None, {}
        self.invalid = None               # (a slope's standing report: the engine's to show)
        start = self.initial_state()
        if resume is not None:
            yaw, shift, engine_start, reason = resume
            rolling = rolling_source(self.dynamics, self.forces, self.scene.terms,
                                     self.scene.scene, start.phase, start.angular_speed, yaw,
                                     s.method, s.tolerance)
            options = dict(shift=shift, engine_start=engine_start, reason=reason)
        elif self.scene.scene.flat_free:    # (also a torque drive at 0)
            rolling = FreeRolling(self.dynamics, self.forces, self.stream)
        else:                               # slope, damping, drive (parameters.py)
            rolling = SceneRolling(self.dynamics, self.scene.terms, self.stream, start.phase,
                                   start.angular_speed, self.forces)
        self.hybrid = HybridMotion(self.dynamics, self.forces, self.stream, s.friction,
                                   method=s.method, tolerance=s.tolerance, rolling=rolling,
                                   damping=s.damping, engine=engine, **options).prepare()
        self.announced = 1          # stretches already published as events

    def sample(self, t, forces=False, time_offset=0.0):
        """As :meth:`Simulation.sample`; the forces are always there (the switches need
        them) and the block's :class:`~twodisk_ros.run.hybrid.HybridSamples` is ``hybrid``."""
        h = self.hybrid.sample(t)
        quaternion = continuous_quaternions(h.quaternion, self._last_quaternion)
        if len(quaternion):
            self._last_quaternion = quaternion[-1]
        theta, psi, dtheta, dpsi = self.body.phase_angles_with_rates(h.phase)
        with np.errstate(invalid='ignore'):
            theta_rate, psi_rate = dtheta * h.phase_rate, dpsi * h.phase_rate
        contact = HybridForces(h.force_a, h.force_b, h.normal_a, h.normal_b, h.mu_required)
        return Sample(t=h.t, phase=h.phase, phase_rate=h.phase_rate, theta=theta, psi=psi,
                      theta_rate=theta_rate, psi_rate=psi_rate, position_g=h.position_g,
                      contact_a=h.contact_a, contact_b=h.contact_b, quaternion=quaternion,
                      forces=contact, angular_speed=h.angular_speed, hybrid=h)

    def update(self, settings):
        """Take settings that leave the motion unchanged; a new friction is the rolling
        model's and the engine's from the next block sampled on (also in an engine stretch)."""
        super().update(settings)
        self.hybrid.set_friction(settings.friction)

    def stretch_at(self, t):
        """The :class:`~twodisk_ros.run.hybrid.Stretch` holding time t (s, this motion's)."""
        for stretch in reversed(self.hybrid.stretches):
            if stretch.t_start <= t:
                return stretch
        return self.hybrid.stretches[0]

    def switches(self, sample, start, stop):
        """[(index, text)]: the stretches not yet announced whose first sample is among
        [start, stop) of the block ``sample``, with the event's text (``contact_model
        <model>: <reason>``); marks them announced. A stretch's first sample is the first
        with t_start ≤ t < t_end of its model; a stretch that ended before any sample (a
        flight or a rolling stretch shorter than a sample period) is announced at the next
        sample, its text saying so. The indices are ≥ start and non-decreasing."""
        found = []
        stretches = self.hybrid.stretches
        t, engine = sample.t, sample.hybrid.engine
        floor = start
        while self.announced < len(stretches):
            stretch = stretches[self.announced]
            mine = np.flatnonzero((t >= stretch.t_start)
                                  & ((engine == (stretch.model == 'engine'))
                                     | (t >= stretch.t_end)))
            mine = mine[mine >= floor]
            if not mine.size or mine[0] >= stop:
                break
            j = int(mine[0])
            text = f'contact_model {stretch.model}: {stretch.reason}'
            if t[j] >= stretch.t_end:
                text += (f' (ended at t = {stretch.t_end:.9g} s, before any sample: '
                         'announced at the next sample)')
            found.append((j, text))
            self.announced += 1
            floor = j
        return found

    def switches_so_far(self, t):
        """How many switches of contact model happened by time t (s, this motion's): the
        stretches after the first with t_start ≤ t."""
        return sum(1 for stretch in self.hybrid.stretches[1:] if stretch.t_start <= t)

    def contact_status(self, sample, i):
        """(level, message, values): which model runs and why, with the contact values."""
        h = sample.hybrid
        stretch = self.stretch_at(float(sample.t[i]))
        values = [('contact_model', 'hybrid'),
                  ('model', 'engine' if h.engine[i] else 'rolling'),
                  ('model_since', stretch.t_start), ('model_reason', stretch.reason),
                  ('switches', self.switches_so_far(float(sample.t[i])))]
        if not h.engine[i]:
            level, message, rolling = super().contact_status(sample, i)
            if stretch.mismatch is not None and level == 0:
                message = f'rolling again since t = {stretch.t_start:.6g} s'
            return level, message, rolling + values
        touching = h.touching[i]
        values += [('normal_a', float(h.normal_a[i])), ('normal_b', float(h.normal_b[i])),
                   ('touching_a', bool(touching[0])), ('touching_b', bool(touching[1])),
                   ('friction', self.settings.friction)]
        air = [name for name, on in zip('AB', touching) if not on]
        where = f'; {" and ".join(air)} in the air' if air else ''
        return 0, f'free body (MuJoCo) since t = {stretch.t_start:.6g} s{where}', values

    def invariant(self, sample, i):
        """('energy', E, drift): rolling: |E + W − E_stretch| / (M g L) (W the work done
        against the damping since the stretch's start, 0 without); engine: only the rise
        above E_stretch + :data:`ENGINE_SINK` × M g counts (module docstring)."""
        energy = float(sample.hybrid.energy[i])
        stretch = self.stretch_at(float(sample.t[i]))
        scale = self.dynamics.energy_scale
        drive = float(sample.hybrid.drive_work[i])
        if sample.hybrid.engine[i]:
            rise = energy - drive - stretch.energy - ENGINE_SINK * self.weight
            return 'energy', energy, max(rise, 0.0) / scale
        balance = energy + float(sample.hybrid.dissipated[i]) - drive
        return 'energy', energy, abs(balance - stretch.energy) / scale

    def energy(self, sample, i):
        """E (J) at sample i: the rolling energy, or the engine's ½ M v² + ½ ωᵀIω + M g z."""
        return float(sample.hybrid.energy[i])

    def check_scene_change(self, settings):
        """A hybrid run's scene is fixed at its start: a runtime change of it is refused."""
        if settings.scene_differs(self.settings):
            raise ValueError(SCENE_FIXED)

    def restarted(self):
        """The motion from the start again (a reset), with this run's engine."""
        return HybridSimulation(self.settings, self.run, engine=self.hybrid.engine)

    def continued(self, settings, sample, i, *, drive=None, command=None):
        """The hybrid motion continued from sample i under ``drive``/``command`` (a command
        or its time-out; the same scene otherwise): from a rolling sample exact rolling of
        the new drive from its state, at its stretch's heading and shift; from an engine
        sample the engine from the sample's state (pose, v_G, ω), with the new drive."""
        if settings.physics_differs(self.settings) or settings.scene_differs(self.settings):
            raise ValueError(SCENE_FIXED)
        h, t = sample.hybrid, float(sample.t[i])
        start = PhaseState(float(sample.phase[i]), float(sample.phase_rate[i]),
                           self.angular_speed(sample, i))
        if h.engine[i]:
            resume = (self.scene.terms.phi0, (0.0, 0.0), self._engine_state(h, i),
                      f'free body (MuJoCo) continued at t = {t:.9g} s of the last motion')
        else:
            stretch = self.stretch_at(t)
            resume = (stretch.yaw, stretch.shift, None,
                      f'exact rolling continued at t = {t:.9g} s of the last motion')
        return HybridSimulation(settings, self.run if self.run.settings == settings else None,
                                drive=drive, command=command, start=start,
                                terms=self.scene.terms, orientation=sample.quaternion[i],
                                engine=self.hybrid.engine, resume=resume)

    def _engine_state(self, h, i):
        """(qpos, qvel) in the slope frame of engine sample i of HybridSamples h (published
        in the gravity frame: R_y(β)ᵀ, q_y(−β) ⊗ q; ω to the body frame)."""
        half, c, s = 0.5 * self.settings.slope, math.cos(self.settings.slope), math.sin(
            self.settings.slope)
        back = np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])
        x, y, z, w = quaternion_product([0.0, -math.sin(half), 0.0, math.cos(half)],
                                        h.quaternion[i])
        q = np.array([w, x, y, z]) / math.sqrt(w * w + x * x + y * y + z * z)
        from ..engine.state import quaternion_matrix   # (scipy.spatial: hybrid runs only)
        rotation_world = back.T @ quaternion_matrix(q)
        return (np.concatenate([back @ h.position_g[i], q]),
                np.concatenate([back @ h.velocity_g[i], rotation_world.T @ h.angular_velocity[i]]))

"""The runs behind the hybrid figures (issue 31): the rounded square's vertices, the oloid's
hops, and the engine alone from the same starts (no matplotlib here).

* :func:`square_runs`: config/rounded_square.yaml (ω0 = 3 rad/s, μ = 0.5) in
  ``contact_model:=hybrid`` over ``span`` s, sampled at the engine's step; the same start
  in MuJoCo alone (:class:`~twodisk_ros.engine.run.Engine`, the same
  :class:`~twodisk_ros.engine.model.ContactParameters`); each hybrid engine stretch
  classified (:func:`classify`) with the energy it lost; the engine alone's stretches found
  by the hybrid's own return rule; and the engine restarted at each hybrid rolling stretch's
  start against the exact rolling motion over that stretch (its accumulated error).
* :func:`oloid_hops`: config/oloid.yaml (friction μ = 5, so that it lifts off before it
  slips) started at ω0 in a list: the lift-off instant and speed, each flight's rise against
  the ballistic v_z0² / (2 g), in the hybrid and in the engine alone; :func:`liftoff_threshold`
  the smallest ω0 at which the exact rolling motion lifts a contact off.

Units SI throughout (s, m, J, rad/s).
"""

from dataclasses import dataclass, field
import math
import time

import numpy as np

from ..engine.model import ContactParameters
from ..engine.run import Engine
from ..engine.state import engine_state
from ..physics.forces.contact import ContactForceModel
from ..physics.forces.validity import check_validity, liftoff_speed
from ..physics.motion.simulate import MotionStream
from ..run.description import RunDescription
from ..run.hybrid import HybridMotion, ReturnRule
from ..run.parameters import DEFAULTS

__all__ = ['ROUNDED_SQUARE', 'OLOID', 'OLOID_PHASE', 'EngineAlone', 'Vertex', 'classify',
           'description', 'engine_alone', 'liftoff_threshold', 'oloid_hops',
           'rolling_stretch_errors', 'slip_speeds',
           'square_runs']

#: config/rounded_square.yaml's parameters
ROUNDED_SQUARE = dict(shape='superellipse', exponent=4.0, a=0.1, b=0.1, delta=0.05,
                      arrangement='parallel', mass=1.0, gravity=9.81, mass_model='laminae',
                      theta0=0.3, branch=1, omega0=3.0)
#: config/oloid.yaml's parameters, with μ = 5 (the oloid slips before it lifts off at 0.5)
OLOID = dict(a=0.1, b=0.1, delta=0.05, mass=1.0, gravity=9.81, mass_model='laminae',
             theta0=0.3, branch=1, omega0=3.0, friction=5.0)
#: rad: the oloid's start phase, midway between the phases 0 and π/2 where B and A lift off
OLOID_PHASE = 0.25 * math.pi


def description(values, **changes):
    """The :class:`RunDescription` of ``values`` (node parameters) in contact_model hybrid."""
    settings = DEFAULTS.with_values(**{**values, **changes}, contact_model='hybrid').checked()
    return settings, RunDescription(settings)


def _energy(mass, gravity, qpos, qvel):
    """½ M v² + ½ ωᵀ I ω + M g z (J) of engine states (n, 7), (n, 6)."""
    v, omega = qvel[:, :3], qvel[:, 3:]
    return (0.5 * mass.mass * np.einsum('ij,ij->i', v, v)
            + 0.5 * np.einsum('ij,jk,ik->i', omega, mass.inertia, omega)
            + mass.mass * gravity * qpos[:, 2])


@dataclass
class EngineAlone:
    """The engine alone at each of its steps: t (n,), qpos (n, 7), qvel (n, 6), energy (n,)
    J, touching (n, 2), slip and normal (n,) the largest contact speeds (m/s), stretches
    [(t0, t1)] where the return rule did not hold (t1 when it had held ``hold`` s again),
    cpu (s) of the stepping."""

    t: np.ndarray
    qpos: np.ndarray
    qvel: np.ndarray
    energy: np.ndarray
    touching: np.ndarray
    slip: np.ndarray
    normal: np.ndarray
    stretches: list = field(default_factory=list)
    cpu: float = math.nan


def engine_alone(engine, dynamics, u0, w0, span, rule):
    """Step ``engine`` from the exact rolling state (u0, w0) at t = 0 for ``span`` s, keeping
    every step (:class:`EngineAlone`); stretches by ``rule`` (:class:`ReturnRule`)."""
    start = engine_state(dynamics, u0, w0)
    engine.set_state(start.qpos, start.qvel, 0.0)
    steps = int(round(span / engine.timestep))
    t, qpos, qvel = np.empty(steps + 1), np.empty((steps + 1, 7)), np.empty((steps + 1, 6))
    touching = np.empty((steps + 1, 2), dtype=bool)
    slip, normal = np.empty(steps + 1), np.empty(steps + 1)
    clock = time.process_time()
    for k in range(steps + 1):
        if k:
            engine.step_to(k * engine.timestep)
        d = engine.data
        t[k], qpos[k], qvel[k] = d.time, d.qpos, d.qvel
        on, s, n = engine.contact_speeds()
        touching[k], slip[k], normal[k] = on, s.max(), n.max()
    cpu = time.process_time() - clock
    rolling = touching.all(axis=1) & (slip < rule.slip_speed) & (normal < rule.normal_speed)
    stretches, begin, held = [], None, None
    for k in range(steps + 1):
        if begin is None:
            if not rolling[k]:
                begin, held = t[k], None
        elif rolling[k]:
            held = t[k] if held is None else held
            if t[k] - held >= rule.hold - 1e-12:
                stretches.append((begin, t[k]))
                begin = None
        else:
            held = None
    if begin is not None:
        stretches.append((begin, math.inf))
    energy = _energy(dynamics.mass, dynamics.gravity, qpos, qvel)
    return EngineAlone(t, qpos, qvel, energy, touching, slip, normal, stretches, cpu)


@dataclass(frozen=True)
class Vertex:
    """One engine stretch of the hybrid: t0, t1 (s), reason ('slip', 'lift-off A', …), kind
    ('hop': both disks in the air at some step; 'rattle': a disk left and touched again
    more than once; 'rock': one disk left and touched again once; 'slide': both always
    touch), energy_lost (J, the rolling energy at the switch minus the one resumed),
    max_slip (m/s, largest contact-point speed along the ground), slide (m, ∫ the slip speed
    of A and B dt summed), max_rise (m, the largest z_G above the exact rolling pose's at
    the same phase, of the sampled engine states)."""

    t0: float
    t1: float
    reason: str
    kind: str
    energy_lost: float
    max_slip: float
    slide: float
    max_rise: float


def slip_speeds(samples):
    """|horizontal speed| of each disk's contact point (n, 2) m/s (0 where in the air)."""
    out = np.zeros((len(samples.t), 2))
    for j, point in enumerate((samples.contact_a, samples.contact_b)):
        v = samples.velocity_g + np.cross(samples.angular_velocity, point - samples.position_g)
        out[:, j] = np.where(samples.touching[:, j], np.hypot(v[:, 0], v[:, 1]), 0.0)
    return out


def classify(touching, flights):
    """'hop', 'rattle', 'rock' or 'slide' from per-step touching (n, 2) and the flights
    (:class:`Vertex`)."""
    if flights:
        return 'hop'
    landings = int(np.sum(touching[1:] & ~touching[:-1]))
    if landings > 1:
        return 'rattle'
    return 'rock' if landings == 1 or not touching.all() else 'slide'


def _vertices(motion, samples, dynamics):
    out, stretches = [], motion.stretches
    speeds = slip_speeds(samples)
    for k, s in enumerate(stretches):
        if s.model != 'engine' or not math.isfinite(s.t_end):
            continue
        inside = (samples.t >= s.t_start) & (samples.t <= s.t_end) & samples.engine
        touching = samples.touching[inside]
        slips = speeds[inside]
        dt = np.diff(samples.t[inside], prepend=s.t_start)
        rolling_z = dynamics.body.phase_height(samples.phase[inside])
        out.append(Vertex(
            s.t_start, s.t_end, s.reason.split(' at ')[0], classify(touching, s.flights),
            s.energy - stretches[k + 1].energy, float(slips.max(initial=0.0)),
            float(np.sum(slips.sum(axis=1) * dt)),
            float(np.max(samples.position_g[inside, 2] - rolling_z, initial=0.0))))
    return out


def rolling_stretch_errors(engine, motion, samples, dynamics, finished=True):
    """The engine restarted at each rolling stretch's start from its exact rolling state,
    stepped to the stretch's samples: [(t0, t1 (s), max |G − G_exact| (m), energy lost by
    the engine (J))]; only the finished stretches, or (``finished`` False) the last one too,
    to the last sample."""
    out = []
    for s in motion.stretches:
        if s.model != 'rolling' or (finished and not math.isfinite(s.t_end)):
            continue
        inside = (samples.t >= s.t_start) & (samples.t <= s.t_end) & ~samples.engine
        t = samples.t[inside]
        if len(t) < 2:
            continue
        near = s.mismatch
        start = (engine_state(dynamics, samples.phase[inside][0], samples.angular_speed
                              [inside][0]) if near is None else
                 engine_state(dynamics, near.phase, near.angular_speed, near.yaw, near.shift))
        engine.set_state(start.qpos, start.qvel, t[0])
        g = np.empty((len(t), 3))
        for j, tj in enumerate(t):
            engine.step_to(tj)
            g[j] = engine.data.qpos[:3]
        e = _energy(dynamics.mass, dynamics.gravity, engine.data.qpos[None],
                    engine.data.qvel[None])[0]
        error = np.linalg.norm(g - samples.position_g[inside], axis=1)
        out.append((s.t_start, float(t[-1]), float(error.max()), float(s.energy - e)))
    return out


def _hybrid(model, dynamics, mu, u0, w0, engine, times, block=1000):
    start = dynamics.initial_state(u0, w0)
    stream = MotionStream(dynamics, start.phase, start.phase_rate, angular_speed=w0)
    motion = HybridMotion(dynamics, model, stream, mu, engine=engine).prepare()
    clock = time.process_time()
    parts = [motion.sample(times[i:i + block]) for i in range(0, len(times), block)]
    cpu = time.process_time() - clock
    joined = {name: np.concatenate([getattr(p, name) for p in parts])
              for name in parts[0].__dataclass_fields__}
    return motion, type(parts[0])(**joined), cpu


def square_runs(span=20.0, parameters=None):
    """The rounded square in hybrid and in the engine alone over ``span`` s (module
    docstring): a dict with settings, dynamics, hybrid (HybridMotion), samples (its
    HybridSamples at every engine step), vertices [:class:`Vertex`], alone
    (:class:`EngineAlone`), rolling_errors (:func:`rolling_stretch_errors`), cpu_hybrid (s)."""
    settings, run = description(ROUNDED_SQUARE)
    dynamics, model = run.dynamics, ContactForceModel(run.dynamics)
    p = parameters or ContactParameters(mu=settings.friction)
    engine = Engine(dynamics.body, dynamics.mass, dynamics.gravity, p)
    times = np.arange(int(round(span / p.timestep)) + 1) * p.timestep
    u0 = run.start().phase
    motion, samples, cpu = _hybrid(model, dynamics, settings.friction, u0,
                                   settings.omega0, engine, times)
    rule = ReturnRule.for_body(dynamics.body.size, dynamics.gravity)
    alone = engine_alone(engine, dynamics, u0, settings.omega0, span, rule)
    errors = rolling_stretch_errors(engine, motion, samples, dynamics)
    return dict(settings=settings, dynamics=dynamics, hybrid=motion, samples=samples,
                vertices=_vertices(motion, samples, dynamics), alone=alone,
                rolling_errors=errors, cpu_hybrid=cpu, rule=rule)


def _lifts(dynamics, model, u0, w0, t):
    """The exact rolling motion from (u0, w0): (stream, index of the first sample of t where
    N_A or N_B < 0, or None)."""
    start = dynamics.initial_state(u0, w0)
    stream = MotionStream(dynamics, start.phase, start.phase_rate, angular_speed=w0)
    u, _, w = stream.sample_with_speed(t)
    report = check_validity(t, model.dynamic(u, angular_speed=w), math.inf)
    return stream, (None if report.valid else report.index)


def liftoff_threshold(dynamics, model, u0, span=2.0, step=1e-4, low=4.0, high=12.0,
                      rtol=1e-9):
    """The smallest ω0 (rad/s) in [low, high] from phase u0 at which the exact rolling motion
    lifts a contact off (N_A or N_B < 0; friction not considered) within ``span`` s (forces
    checked every ``step`` s), by bisection to ``rtol``; and at that ω0 the lift-off instant
    (s, N's zero bracketed by the samples and found by Brent's method on the dense solution
    to 1e-13 s), its phase (rad) and speed |w| (rad/s): (ω0, t, u, |w|)."""
    from scipy.optimize import brentq
    t = np.arange(0.0, span, step)

    def lifts(w0):
        return _lifts(dynamics, model, u0, w0, t)[1] is not None

    if lifts(low) or not lifts(high):
        raise ValueError(f'no lift-off threshold between {low} and {high} rad/s')
    while high - low > rtol * high:
        mid = 0.5 * (low + high)
        low, high = (low, mid) if lifts(mid) else (mid, high)
    stream, k = _lifts(dynamics, model, u0, high, t)

    def normal(time):
        u, _, w = stream.state_at([time])
        f = model.dynamic(u, angular_speed=w)
        return float(min(f.normal_a[0], f.normal_b[0]))

    when = brentq(normal, t[k - 1], t[k], xtol=1e-13) if k else 0.0
    u, _, w = stream.state_at([when])
    return high, when, float(u[0]), abs(float(w[0]))


def _flights(t, z, vz, touching, gravity):
    """[(t0, t1, rise (m), ballistic rise v_z0²/(2g) (m))] of the steps with no contact, for
    flights that begin rising and reach their apex in the air."""
    air = ~touching.any(axis=1)
    edges = np.flatnonzero(np.diff(air.astype(int)))
    starts = [k + 1 for k in edges if air[k + 1]]
    out = []
    for k0 in starts:
        k1 = k0
        while k1 + 1 < len(t) and air[k1 + 1]:
            k1 += 1
        if vz[k0] > 0 and k1 > k0 + 2 and vz[k1] < 0:
            out.append((float(t[k0]), float(t[k1]), float(z[k0:k1 + 1].max() - z[k0]),
                        float(vz[k0] ** 2 / (2 * gravity))))
    return out


def _first_separation(t, touching, least=0.005):
    """The first time (s) a disk leaves the ground for at least ``least`` s (NaN if never)."""
    off = ~touching.all(axis=1)
    k = 0
    while k < len(t):
        if off[k]:
            j = k
            while j + 1 < len(t) and off[j + 1]:
                j += 1
            if t[j] - t[k] >= least:
                return float(t[k])
            k = j
        k += 1
    return math.nan


def oloid_hops(omegas, span=1.0, u0=OLOID_PHASE):
    """The oloid (:data:`OLOID`) started at phase u0 (rad) at each ω0 of ``omegas`` (rad/s):
    a dict with critical (Ω_c, phase, contact) of :func:`~twodisk_ros.physics.forces.
    validity.liftoff_speed`, threshold (ω0, t, u, |w|) (:func:`liftoff_threshold`), and runs:
    per ω0 the hybrid's first switch (time, reason) and the engine alone's first separation
    of ≥ 5 ms (s), each one's flights (:func:`_flights`), z_G (n,) at the steps t (n,) and
    cpu (s)."""
    settings, run = description(OLOID)
    dynamics, model = run.dynamics, ContactForceModel(run.dynamics)
    mu, g = settings.friction, dynamics.gravity
    p = ContactParameters(mu=mu)
    engine = Engine(dynamics.body, dynamics.mass, g, p)
    threshold = liftoff_threshold(dynamics, model, u0)
    times = np.arange(int(round(span / p.timestep)) + 1) * p.timestep
    rule = ReturnRule.for_body(dynamics.body.size, g)
    runs = []
    for w0 in omegas:
        motion, s, cpu = _hybrid(model, dynamics, mu, u0, w0, engine, times)
        first = next((x for x in motion.stretches if x.model == 'engine'), None)
        hybrid = dict(switch=first.t_start if first is not None else math.nan,
                      reason=first.reason if first is not None else '',
                      flights=_flights(s.t, s.position_g[:, 2],
                                       np.where(s.engine, s.velocity_g[:, 2], 0.0),
                                       s.touching, g),
                      z=s.position_g[:, 2], t=s.t, cpu=cpu, engine=s.engine,
                      stretches=[(x.model, x.t_start, x.t_end) for x in motion.stretches])
        alone = engine_alone(engine, dynamics, u0, w0, span, rule)
        runs.append(dict(omega0=float(w0), hybrid=hybrid, alone=dict(
            separation=_first_separation(alone.t, alone.touching),
            flights=_flights(alone.t, alone.qpos[:, 2], alone.qvel[:, 2], alone.touching, g),
            z=alone.qpos[:, 2], t=alone.t, cpu=alone.cpu)))
    return dict(critical=liftoff_speed(model), threshold=threshold, runs=runs,
                dynamics=dynamics, u0=u0, timestep=p.timestep)

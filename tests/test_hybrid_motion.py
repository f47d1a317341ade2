"""The hybrid motion (issue 31, twodisk_ros/run/hybrid.py) against independent references.

The rounded square of config/rounded_square.yaml: at omega0 = 3 rad/s rolling needs more than
μ = 0.5 at 0.499 s (a slip: the engine takes over, then rolling resumes), at 15 rad/s contact
B lifts off at once and the body hops (flights of up to 30 ms). One module-scoped set-up.
"""

import math

import numpy as np
import pytest

from twodisk_ros.engine.state import engine_state, quaternion_matrix
from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.forces.validity import check_validity
from twodisk_ros.physics.motion.simulate import MotionStream
from twodisk_ros.run.description import RunDescription
from twodisk_ros.run.hybrid import HybridMotion
from twodisk_ros.run.parameters import DEFAULTS
from twodisk_ros.run.scene_simulation import SceneMotion

pytest.importorskip('mujoco')

RATE = 100.0          # Hz: the node's default sampling


def _settings():
    import yaml
    from pathlib import Path
    path = Path(__file__).resolve().parents[1] / 'config' / 'rounded_square.yaml'
    values = yaml.safe_load(path.read_text())['/**']['ros__parameters']
    return DEFAULTS.with_values(**values, contact_model='hybrid').checked()


@pytest.fixture(scope='module')
def runs():
    settings = _settings()
    run = RunDescription(settings)
    dynamics, model = run.dynamics, ContactForceModel(run.dynamics)
    slow = HybridMotion(dynamics, model, run.stream(), settings.friction)
    t_slow = np.arange(0.0, 0.75, 1.0 / RATE)
    samples_slow = [slow.sample(t_slow[:37]), slow.sample(t_slow[37:])]   # two blocks
    start = dynamics.initial_state(run.start().phase, 15.0)
    fast = HybridMotion(dynamics, model, MotionStream(dynamics, start.phase, start.phase_rate,
                                                      angular_speed=15.0),
                        settings.friction, engine=slow._engine)
    t_fast = np.arange(0.0, 0.12, 1e-3)
    return dict(settings=settings, run=run, model=model, slow=slow, fast=fast,
                t_slow=t_slow, s_slow=samples_slow, t_fast=t_fast, s_fast=fast.sample(t_fast))


def _rolling(runs):
    """The rolling run's motion (the one :class:`~twodisk_ros.run.simulation.Simulation`
    samples for the flat free scene), from t = 0."""
    run = runs['run']
    motion = SceneMotion(run.dynamics, runs['settings'], runs['model'], start=run.start(),
                         run_start=True)
    assert motion.level          # the level ground's MotionStream, poses and forces
    return motion


def test_the_stretches_alternate_with_reasons(runs):
    models = [s.model for s in runs['slow'].stretches]
    assert models == ['rolling', 'engine', 'rolling'], models
    engine = runs['slow'].stretches[1]
    assert engine.reason.startswith(f'slip at t = {engine.t_start:.9g} s'), engine.reason
    back = runs['slow'].stretches[2]
    assert back.reason.startswith(f'rolling again at t = {back.t_start:.9g} s')
    assert all(a.t_end == b.t_start for a, b in zip(runs['slow'].stretches,
                                                    runs['slow'].stretches[1:]))
    fast = runs['fast'].stretches
    assert [s.model for s in fast] == ['rolling', 'engine'] and fast[1].t_start == 0.0
    assert fast[1].reason.startswith('lift-off of B at t = 0 s'), fast[1].reason
    # rolling fails at t = 0 (N_B < 0 there): the first sample is the engine's already
    assert runs['s_fast'].engine.all() and runs['s_fast'].t[0] == 0.0


def test_switch_time_is_the_crossing_of_the_rolling_model(runs):
    """The validity functions on a fresh stream of the same run, sampled every 1e-6 s around
    the switch and at ±1e-9 s of it: rolling holds before, fails after (the switch is
    bisected to 1e-12 s, so ±1e-9 s is on either side unless the crossing is not one)."""
    switch = runs['slow'].stretches[1].t_start
    stream = runs['run'].stream()
    mu = runs['settings'].friction
    t = np.concatenate([np.arange(switch - 2e-4, switch, 1e-6), [switch - 1e-9, switch + 1e-9]])
    u, _, w = stream.sample_with_speed(t)
    forces = runs['model'].dynamic(u, angular_speed=w)
    report = check_validity(t, forces, mu)
    assert not report.valid and report.index == len(t) - 1, report
    assert report.kind == 'slip'
    rolling = _rolling(runs)       # the rolling run: invalid from the first sample after it
    t = runs['t_slow']
    u, _, _, w, _, _ = rolling.sample(t)
    report = check_validity(t, rolling.forces(u, None, None, w), mu)
    assert report.time == t[t > switch][0]


def test_rolling_samples_before_the_switch_are_the_rolling_runs(runs):
    """Bit for bit: the same stream, the same poses (yaw 0, no shift)."""
    t = runs['t_slow'][:37]
    u, u_dot, _, w, _, (g, a, b, q) = _rolling(runs).sample(t)
    hybrid = runs['s_slow'][0]
    assert t[-1] < runs['slow'].stretches[1].t_start and not hybrid.engine.any()
    for name, value in (('phase', u), ('phase_rate', u_dot), ('angular_speed', w),
                        ('position_g', g), ('contact_a', a), ('contact_b', b),
                        ('quaternion', q)):
        assert np.array_equal(getattr(hybrid, name), value), name


def test_flights_are_ballistic_and_keep_the_angular_momentum(runs):
    """G on the parabola G0 + v0 τ − ½ g τ² e_z within the engine integrator's first-order
    error ½ g h τ (semi-implicit Euler under constant gravity: h the step, 5e-4 s), the
    horizontal part to 16 ulps of the travel; L = R I Rᵀ ω about G constant within the
    first-order bound h τ |ω|² |L| of the explicit gyroscopic term."""
    s, t, g, h = runs['s_fast'], runs['t_fast'], 9.81, 5e-4
    inertia = runs['run'].mass.inertia
    checked = 0
    for a, b in runs['fast'].stretches[1].flights:
        k = np.flatnonzero((t > a) & (t < b))
        if len(k) < 4:
            continue
        assert s.engine[k].all() and not s.touching[k].any()
        tau = t[k] - t[k[0]]
        parabola = (s.position_g[k[0]] + np.outer(tau, s.velocity_g[k[0]])
                    - 0.5 * g * np.outer(tau ** 2, [0.0, 0.0, 1.0]))
        error = np.abs(s.position_g[k] - parabola)
        scale = np.max(np.abs(s.position_g[k]))
        steps = 1 + tau[:, None] / h      # rounding of one addition per step
        assert np.all(error[:, :2] <= 16 * np.finfo(float).eps * scale * steps)
        assert np.all(error[:, 2] <= 0.5 * g * h * tau * (1 + 1e-9) + 16e-16 * scale)
        momenta = []
        for j in k:
            x, y, z, w = s.quaternion[j]
            rotation = quaternion_matrix([w, x, y, z])
            momenta.append(rotation @ inertia @ rotation.T @ s.angular_velocity[j])
        momenta = np.array(momenta)
        speed = np.max(np.linalg.norm(s.angular_velocity[k], axis=1))
        bound = h * tau[-1] * speed ** 2 * np.linalg.norm(momenta[0])
        assert np.max(np.linalg.norm(momenta - momenta[0], axis=1)) <= bound
        checked += 1
    assert checked >= 3, runs['fast'].stretches[1].flights


def test_energy_never_increases_in_the_engine(runs):
    """Within each engine stretch E ≤ E at its start + M g × 2e-5 m (the soft contact lets G
    sink 1.4e-5 m, docs/physics.md: its spring energy is not in E); across a return the
    rolling energy is the engine's plus the reported energy added."""
    weight = runs['run'].mass.mass * 9.81
    for motion, samples in ((runs['slow'], runs['s_slow']), (runs['fast'], [runs['s_fast']])):
        energy = np.concatenate([x.energy for x in samples])
        engine = np.concatenate([x.engine for x in samples])
        t = np.concatenate([x.t for x in samples])
        for stretch in motion.stretches:
            if stretch.model != 'engine':
                continue
            inside = engine & (t >= stretch.t_start) & (t <= stretch.t_end)
            assert inside.sum() >= 3
            start = energy[t <= stretch.t_start][-1] if np.any(t <= stretch.t_start) \
                else energy[inside][0]
            assert np.all(energy[inside] <= start + weight * 2e-5), stretch.reason


def test_the_return_matches_the_engine_within_the_reported_mismatch(runs):
    """The rolling state the engine returns to (engine_state of its u, w, yaw, shift) against
    the engine's state there: G over the same ground point (16 ulps), G's height, the ground
    normal's angle in the body, v_G and the energy differ by the reported mismatch."""
    dynamics = runs['slow'].dynamics
    mass = dynamics.mass
    for stretch in runs['slow'].stretches[2:]:
        if stretch.model != 'rolling':
            continue
        near, (qpos, qvel) = stretch.mismatch, stretch.engine_state
        rolled = engine_state(dynamics, near.phase, near.angular_speed, near.yaw, near.shift)
        size = dynamics.body.size
        assert np.allclose(rolled.qpos[:2], qpos[:2], rtol=0, atol=16e-16 * size * 10)
        assert abs((qpos[2] - rolled.qpos[2]) - near.height_mismatch) <= 16e-16 * size
        normals = [quaternion_matrix(q / np.linalg.norm(q))[2] for q in (qpos[3:], rolled.qpos[3:])]
        angle = math.atan2(np.linalg.norm(np.cross(*normals)), normals[0] @ normals[1])
        assert abs(angle - near.angle_mismatch) <= 1e-9
        assert abs(np.linalg.norm(qvel[:3] - rolled.qvel[:3]) - near.velocity_mismatch) <= 1e-12

        def energy(pos, vel):
            return (0.5 * mass.mass * vel[:3] @ vel[:3] + 0.5 * vel[3:] @ mass.inertia @ vel[3:]
                    + mass.mass * dynamics.gravity * pos[2])
        rolling_energy = float(dynamics.energy_turning(near.phase, near.angular_speed))
        assert abs(rolling_energy - energy(qpos, qvel) - near.energy_mismatch) <= 1e-6
        # the rule held: the engine was rolling, so the map's mismatch is small
        assert near.angle_mismatch < 1e-3 and abs(near.height_mismatch) < 1e-4


def test_state_at_reaches_every_piece_of_the_latest_call():
    """MotionStream.state_at (the bisection's dense solution) answers at every time of its
    latest call, also in a DOP853 segment before the one the call ended in (it raised there):
    against one segment over the whole span (solver tolerance 1e-8: measured 1e-9 rad)."""
    from twodisk_ros.physics import EllipseBody, RollingDynamics
    from twodisk_ros.physics.mass.models import laminae
    dynamics = RollingDynamics(EllipseBody(0.1, 0.1, 0.05), laminae(0.1, 0.1, 0.05, 1.0))
    stream = MotionStream(dynamics, 0.3, 2.0, method='direct', chunk=0.1, tolerance=1e-8)
    reference = MotionStream(dynamics, 0.3, 2.0, method='direct', chunk=100.0, tolerance=1e-8)
    stream.sample_with_speed(np.array([0.02, 0.04]))
    sampled = np.array(stream.sample_with_speed(np.array([0.06, 0.1, 0.14, 0.18])))
    assert stream.segment == (0.1, 0.2)        # the call crossed into a second segment
    # the same dense solutions as the call's samples (bit for bit: one evaluation)
    assert np.array_equal(np.array(stream.state_at([0.18, 0.06, 0.1, 0.14])),
                          sampled[:, [3, 0, 1, 2]])
    times = np.array([0.05, 0.09, 0.11, 0.19])
    u, u_dot, w = stream.state_at(times)
    u_ref, u_dot_ref, w_ref = reference.sample_with_speed(times)
    np.testing.assert_allclose(u, u_ref, rtol=0, atol=1e-6)
    np.testing.assert_allclose(u_dot, u_dot_ref, rtol=0, atol=1e-5 * np.abs(u_dot_ref).max())
    with pytest.raises(ValueError, match='times must lie in'):
        stream.state_at([0.21])                # beyond the latest call's last piece


def test_a_crossing_in_an_earlier_dopri_segment_of_the_block(runs):
    """A rolling block whose scan grid starts in one DOP853 segment (0.03 s chunks here)
    with the crossing there, and ends in the next (it raised in state_at): the switch is the
    table run's (runs['slow'], a closed-form quadrature) to 1e-8 s — the two solvers' states
    agree to their tolerance 1e-10, the crossing moves by that over the rate of μ_required
    (measured 9e-12 s)."""
    run, t0 = runs['run'], 0.45
    u, u_dot, w = (float(x[0]) for x in run.stream().sample_with_speed([t0]))
    stream = MotionStream(run.dynamics, u, u_dot, method='direct', chunk=0.03,
                          lookahead=0.03, angular_speed=w)
    motion = HybridMotion(run.dynamics, runs['model'], stream, runs['settings'].friction,
                          engine=runs['slow']._engine)
    t = np.arange(0.0, 0.08, 0.01)          # switch at 0.0494 s, in the segment [0.03, 0.06]
    motion.sample(t[:5])
    motion.sample(t[5:])                    # its grid: 0.04 … 0.07 s, over two segments
    assert [s.model for s in motion.stretches] == ['rolling', 'engine']
    assert abs(motion.stretches[1].t_start + t0 - runs['slow'].stretches[1].t_start) < 1e-8


def test_a_friction_change_reaches_the_engine(runs):
    """HybridSimulation.update's set_friction: every geom of the engine has the new μ as its
    sliding friction (a MuJoCo contact takes the larger of its two geoms'), and the rolling
    model is judged by it; a switch of a motion sharing the engine puts its own μ back."""
    engine = runs['slow']._engine
    motion = HybridMotion(runs['run'].dynamics, runs['model'], runs['run'].stream(), 0.5,
                          engine=engine)
    try:
        motion.set_friction(0.8)
        assert motion.mu == 0.8 and motion.parameters.mu == 0.8
        assert np.all(engine.model.geom_friction[:, 0] == 0.8)
        assert np.all(engine.model.geom_friction[:, 1:] == 0.0)    # no torsion or rolling
        motion.set_friction(0.5)
        engine.model.geom_friction[:, 0] = 0.9                     # as another motion left it
        motion.sample(np.arange(0.45, 0.52, 0.01))                 # the switch at 0.4994 s
        assert motion.stretches[-1].model == 'engine'
        assert np.all(engine.model.geom_friction[:, 0] == 0.5)
    finally:
        engine.model.geom_friction[:, 0] = runs['settings'].friction


def test_engine_forces_are_of_the_samples_own_state(runs):
    """Newton's second law between consecutive engine steps: with a sample at every step h,
    M (v(t + h) − v(t)) / h = F_A + F_B + M g at sample t (MuJoCo's implicitfast integrator
    updates G's velocity by h × the acceleration of the state at t; no velocity-dependent
    force acts on G). The forces were those of the state one step earlier (off by up to
    16 N in the impacts of this hopping start, M g = 9.8 N). Tolerance: 16 ulps of
    M max|v| / h, the rounding of the velocity difference (measured 2.2e-13 N)."""
    run = runs['run']
    dynamics = run.dynamics
    start = dynamics.initial_state(run.start().phase, 15.0)
    motion = HybridMotion(dynamics, runs['model'],
                          MotionStream(dynamics, start.phase, start.phase_rate,
                                       angular_speed=15.0),
                          runs['settings'].friction, engine=runs['slow']._engine)
    h = motion.prepare()._engine.timestep
    s = motion.sample(np.arange(0.0, 0.06, h))       # 120 steps: a flight and its landing
    both = s.engine[:-1] & s.engine[1:]
    assert both.sum() > 100 and not s.touching[:, 1].all()
    mass = dynamics.mass.mass
    newton = mass * np.diff(s.velocity_g, axis=0) / h - mass * np.array(
        [0.0, 0.0, -dynamics.gravity])
    force = (s.force_a + s.force_b)[:-1]
    tolerance = 16 * np.finfo(float).eps * mass * np.abs(s.velocity_g).max() / h
    assert np.abs(force - newton)[both].max() < tolerance

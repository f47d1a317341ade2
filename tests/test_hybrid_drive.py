"""contact_model hybrid with a drive (issue 31): the torque drive's moment τ ê acts on the
engine's free body too (about the AB of the rolling pose with the closest ground normal,
run/hybrid_drive.py), the speed drive's motor applies nothing there, and commands continue
the hybrid motion from the last sample, rolling or engine.

References: Euler's law for the body in the air (dL_G/dt = the applied moment: gravity has
none about G), with ê from the body's geometry at the published phase and R from the
published orientation; the same start without a drive (bit for bit: a speed drive's engine
is the free body's); the speed drive's first-order lag Ω = cmd + (w − cmd) e^(−t/T); a fresh
SceneStream of the commanded scene from the sample's state; the engine sample's own state.
"""

from copy import copy

import numpy as np
import pytest

from twodisk_ros.engine.model import ContactParameters
from twodisk_ros.engine.run import Engine
from twodisk_ros.engine.state import quaternion_matrix
from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.scenes.motion import SceneStream
from twodisk_ros.physics.scenes.scene import Scene
from twodisk_ros.physics.scenes.terms import SceneTerms
from twodisk_ros.plotting.hybrid_results import OLOID, description
from twodisk_ros.run.hybrid import HybridMotion
from twodisk_ros.run.hybrid_rolling import LOOKAHEAD, SceneRolling
from twodisk_ros.run.hybrid_simulation import ENGINE_SINK, HybridSimulation
from twodisk_ros.run.parameters import DEFAULTS
from twodisk_ros.run.scene_simulation import scene_of

pytest.importorskip('mujoco')

H = 5e-4          # s: the engine's step; the flights are sampled at every step
TAU = 1.0         # N m


@pytest.fixture(scope='module')
def hops():
    """The oloid of config/oloid.yaml at u = 0 (where B lifts off first) at 20 rad/s, above
    its lift-off speed 8.28 rad/s: the engine from t = 0, in the air from 40 to 45 ms; with a
    torque drive of 1 N m on an RK4 engine (n = 64: its rotation keeps L_G in the air to
    1e-10 of the impulse; implicitfast's first-order rotation would leave O(h |ω|) ≈ 1 % of
    it), and with a speed drive (command 20 rad/s) and no drive on one implicitfast engine."""
    settings, run = description(OLOID)
    dynamics = run.dynamics
    model = ContactForceModel(dynamics)
    terms = SceneTerms(dynamics, Scene(gravity=dynamics.gravity), model)
    rk4 = Engine(dynamics.body, dynamics.mass, dynamics.gravity,
                 ContactParameters(mu=settings.friction, resolution=64, integrator='RK4'))
    engine = Engine(dynamics.body, dynamics.mass, dynamics.gravity,
                    ContactParameters(mu=settings.friction, resolution=64))
    u0, w0 = 0.0, 20.0
    out = {}
    # (the torque run to its second flight; the others to 15 ms: the claim is bit-identity)
    for name, scene, engine, t in (
            ('torque', Scene(drive='torque', command=TAU), rk4, np.arange(0.0, 0.045, H)),
            ('speed', Scene(drive='speed', command=20.0), engine, np.arange(0.0, 0.015, H)),
            ('none', None, engine, np.arange(0.0, 0.015, H))):
        placed = copy(terms)
        if scene is not None:
            placed.scene = Scene(gravity=dynamics.gravity, drive=scene.drive,
                                 command=scene.command)
        stream = SceneStream(placed, u0, None, angular_speed=w0, lookahead=H)
        rolling = SceneRolling(dynamics, placed, stream, u0, w0, model)
        motion = HybridMotion(dynamics, model, None, settings.friction, engine=engine,
                              rolling=rolling)
        out[name] = (motion, motion.sample(t), rolling)
    return dict(dynamics=dynamics, runs=out, terms=terms)


def _flights(s):
    """[(k, j)]: sample ranges with both disks in the air (at least 10 steps)."""
    air = s.engine & ~s.touching.any(axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], air.astype(int), [0]])))
    return [(k, j - 1) for k, j in zip(edges[::2], edges[1::2]) if j - 1 - k >= 10]


def _rotation(s, k):
    x, y, z, w = s.quaternion[k]
    return quaternion_matrix(np.array([w, x, y, z]))


def test_the_torque_drive_turns_the_body_in_the_air_by_euler_s_law(hops):
    """In each flight L_G(t_j) − L_G(t_k) = Σ τ R_i ê(u_i) h over its steps (the moment is
    applied from each step's starting state), ê the unit vector from A to B of the published
    phase u_i (body.phase_vectors, signed with ω_u · ê > 0), to 1e-9 of the impulse (RK4 in
    the air: 1e-10 measured; without the drive L_G is conserved to 1e-4 of itself, so the
    drive's impulse, 2–20 % of L_G, is what is measured); the engine's energy never rises
    above the stretch's start plus the drive's work W_d (+ the contact's sinking)."""
    dynamics, (motion, s, _) = hops['dynamics'], hops['runs']['torque']
    assert motion.stretches[1].model == 'engine' and motion.stretches[1].t_start == 0.0
    flights = _flights(s)
    assert len(flights) >= 1
    inertia = dynamics.mass.inertia
    for k, j in flights:
        momentum = [_rotation(s, i) @ inertia @ _rotation(s, i).T @ s.angular_velocity[i]
                    for i in (k, j)]
        impulse = np.zeros(3)
        for i in range(k, j):
            r1, r2 = (np.real(x)[0] for x in dynamics.body.phase_vectors(
                np.array([s.phase[i]]))[:2])
            axis = (r2 - r1) / np.linalg.norm(r2 - r1)
            if dynamics.body.phase_angular_velocity(np.array([s.phase[i]]))[0] @ axis < 0:
                axis = -axis
            impulse += TAU * (_rotation(s, i) @ axis) * H
        gap = np.linalg.norm(momentum[1] - momentum[0] - impulse)
        assert gap <= 1e-9 * np.linalg.norm(impulse), (gap, impulse)
        assert np.linalg.norm(impulse) > 0.02 * np.linalg.norm(momentum[0])
    start = motion.stretches[1].energy
    weight = dynamics.mass.mass * dynamics.gravity
    assert np.max(s.energy - s.drive_work) <= start + ENGINE_SINK * weight
    assert s.drive_work[-1] > 0.1          # J: the drive did work on the free body


def test_the_speed_drive_applies_nothing_to_the_free_body(hops):
    """A speed drive's engine stretch is the free body's: the same start without a drive
    gives the same engine samples bit for bit, and W_d = 0 there."""
    (_, speed, _), (_, free, _) = hops['runs']['speed'], hops['runs']['none']
    assert speed.engine.all() and free.engine.all()
    for name in ('position_g', 'quaternion', 'velocity_g', 'angular_velocity', 'energy'):
        assert np.array_equal(getattr(speed, name), getattr(free, name)), name
    assert not speed.drive_work.any()


def test_after_a_return_the_speed_drive_follows_its_lag_from_the_returned_speed(hops):
    """A return restarts the speed drive's rolling from the returned (u, w): its rolling
    speed is Ω(t) = cmd + (w − cmd) e^(−t/T) (the drive's closed form), to the stream's
    tolerance (1e-9 rad/s: DOP853 at rtol 1e-10 × the speed)."""
    rolling, terms = hops['runs']['speed'][2], hops['terms']
    lag, command, u, w = 0.1, 20.0, 0.3, 4.0
    restarted = rolling.restart(u, w, terms.phi0, 'table', 1e-10)
    t = np.linspace(0.0, 0.1, 5)
    speed = restarted.states(t)[2]
    closed = command + (w - command) * np.exp(-t / lag)
    assert np.max(np.abs(speed - closed)) <= 1e-9 * command


@pytest.fixture(scope='module')
def commanded():
    """The oloid of config/oloid.yaml (θ0 = 0.3 rad, ω0 = 3 rad/s, μ = 0.5) with drive torque
    through HybridSimulation (the node's path): 0.2 s at 100 Hz, then cmd_torque 0.2 N m from
    sample 10 (it rolls on, faster), then 3 N m from its sample 5 (it slips at once: the
    engine takes the torque), then the same command again from an engine sample."""
    settings = DEFAULTS.with_values(**{**OLOID, 'theta0': 0.3, 'omega0': 3.0},
                                    contact_model='hybrid', drive='torque').checked()
    first = HybridSimulation(settings)
    a = first.sample(np.arange(0.0, 0.2, 0.01))
    gentle = first.continued(settings, a, 10, drive='torque', command=0.2)
    g = gentle.sample(np.arange(0.0, 0.1, 0.01))
    second = gentle.continued(settings, g, 5, drive='torque', command=3.0)
    b = second.sample(np.arange(0.0, 0.04, 0.005))
    j = int(np.flatnonzero(b.hybrid.engine)[3])
    third = second.continued(settings, b, j, drive='torque', command=3.0)
    c = third.sample(np.arange(0.0, 0.02, 0.005))
    return dict(settings=settings, first=first, a=a, gentle=gentle, g=g, second=second, b=b,
                j=j, third=third, c=c)


def test_a_command_in_rolling_continues_exact_rolling_of_the_commanded_scene(commanded):
    """From rolling sample 10: the continued run starts at that sample's pose (G bit for bit,
    the orientation to 2 ulps) and rolls as a fresh SceneStream of the scene with 0.2 N m
    from the sample's (u, w), bit for bit (the same equation from the same start); the
    drive's work W_d and the speed grow; 3 N m then needs more friction than μ at once."""
    a, g, gentle = commanded['a'], commanded['g'], commanded['gentle']
    assert np.array_equal(g.position_g[0], a.position_g[10])
    assert np.max(np.abs(g.quaternion[0] - a.quaternion[10])) <= 2.3e-16
    settings, first = commanded['settings'], commanded['first']
    terms = copy(first.scene.terms)
    terms.scene = scene_of(settings, 'torque', 0.2)
    fresh = SceneStream(terms, a.phase[10], None, tolerance=settings.tolerance,
                        angular_speed=a.angular_speed[10], lookahead=LOOKAHEAD).samples(g.t)
    assert not g.hybrid.engine.any()
    assert np.array_equal(g.phase, fresh.phase)
    assert np.array_equal(g.hybrid.drive_work, fresh.drive_work) and fresh.drive_work[-1] > 0
    assert [x.model for x in gentle.hybrid.stretches] == ['rolling']
    assert 'continued at t = 0.1 s' in gentle.hybrid.stretches[0].reason
    assert [x.model for x in commanded['second'].hybrid.stretches] == ['rolling', 'engine']
    assert commanded['second'].hybrid.stretches[1].t_start == 0.0


def test_a_command_in_the_engine_continues_the_engine_from_the_samples_state(commanded):
    """From an engine sample: the continued run's first sample is that sample's state (G,
    orientation, v_G bit for bit through the slope-frame round trip; ω to 16 ulps of |ω|),
    and with the same command it follows the first engine to 1e-8 m over 35 ms (the
    solver's warm start, cleared at a restart, is all that differs); the torque did work
    (W_d > 0) in both."""
    b, c, j = commanded['b'], commanded['c'], commanded['j']
    assert c.hybrid.engine.all()
    for name in ('position_g', 'quaternion'):
        assert np.array_equal(getattr(c, name)[0], getattr(b, name)[j]), name
    assert np.array_equal(c.hybrid.velocity_g[0], b.hybrid.velocity_g[j])
    omega = b.hybrid.angular_velocity[j]
    assert np.max(np.abs(c.hybrid.angular_velocity[0] - omega)) <= 16 * np.spacing(
        np.linalg.norm(omega))
    k = np.arange(1, len(c.t))
    assert np.max(np.abs(c.position_g[k] - b.position_g[j + k])) <= 1e-8
    assert c.hybrid.drive_work[-1] > 0 and b.hybrid.drive_work[j] > 0
    assert 'continued at t = ' in commanded['third'].hybrid.stretches[0].reason

"""contact_model hybrid on a slope (issue 31): the engine's world is the slope frame S (x
downhill in the ground, z its normal, gravity g (sin β, 0, −cos β)), the published world
the gravity frame W = R_y(β) S, and the return map keeps the slope's potential.

Against independent references: the rolling run of the same settings (contact_model rolling,
bit for bit while rolling holds), Coulomb's closed form of a body sliding down a steep
slippery slope (G's acceleration g (sin β − μ cos β) along the fall line), the engine's own
state and energy ½ M v² + ½ ωᵀIω − M g_S · G at a return (the rolling state it is mapped to),
and a second build of the tables at the new heading.

The oloid of config/oloid.yaml (θ0 = 0.3 rad, ω0 = 3 rad/s) on config/slope.yaml's 0.05 rad
downhill without damping: with μ = 0.5 it slips at 1.258 s (the config's note) and rolls again
at 1.419 s. One engine (n = 512, the hybrid's default) serves every run here.
"""

import math

import numpy as np
import pytest

from twodisk_ros.engine.model import ContactParameters
from twodisk_ros.engine.run import Engine
from twodisk_ros.engine.state import quaternion_matrix
from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.scenes.motion import scene_stream
from twodisk_ros.physics.scenes.scene import Scene
from twodisk_ros.physics.scenes.terms import SceneTerms
from twodisk_ros.plotting.hybrid_results import OLOID
from twodisk_ros.run.hybrid import HybridMotion
from twodisk_ros.run.hybrid_rolling import SceneRolling
from twodisk_ros.run.hybrid_simulation import HybridSimulation
from twodisk_ros.run.parameters import DEFAULTS
from twodisk_ros.run.simulation import Simulation

pytest.importorskip('mujoco')

BETA = 0.05           # rad: config/slope.yaml's ramp
HEADING = 0.4         # rad: the bit-identity run heads off the fall line (φ0 ≠ 0)


def _settings(**changes):
    values = {**OLOID, 'theta0': 0.3, 'omega0': 3.0, 'slope': BETA, **changes}
    return DEFAULTS.with_values(**values, contact_model='hybrid').checked()


def _tilt(beta):
    c, s = math.cos(beta), math.sin(beta)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


@pytest.fixture(scope='module')
def slope():
    settings = _settings(friction=5.0, heading0=HEADING)
    hybrid = HybridSimulation(settings)
    t = np.arange(0.0, 1.5, 0.01)       # past the slip time of μ = 0.5: μ = 5 holds
    rolling = Simulation(settings.with_values(contact_model='rolling'))
    dynamics = hybrid.dynamics
    model = ContactForceModel(dynamics)
    engine = hybrid.hybrid.prepare()._engine        # n = 512, slope β
    # μ = 0.5 downhill: slip, engine, return (sampled densely around them)
    scene = Scene(slope=BETA, heading0=0.0, gravity=dynamics.gravity)
    terms = SceneTerms(dynamics, scene, model)
    start = hybrid.initial_state()

    def slipping():
        stream = scene_stream(dynamics, scene, start.phase, None, terms=terms,
                              angular_speed=start.angular_speed)
        return HybridMotion(dynamics, model, None, 0.5, engine=engine, rolling=SceneRolling(
            dynamics, terms, stream, start.phase, start.angular_speed))

    slips = slipping()
    t_slip = np.concatenate([np.arange(0.0, 1.2, 0.2), np.arange(1.2, 1.47, 4e-3)])
    first = hybrid.sample(t)
    stretches = len(hybrid.hybrid.stretches)
    # run-time friction change (the node's update): μ 5 → 0.5 at 1.5 s; rolling needed up to
    # 0.63 before (at 1.38 s): the switch must be the first crossing of 0.5 after the change
    lower = settings.with_values(friction=0.5)
    hybrid.update(lower)
    t_after = np.arange(1.5, 1.6, 0.01)      # (the switch is at 1.548 s)
    after = hybrid.sample(t_after)
    return dict(settings=settings, t=t, hybrid=first, simulation=hybrid, lower=lower,
                stretches=stretches,
                t_after=t_after, after=after,
                rolling=rolling.sample(t, forces=True), dynamics=dynamics, model=model,
                engine=engine, terms=terms, slips=slips, slipping=slipping, t_slip=t_slip,
                s_slip=slips.sample(t_slip))


def test_rolling_that_holds_on_a_slope_is_the_rolling_runs_bit_for_bit(slope):
    """μ = 5 on the 0.05 rad slope at heading 0.4 rad: rolling holds for 1.5 s, the engine
    never runs, and phase, pose and orientation are contact_model rolling's bit for bit; the
    forces (the hybrid's from (u, w, ẇ), the rolling run's from (u, u̇, ü): two forms of the
    same tables) agree to 1e-12 M g (rounding of terms of size M g and m u̇²)."""
    h, r = slope['hybrid'], slope['rolling']
    assert not h.hybrid.engine.any() and slope['stretches'] == 1
    for name in ('phase', 'phase_rate', 'position_g', 'contact_a', 'contact_b', 'quaternion'):
        assert np.array_equal(getattr(h, name), getattr(r, name)), name
    weight = slope['simulation'].weight
    for name in ('force_a', 'force_b'):
        gap = np.max(np.abs(getattr(h.forces, name) - getattr(r.forces, name)))
        assert gap <= 1e-12 * weight, (name, gap / weight)
    # the slope is in the poses: G descends along gravity as the oloid heads 0.4 rad off
    # the fall line (E conserved: the height lost is the kinetic energy gained)
    assert h.position_g[-1, 2] < h.position_g[0, 2] - 0.01


def test_a_body_sliding_down_a_steep_slippery_slope_follows_coulomb(slope):
    """β = 0.3 rad, μ = 0.1 < tan β, the oloid at rest at u = 0 across the fall line: rolling
    needs more friction at t = 0, the engine takes over and G (published in the gravity frame)
    accelerates along the fall line R_y(β) e_x at g (sin β − μ cos β), fitted over 20–100 ms,
    to 1 % (the soft contact's 5 ms settling transient has decayed for 4 time constants when
    the window starts; 7e-5 measured); nothing across it, and it keeps its height above the
    ground (the plane through the origin with normal (sin β, 0, cos β)) to the contact's
    sinking (1e-3 of the body's size)."""
    beta, mu = 0.3, 0.1
    dynamics, model = slope['dynamics'], slope['model']
    scene = Scene(slope=beta, heading0=0.5 * math.pi, gravity=dynamics.gravity)
    terms = SceneTerms(dynamics, scene, model)
    stream = scene_stream(dynamics, scene, 0.0, None, terms=terms, angular_speed=0.0)
    engine = Engine(dynamics.body, dynamics.mass, dynamics.gravity,
                    ContactParameters(mu=mu, resolution=64), slope=beta)
    motion = HybridMotion(dynamics, model, None, mu, engine=engine,
                          rolling=SceneRolling(dynamics, terms, stream, 0.0, 0.0))
    t = np.arange(0.0, 0.1 + 1e-9, 0.005)
    s = motion.sample(t)
    assert [x.model for x in motion.stretches] == ['rolling', 'engine']
    assert motion.stretches[1].t_start == 0.0 and 'slip' in motion.stretches[1].reason
    window = t >= 0.02
    fall = np.array([math.cos(beta), 0.0, -math.sin(beta)])
    along = 2 * np.polyfit(t[window], s.position_g[window] @ fall, 2)[0]
    across = 2 * np.polyfit(t[window], s.position_g[window, 1], 2)[0]
    closed = dynamics.gravity * (math.sin(beta) - mu * math.cos(beta))
    assert abs(along / closed - 1) < 1e-2, (along, closed)
    assert abs(across) < 1e-2 * closed
    height = s.position_g @ np.array([math.sin(beta), 0.0, math.cos(beta)])
    assert np.max(np.abs(height - height[0])) < 1e-3 * dynamics.body.size


def test_the_return_on_a_slope_keeps_the_engines_pose_and_energy(slope):
    """μ = 0.5 downhill: slip at 1.258 s (the config's note: 1.26 s), engine, rolling again.
    At the return the rolling state (published at the return's time, in W) has the engine's
    G (mapped from S by R_y(β)) up to the reported height mismatch along the ground normal
    (to 1e-12 of the size: rounding of the pose table), the orientation within the reported
    tilt (1e-9 rad), and the engine's energy ½ M v² + ½ ωᵀIω − M g_S · G (the test's own sum,
    g_S = g (sin β, 0, −cos β)) to 1e-12 M g L (rounding of the tables' V; 1.5e-16 measured):
    the slope's potential is matched, not only G's height."""
    motion, dynamics = slope['slips'], slope['dynamics']
    models = [x.model for x in motion.stretches]
    assert models[:3] == ['rolling', 'engine', 'rolling'], motion.stretches
    assert abs(motion.stretches[1].t_start - 1.2584) < 1e-3
    back = motion.stretches[2]
    near, (qpos, qvel) = back.mismatch, back.engine_state
    mass, g = dynamics.mass, dynamics.gravity
    gravity = g * np.array([math.sin(BETA), 0.0, -math.cos(BETA)])
    energy = (0.5 * mass.mass * qvel[:3] @ qvel[:3] + 0.5 * qvel[3:] @ mass.inertia @ qvel[3:]
              - mass.mass * gravity @ qpos[:3])
    assert near.energy_mismatch == 0.0
    assert abs(back.energy - energy) <= 1e-12 * dynamics.energy_scale, back.energy - energy
    # the published rolling state at the return's time (a second run, sampled there too:
    # the engine's steps up to it are the same)
    again = slope['slipping']()
    t = slope['t_slip']
    t = np.sort(np.append(t[t < back.t_start], back.t_start))
    s = again.sample(t)
    assert again.stretches[2].t_start == back.t_start and not s.engine[-1]
    normal = np.array([math.sin(BETA), 0.0, math.cos(BETA)])
    tilt = _tilt(BETA)
    gap = s.position_g[-1] - (tilt @ qpos[:3] - near.height_mismatch * normal)
    assert np.max(np.abs(gap)) <= 1e-12 * dynamics.body.size, gap
    x, y, z, w = s.quaternion[-1]
    published = quaternion_matrix(np.array([w, x, y, z]))
    engine_rotation = tilt @ quaternion_matrix(qpos[3:] / np.linalg.norm(qpos[3:]))
    turn = published @ engine_rotation.T
    angle = math.acos(min(1.0, 0.5 * (np.trace(turn) - 1)))
    assert abs(angle - near.angle_mismatch) <= 1e-9, (angle, near.angle_mismatch)
    assert near.angle_mismatch < 1e-3 and abs(near.height_mismatch) < 1e-4


def test_energy_balance_across_the_switches_on_a_slope(slope):
    """E = ½ M v² + ½ ωᵀIω + M g × G's height along gravity (W's z: the gravity frame's) is
    what the samples report in both models: recomputed here from the engine samples' velocity
    and ω (16 ulps of E's terms); it is conserved along each rolling stretch (exact rolling:
    1e-9 M g L, the closed forms' tolerance), never rises in the engine beyond the contact's
    sinking (ENGINE_SINK M g), and each stretch starts with the energy the last one ended
    with (rolling → engine: the same state; engine → rolling: the map adds none here)."""
    from twodisk_ros.run.hybrid_simulation import ENGINE_SINK
    motion, s, dynamics = slope['slips'], slope['s_slip'], slope['dynamics']
    mass = dynamics.mass
    e = s.engine
    recomputed = (0.5 * mass.mass * np.einsum('ij,ij->i', s.velocity_g[e], s.velocity_g[e])
                  + 0.5 * np.einsum('ij,ijk,ik->i', s.angular_velocity[e],
                                    _world_inertia(s, e, mass), s.angular_velocity[e])
                  + mass.mass * dynamics.gravity * s.position_g[e, 2])
    scale = dynamics.energy_scale
    assert np.max(np.abs(recomputed - s.energy[e])) <= 1e-12 * scale
    weight = mass.mass * dynamics.gravity
    for k, stretch in enumerate(motion.stretches):
        inside = (s.t >= stretch.t_start) & (s.t < stretch.t_end)
        if stretch.model == 'rolling':
            assert np.max(np.abs(s.energy[inside] - stretch.energy)) <= 1e-9 * scale
        else:
            assert np.max(s.energy[inside]) <= stretch.energy + ENGINE_SINK * weight
        if k:
            assert stretch.energy <= motion.stretches[k - 1].energy + 1e-9 * scale
    assert motion.stretches[2].energy < motion.stretches[1].energy - 1e-3   # slid: lost


def _world_inertia(s, e, mass):
    """I in the world frame per engine sample (n, 3, 3), from the published quaternions."""
    out = []
    for x, y, z, w in s.quaternion[e]:
        r = quaternion_matrix(np.array([w, x, y, z]))
        out.append(r @ mass.inertia @ r.T)
    return np.array(out)


def test_turned_tables_are_the_tables_built_at_that_heading(slope):
    """SceneTerms.turned(φ0) (a return's heading: V's table rebuilt, the wide table shared)
    against SceneTerms built anew for the heading0 that gives φ0: V, V′ and the forces agree
    to 1e-12 M g L and 1e-12 M g (the same sums in another order)."""
    terms, dynamics = slope['terms'], slope['dynamics']
    phi0 = 1.3
    turned = terms.turned(phi0)
    shift = complex(dynamics.cycle.displacement.shift)
    fresh = SceneTerms(dynamics, Scene(slope=BETA, heading0=phi0 + math.atan2(shift.imag,
                                                                             shift.real),
                                       gravity=dynamics.gravity), slope['model'])
    assert abs(fresh.phi0 - phi0) <= 4e-16
    u = np.linspace(-3.0, 9.0, 97)
    scale, weight = dynamics.energy_scale, fresh.weight
    assert np.max(np.abs(turned.potential(u) - fresh.potential(u))) <= 1e-12 * scale
    assert np.max(np.abs(turned.potential_slope(u) - fresh.potential_slope(u))) <= 1e-12 * scale
    a, b = turned.forces(u, 2.0, 0.5), fresh.forces(u, 2.0, 0.5)
    assert np.max(np.abs(a.force_a - b.force_a)) <= 1e-12 * weight
    # and the turn is real: V at another heading differs by M g sin β × the downhill shift
    assert np.max(np.abs(turned.potential(u) - terms.potential(u))) > 1e-3 * scale


def test_the_inspectors_engine_check_reads_forces_and_points_in_the_slope_frame():
    """On a slope β the recorded forces and points (gravity frame) are taken to the slope
    frame: a force along the ground normal (sin β, 0, cos β) has no tangential part (it would
    have tan β = 0.31 > μ = 0.2 read against e_z) and a point on the ground downhill of the
    origin is not below it (read against z it would be 0.1 sin β = 2.96e-2 m deep); the
    same force tilted beyond the cone, or a point 1.5e-2 L under the slope, still fail."""
    from twodisk_ros.inspector.engine_stretches import engine_check
    from twodisk_ros.inspector.series import Series
    beta, stamps = 0.3, np.arange(2, dtype=np.int64)
    normal = np.array([math.sin(beta), 0.0, math.cos(beta)])
    downhill = np.array([math.cos(beta), 0.0, -math.sin(beta)])

    def check(force, point, slope=beta):
        engine = {'wrench_a': Series('x', stamps, stamps, stamps, {'force': np.array(force)}),
                  'contact_a': Series('x', stamps, stamps, stamps, {'point': np.array(point)})}
        return engine_check(engine, [(0, None)], {'friction': '0.2', 'slope': repr(slope)},
                            9.81, 0.2).passed

    on_ground = [0.1 * downhill, 0.05 * downhill]
    assert check([5 * normal, 5 * normal], on_ground)
    assert not check([5 * normal, 5 * normal], on_ground, slope=0.0)     # read level: fails
    assert not check([5 * normal, 5 * normal + 1.1 * downhill], on_ground)   # 0.22 > 0.2
    assert not check([5 * normal, 5 * normal], [0.1 * downhill, -3e-3 * normal])


def test_a_friction_change_at_run_time_switches_at_the_new_mu(slope):
    """μ 5 → 0.5 at 1.5 s (HybridSimulation.update, the node's path for a friction change):
    the engine takes over at the first time after the change where the slope scene's forces
    (a fresh closed-form stream, forces from (u, u̇, ü): SceneMotion's path) need more than
    0.5: valid on a 1 ms grid from 1.5 s to 1e-9 s before the switch, not 1e-9 s after it
    (the bisection's 1e-12 s); the engine's contacts have μ = 0.5; a later change reaches
    the engine inside its stretch."""
    from twodisk_ros.physics.forces.validity import check_validity
    simulation, lower = slope['simulation'], slope['lower']
    stretches = simulation.hybrid.stretches
    assert [x.model for x in stretches[:2]] == ['rolling', 'engine'], stretches
    switch = stretches[1].t_start
    assert 1.5 < switch < 1.6
    start = simulation.initial_state()
    terms = simulation.scene.terms
    stream = scene_stream(slope['dynamics'], terms.scene, start.phase, None, terms=terms,
                          angular_speed=start.angular_speed)
    t = np.concatenate([[0.0], np.arange(1.5, switch - 1e-9, 1e-3),
                        [switch - 1e-9, switch + 1e-9]])
    fresh = stream.samples(t)
    forces = terms.forces(fresh.phase[1:], fresh.phase_rate[1:], fresh.phase_acceleration[1:])
    report = check_validity(t[1:], forces, lower.friction)
    assert not report.valid and report.index == len(t) - 2, report
    engine = simulation.hybrid.engine
    assert np.all(engine.model.geom_friction[:, 0] == 0.5)
    simulation.update(lower.with_values(friction=0.3))
    assert np.all(engine.model.geom_friction[:, 0] == 0.3)


def test_a_reset_starts_the_hybrid_again_with_the_runs_engine(slope):
    """The node's reset (Simulation.restarted) after an engine stretch: one rolling stretch
    from t = 0 again, the same engine object (no second 0.5 s build); sampled at the first
    run's times, its samples before its own first switch (μ is 0.3 now) are the first run's
    bit for bit, and the engine takes over from the rolling pose there (G within the
    distance G moves in one sample)."""
    simulation = slope['simulation']
    reset = simulation.restarted()
    assert reset.hybrid.engine is simulation.hybrid.engine
    assert [x.model for x in reset.hybrid.stretches] == ['rolling']
    blocks = []               # (in blocks of 10, as the node samples, up to its switch)
    for k in range(0, len(slope['t']), 10):
        blocks.append(reset.sample(slope['t'][k:k + 10]))
        if blocks[-1].hybrid.engine.any():
            break
    again = _joined(blocks)
    switch = reset.hybrid.stretches[1].t_start
    before = again.t <= switch
    assert before.sum() >= 50 and again.hybrid.engine[~before].any()
    for name in ('phase', 'position_g', 'quaternion'):
        assert np.array_equal(getattr(again, name)[before],
                              getattr(slope['hybrid'], name)[:len(again.t)][before]), name
    k = int(np.argmax(~before))
    step = np.linalg.norm(again.position_g[k - 1] - again.position_g[k - 2])
    assert np.linalg.norm(again.position_g[k] - again.position_g[k - 1]) < 2 * step


def _joined(blocks):
    """The samples of consecutive blocks as one (t, phase, position_g, quaternion, engine)."""
    from types import SimpleNamespace
    cat = {name: np.concatenate([getattr(b, name) for b in blocks])
           for name in ('t', 'phase', 'position_g', 'quaternion')}
    return SimpleNamespace(**cat, hybrid=SimpleNamespace(
        engine=np.concatenate([b.hybrid.engine for b in blocks])))

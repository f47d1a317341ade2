"""contact_model hybrid with damping (issue 31): the rolling stretches are the damped scene's
exact motion and the switch is where that motion's forces leave the rolling model; the
engine's body gets the same torque −c ω (its closed form: tests/test_engine_scene.py).

The oloid of config/oloid.yaml with μ = 5 and c = 0.002 N m s, from u = π/4 at 10 rad/s: it
rolls for 63 ms, then needs more friction than μ as N_B falls to 0 (the engine's from there)."""

import math

import numpy as np
import pytest

from twodisk_ros.engine.model import ContactParameters
from twodisk_ros.engine.run import Engine
from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.forces.validity import check_validity
from twodisk_ros.physics.scenes.motion import SceneStream, scene_stream
from twodisk_ros.physics.scenes.terms import SceneTerms
from twodisk_ros.plotting.hybrid_results import OLOID, description
from twodisk_ros.run.hybrid import HybridMotion
from twodisk_ros.run.hybrid_rolling import SceneRolling
from twodisk_ros.run.parameters import DEFAULTS
from twodisk_ros.run.scene_simulation import scene_of

pytest.importorskip('mujoco')

C, MU, W0 = 0.002, 5.0, 10.0


@pytest.fixture(scope='module')
def damped():
    settings, run = description(OLOID, damping=C)
    dynamics, model = run.dynamics, ContactForceModel(run.dynamics)
    terms = SceneTerms(dynamics, scene_of(settings), model)
    start = dynamics.initial_state(0.25 * math.pi, W0)

    def stream():
        return SceneStream(terms, start.phase, None, angular_speed=W0)

    engine = Engine(dynamics.body, dynamics.mass, dynamics.gravity,
                    ContactParameters(mu=MU, resolution=64), damping=C)
    motion = HybridMotion(dynamics, model, None, MU, engine=engine, damping=C,
                          rolling=SceneRolling(dynamics, terms, stream(), start.phase, W0))
    t = np.arange(0.0, 0.07, 1e-3)
    return dict(terms=terms, stream=stream, motion=motion, t=t, samples=motion.sample(t),
                dynamics=dynamics)


def test_the_rolling_samples_are_the_damped_scenes_motion(damped):
    """Before the switch: the phase and speed of a fresh SceneStream of the same scene, bit for
    bit, and its energy balance E + W = E0 to the stream's tolerance (1e-10 × M g L)."""
    s, motion = damped['samples'], damped['motion']
    switch = motion.stretches[1].t_start
    rolling = s.t <= switch
    assert motion.stretches[1].model == 'engine' and 0.05 < switch < 0.07
    assert not s.engine[rolling].any() and s.engine[~rolling].all()
    fresh = damped['stream']().samples(s.t[rolling])
    assert np.array_equal(s.phase[rolling], fresh.phase)
    assert np.array_equal(s.angular_speed[rolling], fresh.rolling_speed)
    balance = s.energy[rolling] + s.dissipated[rolling]
    scale = damped['dynamics'].energy_scale
    assert np.max(np.abs(balance - motion.stretches[0].energy)) <= 1e-10 * scale * 10
    # damping does work: the energy falls along the rolling stretch
    assert s.dissipated[rolling][-1] > 1e-4


def test_the_switch_is_where_the_damped_forces_leave_the_rolling_model(damped):
    """The scene's forces from (u, u̇, ü) (SceneMotion's path, not the hybrid's (u, w, ẇ)) on a
    fresh stream at ±1e-9 s of the switch (bisected to 1e-12 s): rolling holds before,
    fails after, by needing more than μ."""
    switch = damped['motion'].stretches[1].t_start
    t = np.array([switch - 1e-9, switch + 1e-9])
    fresh = damped['stream']().samples(np.concatenate([[0.0], t]))
    forces = damped['terms'].forces(fresh.phase[1:], fresh.phase_rate[1:],
                                    fresh.phase_acceleration[1:])
    report = check_validity(t, forces, MU)
    assert not report.valid and report.index == 1 and report.kind == 'slip', report


def test_hybrid_takes_damping_and_slope_and_still_refuses_rolling_resistance():
    hybrid = DEFAULTS.with_values(contact_model='hybrid', damping=C, slope=0.1).checked()
    assert (hybrid.damping, hybrid.slope) == (C, 0.1)
    with pytest.raises(ValueError, match='rolling_resistance 0') as error:
        DEFAULTS.with_values(contact_model='hybrid', rolling_resistance=0.01).checked()
    assert '\n' not in str(error.value)


def test_a_damped_hybrid_at_a_heading_is_placed_as_the_rolling_run():
    """Level ground with damping at heading0 = 1 rad: while rolling holds the hybrid publishes
    the rolling run's poses (the scene's, turned by φ0 = heading0) bit for bit and forces that
    go with them (to 1e-12 M g: from (u, w, ẇ) instead of (u, u̇, ü)). Before, the hybrid
    placed the cycle unturned (G 1 rad about the vertical away from the rolling run's) while
    its forces were turned."""
    from twodisk_ros.run.simulation import Simulation
    settings = DEFAULTS.with_values(**{**OLOID, 'damping': C, 'heading0': 1.0}).checked()
    rolling = Simulation(settings)
    t = np.arange(0.0, 0.5, 0.01)
    expected = rolling.sample(t, forces=True)
    start, terms, dynamics = rolling.initial_state(), rolling.scene.terms, rolling.dynamics
    stream = scene_stream(dynamics, terms.scene, start.phase, None, tolerance=settings.tolerance,
                          terms=terms, angular_speed=start.angular_speed)   # SceneMotion's
    motion = HybridMotion(dynamics, rolling.forces, None, settings.friction,
                          rolling=SceneRolling(dynamics, terms, stream, start.phase,
                                               start.angular_speed))
    s = motion.sample(t)
    assert not s.engine.any()
    for name in ('phase', 'position_g', 'contact_a', 'contact_b'):
        assert np.array_equal(getattr(s, name), getattr(expected, name)), name
    assert np.array_equal(s.quaternion, expected.quaternion)
    weight = rolling.weight
    assert np.max(np.abs(s.force_a - expected.forces.force_a)) <= 1e-12 * weight

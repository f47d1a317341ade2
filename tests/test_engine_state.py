"""The engine's model and state map (twodisk_ros/engine): the rolling state <-> MuJoCo round
trip, MuJoCo's free-joint velocity convention, and bad input.

References: the cycle's closed-form G velocity (RollingCycle.velocity_g, -R (omega_u x r1)), an
independent path from the map's omega x (G - A); MuJoCo's own mj_objectVelocity for the
free joint's convention; the energy identity 1/2 M |v|^2 + 1/2 omega.I.omega = 1/2 J w^2 of
rolling (the map inverts one side by the other)."""

import math

import mujoco
import numpy as np
import pytest

from twodisk_ros import EllipseBody, RollingDynamics
from twodisk_ros.engine.model import ContactParameters, build_model, engine_xml
from twodisk_ros.engine.state import engine_state, nearest_rolling, quaternion_matrix
from twodisk_ros.physics.mass.models import centred_on_mass


@pytest.fixture(scope='module')
def oloid():
    body, props = centred_on_mass('laminae', EllipseBody(0.1, 0.1, 0.05), 1.0)
    return RollingDynamics(body, props, 9.81)


# phases on both branches, past turning points, negative and cycles ahead; both senses
CASES = [(0.3, 3.0, 0.0, (0.0, 0.0)), (1.9, -2.0, 1.2, (0.5, -0.25)),
         (-4.0, 0.7, -2.5, (-1.0, 2.0)), (13.1, 5.0, 3.0, (0.01, 0.02))]


@pytest.mark.parametrize('phase, w, yaw, shift', CASES)
def test_round_trip_rolling_engine_rolling_is_exact_to_rounding(oloid, phase, w, yaw, shift):
    state = engine_state(oloid, phase, w, yaw, shift)
    back = nearest_rolling(oloid, state.qpos, state.qvel, near_phase=phase + 0.4)
    # the phase is a simple root of d(n_e . n(u))/du found by Brent to 1e-15 rad; the
    # normal's rounding (1e-16) moves it by 1e-16 / |dn/du|^2 ~ 1e-15: 64 ulps of u
    assert back.phase == pytest.approx(phase, abs=64 * math.ulp(max(abs(phase), 1.0)))
    assert back.angular_speed == pytest.approx(w, rel=1e-12)   # energies of 5 rounded terms
    assert math.remainder(back.yaw - yaw, 2 * math.pi) == pytest.approx(0.0, abs=1e-13)
    assert np.allclose(back.shift, shift, rtol=0, atol=1e-14)   # metres, rounding of G
    assert back.angle_mismatch < 1e-14 and abs(back.height_mismatch) < 1e-15
    assert back.energy_mismatch == 0.0 and back.velocity_mismatch < 1e-14


@pytest.mark.parametrize('phase, w, yaw, shift', CASES[:2])
def test_engine_velocity_is_the_closed_form_rolling_velocity(oloid, phase, w, yaw, shift):
    state = engine_state(oloid, phase, w, yaw, shift)
    u_dot = w / float(oloid.angular_speed_per_phase(np.array([phase]))[0])
    v_cycle = oloid.cycle.velocity_g(np.array([phase]))[0] * u_dot
    c, s = math.cos(yaw), math.sin(yaw)
    v_ref = np.array([c * v_cycle[0] - s * v_cycle[1], s * v_cycle[0] + c * v_cycle[1],
                      v_cycle[2]])
    assert np.allclose(state.qvel[:3], v_ref, rtol=0, atol=1e-14 * abs(w))
    # the angular velocity's size is the angular speed about the contact line
    assert np.linalg.norm(state.qvel[3:]) == pytest.approx(abs(w), rel=1e-14)


def test_free_joint_convention_world_linear_body_angular(oloid):
    """MuJoCo's own velocity of the body (world frame) from our qvel: linear = v_G, angular
    = R omega_body, so qvel[3:6] is the body-frame angular velocity."""
    state = engine_state(oloid, 1.9, -2.0, 1.2, (0.5, -0.25))
    model = build_model(oloid.body, oloid.mass)
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = state.qpos, state.qvel
    mujoco.mj_forward(model, data)
    res = np.zeros(6)
    mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, 1, res, 0)
    rotation = quaternion_matrix(state.qpos[3:])
    assert np.allclose(res[:3], rotation @ state.qvel[3:], rtol=0, atol=1e-14)
    assert np.allclose(res[3:], state.qvel[:3], rtol=0, atol=1e-14)
    assert np.allclose(data.xmat[1].reshape(3, 3), rotation, rtol=0, atol=1e-15)


def test_rolling_pose_touches_the_ground_with_both_plates(oloid):
    """At a rolling pose both plates reach the ground: the deepest contact of each is within
    the mesh's chord error size (1 - cos(pi/n)) plus half the plate thickness."""
    params = ContactParameters()
    state = engine_state(oloid, 0.3, 3.0)
    model = build_model(oloid.body, oloid.mass, 9.81, params)
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = state.qpos, state.qvel
    mujoco.mj_forward(model, data)
    size = oloid.body.size
    bound = size * (1 - math.cos(math.pi / params.resolution)) + params.thickness * size / 2
    disks = {model.geom(c.geom[1]).name for c in data.contact[:data.ncon]}
    assert disks == {'disk_a', 'disk_b'}
    assert all(abs(c.dist) <= bound for c in data.contact[:data.ncon])


def test_mass_properties_reach_mujoco(oloid):
    model = build_model(oloid.body, oloid.mass)
    # two discs of M/2 (radius r, centres delta off G): about e1 a diameter of one, the axis
    # of the other, M r^2 (1/8 + 1/4) + M delta^2; about e2 a diameter of both, M r^2 / 4
    r, delta, m = 0.1, 0.05, 1.0
    i11, i22 = m * (3 * r * r / 8 + delta**2), m * r * r / 4
    assert model.body_mass[1] == m
    assert sorted(model.body_inertia[1]) == pytest.approx(sorted([i11, i22, i11]), rel=1e-12)


@pytest.mark.parametrize('changes, words', [
    (dict(resolution=10), 'resolution must be an integer multiple of 4'),
    (dict(resolution=256.0), 'resolution must be an integer multiple of 4'),
    (dict(mu=0.0), 'mu must be a friction coefficient in (0, 10]'),
    (dict(mu=-0.5), 'mu must be a friction coefficient in (0, 10]'),
    (dict(mu=float('nan')), 'mu must be a friction coefficient'),
    (dict(timestep=0.1), 'timestep must be a number of s in [1e-05, 0.005]'),
    (dict(timestep=0.0), 'timestep must be a number of s'),
    (dict(timestep=1e-3, time_constant=1e-3), 'time_constant must be a number of s in [0.002'),
    (dict(integrator='verlet'), 'integrator must be one of implicitfast'),
    (dict(cone='round'), 'cone must be one of elliptic, pyramidal'),
    (dict(thickness=0.5), 'thickness must be a number of body sizes'),
])
def test_bad_parameters_one_clear_line(changes, words):
    with pytest.raises(ValueError) as info:
        ContactParameters(**changes)
    message = str(info.value)
    assert words in message and '\n' not in message and 'got' in message


def test_engine_xml_rejects_a_body_not_centred_on_its_mass(oloid):
    import dataclasses
    moved = dataclasses.replace(oloid.mass, center_of_mass=np.array([0.0, 0.01, 0.0]))
    with pytest.raises(ValueError, match='center_of_mass must be G'):
        engine_xml(oloid.body, moved)

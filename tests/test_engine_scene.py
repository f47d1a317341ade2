"""The engine's slope and damping (twodisk_ros/engine: ``slope`` tilts gravity in the slope
frame, ``damping`` applies −c ω) against closed forms: the oloid sliding down a slope on a
low-friction ground accelerates at g (sin β − μ cos β) along the fall line; a body spinning
about a principal axis of moment I under −c ω slows by the factor 1 − c h / I per step h
(MuJoCo's explicit force), e^(−c t / I) to first order in h; and the refusals."""

import math

import numpy as np
import pytest

from twodisk_ros import EllipseBody, RollingDynamics
from twodisk_ros.engine.model import ContactParameters, engine_xml, gravity_vector
from twodisk_ros.engine.run import Engine
from twodisk_ros.engine.state import engine_state
from twodisk_ros.physics.mass.models import centred_on_mass

pytest.importorskip('mujoco')

G = 9.81


@pytest.fixture(scope='module')
def oloid():
    body, props = centred_on_mass('laminae', EllipseBody(0.1, 0.1, 0.05), 1.0)
    return RollingDynamics(body, props, G)


def test_the_oloid_slides_down_a_slope_at_the_coulomb_closed_form(oloid):
    """β = 0.3 rad, μ = 0.1 < tan β: from rest in its rolling pose at u = 0 turned across
    the fall line (heading π/2, where gravity's torque about G is balanced and it slides
    without turning), G's acceleration along the slope is g (sin β − μ cos β), fitted over
    20–100 ms; nothing across it. Tolerance 1 % of it: the friction μ N follows the soft
    contact's normal force, whose settling transient (time constant 5 ms) has decayed for 4
    time constants when the window starts (7e-5 measured)."""
    beta, mu = 0.3, 0.1
    engine = Engine(oloid.body, oloid.mass, G, ContactParameters(mu=mu, resolution=64),
                    slope=beta)
    start = engine_state(oloid, 0.0, 0.0, 0.5 * math.pi)
    engine.set_state(start.qpos, start.qvel)
    t = np.arange(0.0, 0.1 + 1e-9, 0.005)
    s = engine.sample(t)
    window = t >= 0.02
    along = 2 * np.polyfit(t[window], s.qpos[window, 0], 2)[0]
    across = 2 * np.polyfit(t[window], s.qpos[window, 1], 2)[0]
    closed = G * (math.sin(beta) - mu * math.cos(beta))
    assert abs(along / closed - 1) < 1e-2, (along, closed)
    assert abs(across) < 1e-2 * closed
    assert np.nanmax(s.slip_speed[-1]) > 0.5 * closed * t[-1]     # it slides, not rolls
    # on level ground (u = 0 is a rest pose) the same start stays put: the slide is the slope's
    level = Engine(oloid.body, oloid.mass, G, ContactParameters(mu=0.5, resolution=64))
    level.set_state(start.qpos, start.qvel)
    assert np.linalg.norm(level.sample(t).qpos[-1, :2] - start.qpos[:2]) < 1e-4


def test_gravity_is_tilted_in_the_slope_frame_and_level_ground_is_unchanged(oloid):
    beta = 0.2
    g = gravity_vector(G, beta)
    assert np.allclose(g, [G * math.sin(beta), 0.0, -G * math.cos(beta)], rtol=0, atol=4e-15)
    assert 'gravity="0 0 -9.81"' in engine_xml(oloid.body, oloid.mass, G, slope=0.0)
    assert engine_xml(oloid.body, oloid.mass, G) == engine_xml(oloid.body, oloid.mass, G,
                                                               slope=0.0)


def test_damping_slows_a_spin_about_a_principal_axis_as_the_closed_form(oloid):
    """High above the ground (no contact), ω0 about each principal axis: after n steps ω is
    ω0 (1 − c h / I)^n to 16 ulps per step (MuJoCo applies the torque explicitly) and
    ω0 e^(−c t / I) to within its first-order error n (c h / I)² / 2 (+1 % for the next
    order); it stays on the axis."""
    c, w0, n = 0.002, 10.0, 400
    moments, axes = np.linalg.eigh(oloid.mass.inertia)
    engine = Engine(oloid.body, oloid.mass, G, ContactParameters(resolution=16), damping=c)
    h = engine.timestep
    for moment, axis in zip(moments, axes.T):
        engine.set_state(np.array([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0]),
                         np.concatenate([[0.0, 0.0, 0.0], w0 * axis]))
        engine.step_to(n * h)
        omega = engine.data.qvel[3:].copy()
        along = omega @ axis
        discrete = w0 * (1 - c * h / moment) ** n
        assert abs(along - discrete) <= 16 * n * np.finfo(float).eps * w0
        continuous = w0 * math.exp(-c * n * h / moment)
        assert abs(along / continuous - 1) <= 1.01 * n * (c * h / moment) ** 2 / 2
        assert np.linalg.norm(omega - along * axis) <= 16 * n * np.finfo(float).eps * w0


@pytest.mark.parametrize('kwargs, words', [
    (dict(slope=2.0), 'slope must be a number of rad in'),
    (dict(slope=float('nan')), 'slope must be a number of rad in'),
    (dict(damping=-1.0), 'damping must be a finite torque per angular speed >= 0 N m s'),
    (dict(damping='a'), 'damping must be a finite torque per angular speed >= 0 N m s'),
])
def test_bad_slope_or_damping_is_refused_in_one_line(oloid, kwargs, words):
    with pytest.raises(ValueError, match=words) as error:
        Engine(oloid.body, oloid.mass, G, ContactParameters(resolution=16), **kwargs)
    assert '\n' not in str(error.value)

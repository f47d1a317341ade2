"""LaminaBody.about (the body seen from another point on e2) and mass.models.centred_on_mass
(a solid whose centre of mass lies off the laminae's centroid G: the parallel egg).

References: the exact contact geometry of bodies/contact_solver.py (support height of the lamina at
the ground normal, from O), brute-force distances over the rims, the unmoved body's own
vectors (a moved point is a translation), and for the dynamics the energy of the real body
computed from the unmoved body's world poses alone: the centre of mass at G + c e2, its
velocity and the angular velocity from 5-point differences of the poses in u.
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.cycle import RollingCycle
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.laminae.shapes import Superellipse
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.physics.bodies.lamina_body import LaminaBody
from twodisk_ros.physics.mass.models import centred_on_mass, mass_properties_of
from twodisk_ros.physics.motion.simulate import simulate

TWO_PI = 2 * math.pi
GRAVITY = 9.81
_BODIES = {}


def _egg():
    """The brief's egg: Egg(0.1, 0.08, 0.004), Δ = 0.04 m, parallel."""
    if 'egg' not in _BODIES:
        _BODIES['egg'] = LaminaBody(Egg(0.1, 0.08, 0.004), 0.04)
    return _BODIES['egg']


def _square():
    if 'square' not in _BODIES:
        _BODIES['square'] = LaminaBody(Superellipse(0.1, 0.1, 4.0), 0.05)
    return _BODIES['square']


def test_moved_point_sees_translated_vectors_and_its_own_height():
    """r_i(P) = r_i(G) − c e2 to rounding; z_P = z_G + c n·e2 against the exact pose: the
    support height h of the lamina at m = −n (from O) plus n·P. Claimed: table poses ≤ 1e-10
    of the size (measured 2.3e-15 here)."""
    body, c = _egg(), 3e-3
    moved = body.about(c)
    rounding = ulps(16, body.size)        # a few rounded sums of lengths of the size (m)
    theta = np.linspace(-0.99, 0.99, 41) * body.theta_max
    for branch in (1, -1):
        u = body.phase_from_theta(theta, branch)
        r1, r2, n, t1, z = body.phase_vectors(u)
        q1, q2, m, s1, zp = moved.phase_vectors(u)
        shift = np.array([0.0, c, 0.0])
        assert np.max(np.abs(q1 - (r1 - shift))) <= rounding
        assert np.max(np.abs(q2 - (r2 - shift))) <= rounding
        assert np.array_equal(m, n) and np.array_equal(s1, t1)
        exact = body.general.geometry(theta, branch)
        reference = exact.support_height + np.sum(exact.ground_normal * moved.origin, axis=-1)
        assert np.max(np.abs(zp - reference)) <= 1e-13 * body.size
        assert np.max(np.abs(moved.phase_height(u) - zp)) == 0.0
        assert np.max(np.abs(zp - z - c * n[..., 1])) <= rounding
        # the θ chart moves with it
        pose = moved.geometry(theta, branch)
        assert np.max(np.abs(pose.height - reference)) <= rounding
        assert np.max(np.abs(pose.contact_a + moved.origin
                             - (exact.contact_a + body.centroid))) <= rounding


def test_moved_body_keeps_phase_rates_and_angular_velocity():
    """What does not depend on the reference point is shared bit for bit."""
    body = _egg()
    moved = body.about(-2e-3).about(5e-3)
    assert moved.offset == pytest.approx(3e-3, abs=ulps(16, 5e-3))    # −2e-3 + 5e-3, rounded
    u = np.linspace(0, TWO_PI, 97)
    for name in ('phase_rates', 'phase_angles_with_rates'):
        for x, y in zip(getattr(body, name)(u), getattr(moved, name)(u)):
            assert np.array_equal(x, y)
    assert np.array_equal(body.phase_angular_velocity(u), moved.phase_angular_velocity(u))
    assert body.about(0.0) is body
    assert 'about(0.003' in repr(moved)


def test_moved_size_is_the_farthest_rim_point():
    """size from P against a brute-force maximum over 200 001 rim points of both disks
    (the rim sampling bounds the error by ~(spacing)² / size ≈ 1e-11 m)."""
    body = _egg()
    lam = body.lamina
    for c in (-0.03, 0.004, 0.05):
        moved = body.about(c)
        s = np.linspace(-math.pi, math.pi, 200_001)
        x, y = lam.point(s)[..., 0], lam.point(s)[..., 1]
        p = moved.origin[1]
        disk1 = np.hypot(x, y - body.delta - p)
        disk2 = np.hypot(x, body.delta + body.general.sigma * y - p)
        brute = max(disk1.max(), disk2.max())
        assert moved.size == pytest.approx(brute, abs=1e-10)


@pytest.mark.parametrize('offset', [float('nan'), 'x', True, 1.0, -0.5, None])
def test_bad_offsets_are_refused_in_one_line(offset):
    with pytest.raises(ValueError) as info:
        _egg().about(offset)
    assert '\n' not in str(info.value) and 'offset' in str(info.value)


def test_mass_properties_of_a_moved_body_are_from_its_point():
    """The centre of mass from P is the one from G minus the offset; inertia about it."""
    body, c = _egg(), 2e-3
    for model in ('laminae', 'solid'):
        at_g = mass_properties_of(model, body, 1.0)
        at_p = mass_properties_of(model, body.about(c), 1.0)
        assert np.array_equal(at_p.inertia, at_g.inertia)
        assert at_p.center_of_mass == pytest.approx(at_g.center_of_mass - [0, c, 0],
                                                    abs=ulps(16, c))     # a rounded shift


def test_centred_on_mass_moves_the_egg_and_leaves_symmetric_bodies():
    """The parallel egg's solid has its centre of mass off G along e2 (here 2.1e-4 m, 0.2 % of
    the size): the centred body is moved there and reports it at its origin. A body with
    the disk-swap symmetry (square superellipse) moves by rounding only; the ellipse's
    EllipseBody is returned as it is."""
    body = _egg()
    solid = mass_properties_of('solid', body, 1.0)
    assert abs(solid.center_of_mass[1]) > 1e-3 * body.size
    moved, props = centred_on_mass('solid', body, 1.0)
    assert moved.offset == solid.center_of_mass[1]
    assert np.array_equal(props.center_of_mass, np.zeros(3))
    assert np.array_equal(props.inertia, solid.inertia)
    square, _ = centred_on_mass('solid', _square(), 1.0)
    assert abs(square.offset) <= ulps(16, square.size)     # the quadrature's rounding
    ellipse = EllipseBody(0.1, 0.08, 0.04)
    same, props = centred_on_mass('solid', ellipse, 1.0)
    assert same is ellipse
    with pytest.raises(ValueError, match='center_of_mass must be G'):
        RollingDynamics(body, solid)


def _real_energy(body, com, props, u, u_dot, h=2e-3):
    """E of the body whose centre of mass is G + com e2 (G the laminae's centroid), from the
    unmoved body's world poses: 5-point differences in u of the centre of mass's position
    and of the rotation (ω from Ṙ Rᵀ)."""
    cycle = RollingCycle(body)
    steps = np.arange(-2, 3) * h
    poses = cycle.poses(u[:, None] + steps)
    rotation = Rotation.from_quat(poses.quaternion.reshape(-1, 4)).as_matrix().reshape(
        u.shape + (5, 3, 3))
    x = poses.position_g + rotation @ np.array([0.0, com, 0.0])
    weights = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) / (12 * h)
    dx = np.einsum('k,nki->ni', weights, x)
    dr = np.einsum('k,nkij->nij', weights, rotation)
    spin = dr @ np.swapaxes(rotation[:, 2], -1, -2)
    omega = np.stack([spin[:, 2, 1], spin[:, 0, 2], spin[:, 1, 0]], axis=-1)
    inertia = rotation[:, 2] @ props.inertia @ np.swapaxes(rotation[:, 2], -1, -2)
    kinetic = 0.5 * u_dot**2 * (props.mass * np.sum(dx * dx, axis=-1)
                                + np.einsum('ni,nij,nj->n', omega, inertia, omega))
    return kinetic + props.mass * GRAVITY * x[:, 2, 2]


@pytest.mark.parametrize('omega0', [0.5, 4.0, 8.0])
def test_solid_parallel_egg_conserves_the_real_bodys_energy(omega0):
    """The solid parallel egg simulated with the centred pair, through the three solvers: a
    libration (ω0 = 0.5 rad/s), the band just above the highest barrier (4 rad/s, DOP853 at
    rtol 1e-12) and rolling over (8 rad/s, quadrature). The energy of the real body (centre
    of mass off G, from the unmoved poses) stays constant to the solver's tolerance and the
    differences' truncation: measured ≤ 3.0e-12 M g L (h = 5e-4 rad; 3e-11 at h = 2e-3,
    truncation). The same libration with the centre of mass wrongly put at G: 1.2e-2."""
    body = _egg()
    solid = mass_properties_of('solid', body, 1.0)
    dyn = RollingDynamics(*centred_on_mass('solid', body, 1.0), gravity=GRAVITY)
    motion = simulate(dyn, np.linspace(0.0, 3.0, 61), theta0=0.3, omega0=omega0,
                      tolerance=1e-12)
    energy = _real_energy(body, solid.center_of_mass[1], solid, motion.phase,
                          motion.phase_rate, h=5e-4)
    assert np.ptp(energy) <= 1e-11 * dyn.energy_scale

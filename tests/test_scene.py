"""Tests of scenes (slope, drive, dissipation) against independent references.

References, none of them the module's own energy or forces:

* the energy integral t(u) = ∫ du / u̇(u) by quadrature (tests/energy_integral.py) for the
  level, lossless scene, and the MotionStream of that scene as a second method for the
  others (bit for bit where the scene keeps its fast path);
* finite differences in time of the published poses (gravity frame W): v_G, a_G, and ω from
  the quaternions (ω = 2 q̇ ⊗ q̄), hence T = ½ M v_G² + ½ ω·(R I Rᵀ) ω and E = T + M g z_G;
* Newton's law with the tilted gravity, F_A + F_B + M g = M a_G, and the determinate normal
  sum N_A + N_B = M (a_G − g)·n_S built from it for the rolling-resistance work; Euler's law
  about the other contact for each normal force alone (where a contact lifts off);
* the stick condition |V′| ≤ μ_r k N and the rest criterion for where a body comes to rest;
* the closed-form lag Ω(t) = Ω_cmd + (Ω₀ − Ω_cmd) e^{−t/T} of the speed drive;
* geometry: contacts on the sloped plane, no slip at A and B (v_G + ω × (P − G) = 0).

Units SI; tolerances relative to M g (forces), M g L (energies), stated with each constant.
"""

import math

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson
from scipy.spatial.transform import Rotation

from twodisk_ros.physics import MotionStream, RollingDynamics, EllipseBody
from twodisk_ros.physics.mass.models import mass_properties
from twodisk_ros.physics.scenes.scene import Scene, quaternion_product
from twodisk_ros.physics.scenes.events import first_failure, settle
from twodisk_ros.physics.scenes.motion import SceneStream, scene_stream
from twodisk_ros.physics.scenes.terms import SceneTerms

from energy_integral import phase_rate, times_to

MASS, GRAVITY = 1.3, 9.81
OLOID = (0.1, 0.1, 0.05)
FAT = (0.1, 0.2, 0.05)                     # θ = 0 family stable
TOL = 1e-12                                # rtol of the scene integrator in these tests
#: finite-difference step (s) and 5-point stencils: truncation ~h⁴ and rounding ~ε L/h stay
#: below 1e-9 of the scales at speeds of a few rad/s (as in test_contact_forces)
FD_STEP = 4e-4
#: E from finite differences of poses against E₀ (× M g L): the stencils' truncation
#: (~1e-10) plus the integrator at rtol 1e-12
ENERGY_TOL = 2e-9
#: F_A + F_B + M g − M a_G (× M g): as test_contact_forces' FORCE_TOL
FORCE_TOL = 2e-8
#: E + W_d − E₀ (× M g L) with the dissipated work W_d by Simpson's rule on the 0.01 s grid of
#: the centres: its h⁴ error (measured 5.5e-9 damping, 6.8e-9 rolling resistance; 2.3e-7
#: and 9.1e-7 by the trapezoid rule before) plus ENERGY_TOL
BALANCE_TOL = 2e-8

_DYNAMICS = {}


def dynamics_of(shape):
    if shape not in _DYNAMICS:
        _DYNAMICS[shape] = RollingDynamics(EllipseBody(*shape),
                                           mass_properties('laminae', *shape, MASS), GRAVITY)
    return _DYNAMICS[shape]


def start(dynamics, theta0=0.3, omega0=3.0):
    u0 = float(dynamics.body.phase_from_theta(theta0, 1))
    return u0, dynamics.initial_phase_rate(u0, omega0)


def stencil(centres, step=FD_STEP):
    return (np.asarray(centres)[:, None] + step * np.arange(-2, 3)).ravel()


def d5(x, step=FD_STEP):
    x = x.reshape((-1, 5) + x.shape[1:])
    return (x[:, 0] - 8 * x[:, 1] + 8 * x[:, 3] - x[:, 4]) / (12 * step)


def dd5(x, step=FD_STEP):
    x = x.reshape((-1, 5) + x.shape[1:])
    return (-x[:, 0] + 16 * x[:, 1] - 30 * x[:, 2] + 16 * x[:, 3] - x[:, 4]) / (12 * step**2)


def kinematics(terms, u):
    """From poses at 5-point stencils: G, v_G, a_G, ω (world), T and E at the centres."""
    g, a, b, q = terms.poses(u)
    velocity, acceleration = d5(g), dd5(g)
    q_mid = q[2::5]
    q_dot = d5(q)
    conj = q_mid * [-1, -1, -1, 1]
    omega = 2 * quaternion_product(q_dot, conj)[:, :3]
    rot = Rotation.from_quat(q_mid).as_matrix()
    inertia = rot @ terms.dynamics.mass.inertia @ np.transpose(rot, (0, 2, 1))
    kinetic = 0.5 * MASS * np.sum(velocity**2, -1) + 0.5 * np.einsum(
        'ni,nij,nj->n', omega, inertia, omega)
    energy = kinetic + MASS * GRAVITY * g[2::5, 2]
    return dict(g=g[2::5], a=a[2::5], b=b[2::5], velocity=velocity,
                acceleration=acceleration, omega=omega, energy=energy)


def run(shape, scene, centres, theta0=0.3, omega0=3.0):
    dynamics = dynamics_of(shape)
    terms = SceneTerms(dynamics, scene)
    u0, u_dot0 = start(dynamics, theta0, omega0)
    stream = SceneStream(terms, u0, u_dot0, tolerance=TOL)
    samples = stream.samples(stencil(centres))
    return terms, samples, kinematics(terms, samples.phase)


#: outer step (s) of the 5-point dE/dt of E from poses: E varies on the body's sharpest
#: features (~0.05 s for these shapes at 7 rad/s), truncation ~ (δ/0.05)⁴ / 30 ≈ 1e-6
OUTER_STEP = 2e-3


def energy_rate(shape, scene, centres, omega0=3.0):
    """dE/dt at the centres (5-point, OUTER_STEP) of E from poses; samples and ω there."""
    terms, samples, kin = run(shape, scene, stencil(centres, OUTER_STEP), omega0=omega0)
    mid = slice(12, None, 25)
    picked = type(samples)(**{k: v[mid] for k, v in vars(samples).items()})
    return terms, picked, d5(kin['energy'], OUTER_STEP), kin['omega'][2::5]


# ------------------------------------------------------------------ the level, lossless scene

def test_default_scene_is_the_energy_integral():
    """The default scene (level, no drive, no losses) takes the closed-form path, and its
    motion is the energy integral (tests/energy_integral.py): the phase to 1e-11 rad and u̇ to
    1e-11 of u̇0 over 20 s, the accuracy docs/physics.md states for the table method
    (measured 6e-15 rad and 2e-13)."""
    dynamics = dynamics_of(OLOID)
    u0, u_dot0 = start(dynamics)
    t = np.linspace(0.0, 20.0, 2001)
    stream = scene_stream(dynamics, Scene(gravity=GRAVITY), u0, u_dot0)
    assert isinstance(stream, MotionStream)        # the fast solver, chosen in the physics
    u, u_dot = stream.sample(t)
    energy = float(dynamics.energy(u0, u_dot0))
    assert np.max(np.abs(u_dot - phase_rate(dynamics, energy, u))) < 1e-11 * u_dot0
    checked = np.arange(100, t.size, 100)
    assert u[-1] - u0 > 6 * math.pi                  # rolled over several cycles
    times = times_to(dynamics, energy, u0, u[checked])
    assert np.max(np.abs(times - t[checked]) * u_dot[checked]) < 1e-11


def test_general_integrator_on_flat_ground_agrees_with_the_quadrature():
    # a second method: DOP853 on the scene's tables against the closed-form quadrature;
    # measured 4e-10 rad over 10 s (u ≈ 30 rad) at rtol 1e-12 (DOP853 in τ on (u, w))
    dynamics = dynamics_of(OLOID)
    u0, u_dot0 = start(dynamics)
    t = np.linspace(0.0, 10.0, 101)
    samples = SceneStream(SceneTerms(dynamics, Scene(gravity=GRAVITY)), u0, u_dot0,
                          tolerance=TOL).samples(t)
    ref_u, ref_u_dot = MotionStream(dynamics, u0, u_dot0).sample(t)
    assert np.max(np.abs(samples.phase - ref_u)) < 1e-9
    assert np.max(np.abs(samples.phase_rate - ref_u_dot)) < 1e-9


def test_speed_drive_at_its_command_is_the_kinematic_motion():
    dynamics = dynamics_of(OLOID)
    u0, u_dot0 = start(dynamics)
    omega = u_dot0 * float(dynamics.angular_speed_per_phase(u0))
    scene = Scene(gravity=GRAVITY, slope=0.2, drive='speed', command=omega, damping=0.1)
    stream = scene_stream(dynamics, scene, u0, u_dot0)
    t = np.linspace(0.0, 5.0, 51)
    u, _ = stream.sample(t)
    ref, _ = MotionStream(dynamics, u0, u_dot0, mode='kinematic').sample(t)
    assert np.array_equal(u, ref)


# ------------------------------------------------------------------------------ slope

@pytest.mark.parametrize('shape, slope, heading0, duration', [
    (OLOID, 0.05, 0.0, 3.0), (OLOID, 0.2, 0.7, 1.2), (FAT, 0.1, math.pi / 2, 3.0),
    (FAT, -0.15, 2.5, 1.5)])
def test_energy_on_a_slope_is_conserved_from_poses(shape, slope, heading0, duration):
    # (the stencils' truncation grows as (h u̇)⁴: at 0.2 rad the oloid reaches u̇ = 30 rad/s
    # by 3 s, and 2e-7 M g L; it stays below 10 rad/s for 1.2 s)
    scene = Scene(gravity=GRAVITY, slope=slope, heading0=heading0)
    terms, samples, kin = run(shape, scene, np.linspace(0.01, duration, 30))
    scale = terms.dynamics.energy_scale
    assert np.max(np.abs(kin['energy'] - kin['energy'][0])) < ENERGY_TOL * scale
    # the energy of a non-flat scene is not the level ground's: the check would fail without the slope
    flat = kin['energy'] - MASS * GRAVITY * kin['g'][:, 2] + MASS * GRAVITY * \
        terms.dynamics.body.phase_height(samples.phase[2::5])
    assert np.ptp(flat) > 1e3 * ENERGY_TOL * scale


def test_contacts_lie_on_the_sloped_plane_and_do_not_slip():
    slope = 0.15
    terms, samples, kin = run(OLOID, Scene(gravity=GRAVITY, slope=slope, heading0=0.4),
                              np.linspace(0.01, 2.0, 20))
    normal = np.array([math.sin(slope), 0.0, math.cos(slope)])      # n_S in W
    size = terms.dynamics.body.size
    assert np.max(np.abs(kin['a'] @ normal)) < 1e-13 * size
    assert np.max(np.abs(kin['b'] @ normal)) < 1e-13 * size
    for contact in ('a', 'b'):
        slip = kin['velocity'] + np.cross(kin['omega'], kin[contact] - kin['g'])
        speed = np.max(np.linalg.norm(kin['velocity'], axis=-1))
        assert np.max(np.linalg.norm(slip, axis=-1)) < 1e-8 * speed
    # the mean travel heads downhill-ish: G descends along gravity
    assert kin['g'][-1, 2] < kin['g'][0, 2]


@pytest.mark.parametrize('scene', [
    Scene(gravity=GRAVITY, slope=0.1, heading0=0.3),
    Scene(gravity=GRAVITY, slope=-0.2, heading0=1.2, drive='torque', command=0.02),
    Scene(gravity=GRAVITY, slope=0.1, drive='speed', command=5.0, lag=0.3)])
def test_forces_obey_newton_with_tilted_gravity(scene):
    terms, samples, kin = run(OLOID, scene, np.linspace(0.01, 1.5, 15))
    mid = slice(2, None, 5)
    forces = terms.forces(samples.phase[mid], samples.phase_rate[mid],
                          samples.phase_acceleration[mid])
    gravity = np.array([0.0, 0.0, -GRAVITY])
    residual = forces.force_a + forces.force_b + MASS * gravity - MASS * kin['acceleration']
    assert np.max(np.abs(residual)) < FORCE_TOL * MASS * GRAVITY
    if scene.drive == 'none':     # a free motion needs no external moment about AB
        assert np.max(np.abs(forces.torque)) < 1e-9 * MASS * GRAVITY * 0.1


def test_body_aimed_across_the_slope_rocks():
    dynamics = dynamics_of(OLOID)
    terms = SceneTerms(dynamics, Scene(gravity=GRAVITY, slope=0.3, heading0=math.pi / 2))
    stable = [eq for eq in terms.equilibria() if eq.stable]
    u0 = stable[0].phase + 0.3
    samples = SceneStream(terms, u0, 0.0, tolerance=TOL).samples(np.linspace(0, 20, 2001))
    assert np.ptp(samples.phase) < 1.0          # stays in its well
    g = terms.poses(samples.phase)[0]
    assert np.ptp(g[:, 0]) < terms.dynamics.body.size   # no net travel downhill
    # the period of the rocking tends to the small-oscillation period of the rest pose
    small = SceneStream(terms, stable[0].phase + 1e-4, 0.0, tolerance=TOL).samples(
        np.linspace(0, 3 * stable[0].period, 3001))
    crossings = np.flatnonzero(np.diff(np.sign(small.phase_rate)) != 0)
    half = np.diff(small.t[crossings])
    assert abs(2 * np.mean(half) / stable[0].period - 1) < 2e-3


def test_equilibria_on_a_slope_are_stationary_heights_and_vanish_past_tipping():
    dynamics = dynamics_of(OLOID)
    for slope in (0.02, 0.05):
        terms = SceneTerms(dynamics, Scene(gravity=GRAVITY, slope=slope))
        found = terms.equilibria()
        assert found and any(eq.stable for eq in found)
        for eq in found:      # dz_G/du = 0 along gravity, by central differences of poses
            h = 1e-5
            z = terms.poses(np.array([eq.phase - h, eq.phase + h]))[0][:, 2]
            assert abs(z[1] - z[0]) / (2 * h) < 1e-9 * dynamics.body.size
        assert terms.standing()[0]
    # straight downhill, the oloid's tipping limit: max h'/s' over the cycle, from poses
    u = np.linspace(0, 2 * math.pi, 4001)
    flat = SceneTerms(dynamics, Scene(gravity=GRAVITY))
    g = flat.poses(u)[0]
    ratio = np.gradient(g[:, 2], u) / np.gradient(g[:, 0], u)
    limit = math.atan(np.max(ratio[np.gradient(g[:, 0], u) > 0]))
    below = SceneTerms(dynamics, Scene(gravity=GRAVITY, slope=0.98 * limit))
    above = SceneTerms(dynamics, Scene(gravity=GRAVITY, slope=1.02 * limit))
    assert below.equilibria() and not above.equilibria()
    ok, why = above.standing()
    assert not ok and 'tips over' in why


#: outer step (s) of the nested stencils that difference the angular momentum: with ω below
#: 10 rad/s, truncation (ω H)⁴ / 30 < 1e-7 of dL/dt
OUTER_H = 2e-3


def normal_forces(terms, stream, centres):
    """(N_A, N_B) (N) at the centres from Newton–Euler alone, with finite differences of the
    poses: ω from the quaternions on inner stencils, dL/dt (L = R I Rᵀ ω about G) and a_G on
    outer ones (step OUTER_H). Moments about the other contact Q, along e = n × (P − Q)/|P − Q|
    (in the ground, normal to AB): friction and the pull along AB drop out, so
    N_P |P − Q| = −(dL/dt + (G − Q) × M (a_G − g))·e."""
    outer, inner = OUTER_H * np.arange(-2, 3), FD_STEP * np.arange(-2, 3)
    times = (np.asarray(centres)[:, None, None] + outer[None, :, None]
             + inner[None, None, :]).ravel()
    g, a, b, q = terms.poses(stream.samples(times).phase)
    middle = q[2::5]
    omega = 2 * quaternion_product(d5(q), middle * [-1, -1, -1, 1])[:, :3]
    rot = Rotation.from_quat(middle).as_matrix()
    inertia = rot @ terms.dynamics.mass.inertia @ np.transpose(rot, (0, 2, 1))
    rate = d5(np.einsum('nij,nj->ni', inertia, omega), OUTER_H)
    centre_g, contact_a, contact_b = g[2::5][2::5], a[2::5][2::5], b[2::5][2::5]
    push = MASS * (dd5(g[2::5], OUTER_H) - [0.0, 0.0, -GRAVITY])
    slope = terms.scene.slope
    normal = np.array([math.sin(slope), 0.0, math.cos(slope)])
    out = []
    for p, other in ((contact_a, contact_b), (contact_b, contact_a)):
        length = np.linalg.norm(p - other, axis=-1)
        e = np.cross(normal, (p - other) / length[:, None])
        moment = rate + np.cross(centre_g - other, push)
        out.append(-np.einsum('ni,ni->n', moment, e) / length)
    return out


def test_lift_off_on_a_slope_is_reported_when_newton_says():
    """The oloid rolling down a 0.1 rad slope lifts contact A off. Located on the dense
    output (first_failure with the stream: Brent to 1e-12 s), it is where N_A of Newton–Euler
    (:func:`normal_forces`) crosses 0: a quartic through N_A at seven times 4 ms apart has its
    root within 1e-7 s (measured 4e-8 s; N_A falls at ~130 N/s, and the nested differences
    are good to ~2e-7 M g). From the samples alone the report is the first sample after it."""
    dynamics = dynamics_of(OLOID)
    terms = SceneTerms(dynamics, Scene(gravity=GRAVITY, slope=0.1))
    u0, u_dot0 = start(dynamics)
    stream = SceneStream(terms, u0, u_dot0, tolerance=TOL)
    samples = stream.samples(np.linspace(0.01, 1.5, 150))
    located = first_failure(terms, samples, stream)
    sampled = first_failure(terms, samples)
    assert not located.valid and located.kind == sampled.kind == 'lift-off A'
    assert samples.t[located.index - 1] < located.time <= samples.t[located.index]
    assert sampled.index == located.index and sampled.time == samples.t[located.index]
    offsets = 0.004 * np.arange(-3, 4)
    normal_a, normal_b = normal_forces(
        terms, SceneStream(terms, u0, u_dot0, tolerance=TOL), located.time + offsets)
    fit = np.polynomial.Polynomial.fit(offsets, normal_a, 4).convert()
    roots = fit.roots()
    roots = roots[np.abs(roots.imag) < 1e-12].real
    assert np.min(np.abs(roots)) < 1e-7
    assert np.all(normal_a[:3] > 0) and np.all(normal_a[4:] < 0)   # A lifts off, B stays
    assert np.all(normal_b > 0.5 * MASS * GRAVITY)


# ------------------------------------------------------------------------------ drives

def test_torque_drive_power_is_torque_times_angular_speed():
    tau = 0.03
    scene = Scene(gravity=GRAVITY, drive='torque', command=tau)
    terms, samples, power, omega = energy_rate(OLOID, scene, np.linspace(0.05, 2.0, 40))
    expected = tau * np.linalg.norm(omega, axis=-1)
    assert np.all(samples.phase_rate > 0)
    assert np.max(np.abs(power - expected)) < 1e-6 * np.max(expected)
    # the module's power and its integrated balance: E − W_d = E₀
    assert np.max(np.abs(samples.power - expected)) < 1e-6 * np.max(expected)
    assert np.ptp(samples.balance) < 1e-9 * terms.dynamics.energy_scale


def test_speed_drive_follows_the_first_order_lag():
    command, lag, omega0 = 7.0, 0.4, 3.0
    scene = Scene(gravity=GRAVITY, drive='speed', command=command, lag=lag, slope=0.05)
    terms, samples, power, omega = energy_rate(FAT, scene, np.linspace(0.01, 2.0, 25),
                                               omega0=omega0)
    expected = command + (omega0 - command) * np.exp(-samples.t / lag)
    assert np.max(np.abs(np.linalg.norm(omega, axis=-1) - expected)) < 1e-8 * command
    # the drive's power is what the energy gains (no dissipation)
    assert np.max(np.abs(power - samples.power)) < 1e-5 * np.max(np.abs(samples.power))


# ------------------------------------------------------------------------- dissipation

def test_damping_energy_balance_from_poses():
    c = 0.004
    terms, samples, kin = run(OLOID, Scene(gravity=GRAVITY, damping=c),
                              np.linspace(0.01, 4.0, 400))
    centres = samples.t[2::5]
    dissipated = cumulative_simpson(c * np.sum(kin['omega']**2, -1), x=centres, initial=0.0)
    balance = kin['energy'] + dissipated
    scale = terms.dynamics.energy_scale
    assert np.ptp(kin['energy']) > 0.02 * scale              # it does slow down
    assert np.max(np.abs(balance - balance[0])) < BALANCE_TOL * scale
    assert np.max(np.abs(samples.balance - samples.balance[0])) < 1e-9 * scale


def test_rolling_resistance_energy_balance_from_newton():
    mu_r, slope = 0.02, 0.05
    terms, samples, kin = run(OLOID, Scene(gravity=GRAVITY, slope=slope, heading0=1.0,
                                           rolling_resistance=mu_r), np.linspace(0.01, 3, 300))
    centres = samples.t[2::5]
    normal = np.array([math.sin(slope), 0.0, math.cos(slope)])
    # N_A + N_B from Newton alone: M (a_G − g)·n_S
    load = MASS * (kin['acceleration'] + [0.0, 0.0, GRAVITY]) @ normal
    rate = mu_r * load * np.linalg.norm(kin['velocity'], axis=-1)
    dissipated = cumulative_simpson(rate, x=centres, initial=0.0)
    scale = terms.dynamics.energy_scale
    balance = kin['energy'] + dissipated
    assert dissipated[-1] > 0.01 * scale
    assert np.max(np.abs(balance - balance[0])) < BALANCE_TOL * scale


@pytest.mark.parametrize('scene', [Scene(gravity=GRAVITY, damping=0.01),
                                   Scene(gravity=GRAVITY, rolling_resistance=0.01)])
def test_dissipation_brings_the_body_to_rest_on_a_stable_equilibrium(scene):
    dynamics = dynamics_of(OLOID)
    terms = SceneTerms(dynamics, scene)
    u0, u_dot0 = start(dynamics, 0.3, 2.0)
    time, u, eq = settle(terms, u0, u_dot0, t_max=120.0, step=2.0)
    assert math.isfinite(time) and eq is not None and eq.stable
    # the oloid's stable rest poses: θ = ±π/2 (the closed form of docs/physics.md)
    theta = float(dynamics.body.phase_geometry(u).theta)
    if scene.rolling_resistance:
        # it sticks where |V′(u)| ≤ μ_r k N (docs/physics.md#scenes), k = |dG/du|, N = M g at
        # rest on level ground: V′ and k by central differences of V and of G's position
        # (h = 1e-5 rad: truncation ~1e-10 relative), inside the stuck zone of θ = ±π/2
        h = 1e-5
        slope = (float(dynamics.potential(u + h)) - float(dynamics.potential(u - h))) / (2 * h)
        g = dynamics.cycle.poses(np.array([u - h, u + h])).position_g
        lever = np.linalg.norm(g[1] - g[0]) / (2 * h)
        assert abs(slope) <= scene.rolling_resistance * lever * MASS * GRAVITY * (1 + 1e-6)
        assert abs(abs(theta) - math.pi / 2) < math.pi / 4
    else:
        # damping alone: settled once E − V(u*) = 1e-9 M g L (settle's rest_energy), so
        # ½ V″(u*) (u − u*)² ≤ 1e-9 M g L to leading order (1 % for the cubic term)
        centre = eq.phase + 2 * math.pi * round((u - eq.phase) / (2 * math.pi))
        curvature = float(dynamics.potential_curvature(centre))
        reach = math.sqrt(2e-9 * dynamics.energy_scale / curvature)
        assert abs(u - centre) <= 1.01 * reach
        assert abs(abs(float(dynamics.body.phase_geometry(centre).theta)) - math.pi / 2) < 1e-12


# ------------------------------------------------------------------------------ input

@pytest.mark.parametrize('kwargs, word', [
    (dict(slope=1.6), 'slope'), (dict(slope=math.nan), 'slope'), (dict(drive='fast'), 'drive'),
    (dict(lag=0.0), 'lag'), (dict(damping=-1.0), 'damping'), (dict(command='x'), 'command'),
    (dict(rolling_resistance=math.inf), 'rolling_resistance'), (dict(friction=-1), 'friction')])
def test_bad_scene_values_are_one_line_errors(kwargs, word):
    with pytest.raises(ValueError) as error:
        Scene(**kwargs)
    message = str(error.value)
    assert message.startswith(word) and '\n' not in message


def test_scene_gravity_must_match_the_dynamics():
    with pytest.raises(ValueError, match='gravity'):
        SceneTerms(dynamics_of(OLOID), Scene(gravity=1.0))

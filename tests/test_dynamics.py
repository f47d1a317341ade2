"""Tests of :mod:`twodisk_ros.physics.motion.dynamics` against independent references.

Nothing here compares the module with its own output. The references are:

* conservation laws (energy; for a constant height of G, the kinetic energy ½ m(u) u̇²);
* an energy computed from scratch in the test, from finite differences *in time* of the
  simulated poses (``RollingMotion.states()``): ½ ωᵀ I_G ω + ½ M |Ġ|² + M g z_G, with ω
  from (R(t+h) − R(t−h))/2h · Rᵀ;
* an effective mass m(u) computed from scratch, from finite differences *in u* of the
  rotation matrices and of G along the cycle (``RollingCycle.state``), not from
  ``dynamics.effective_mass``;
* closed forms of the physics notes (z_G at θ = 0 and θ = π/2, the constant height of the
  Two-Circle-Roller), the small-oscillation period T = 2π √(m / M g z_G″), the scaling law
  T ∝ √(L / g), the rolling constraint (ω ∥ AB);
* a second method: ``direct`` against ``table``, ``MotionStream``'s restarted chunks against
  one integration over the whole span, and the trace of A against an independent DOP853
  integration of the paper's eqs. (4)-(6) (``integrate_contact_trace``).

Known bugs, if any, are marked ``xfail(strict=True)`` with the input, the expected and the
result in the reason.

Units: SI (m, kg, s, rad). Relative drifts are relative to M g × body size.
"""

import functools
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.interpolate import CubicSpline

from paper_forms import curvature_at_half_pi
from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.cycle import RollingCycle, integrate_contact_trace
from twodisk_ros.physics import MotionStream, RollingDynamics, simulate, simulate_phase
from twodisk_ros.physics.stability.equilibria import STABLE, UNSTABLE, equilibria
from twodisk_ros.physics.mass.models import laminae, solid_hull
from twodisk_ros.physics.motion.solvers import QuadratureSolution

# ----------------------------------------------------------------------------- constants

MASS = 1.3        # kg: not 1, so a missing factor M shows
GRAVITY = 9.81    # m/s²

OLOID = (1.0, 1.0, 0.5)                   # (a, b, Δ) in m
FIGURE3 = (2.0, 1.0, 1.0)                 # the paper's figure-3 body
TCR = (1.0, 1.0, 1.0 / math.sqrt(2.0))    # Two-Circle-Roller: z_G constant
THIN = (1.0, 0.2, 0.9)                    # b << a: turning points unstable
FAT = (1.0, 2.0, 0.3)                     # b > a: θ = ±π/2 unstable
LONG = (3.0, 0.5, 0.02)                   # a >> b, small Δ: θ = 0 unstable

#: rtol of the ODE solver in the energy and method-agreement tests.
SOLVER_TOL = 1e-11
#: Bound on the module's own energy drift max|E − E0| / (M g size), per method. docs/physics.md
#: (Motion): table 5e-14 to 1.4e-13 rolling, 9e-13 to 2e-12 oscillating over the benchmarks'
#: runs; here (≤ 3 s) measured ≤ 1.5e-14 rolling and ≤ 2.9e-13 oscillating (laminae and
#: solid). The direct method follows SOLVER_TOL: measured ≤ 1.4e-11. A wrong equation of
#: motion (e.g. a missing ½ m′ u̇² term) drifts by > 1e-3.
ENERGY_DRIFT_MAX = {'table': 1e-12, 'direct': 5e-11}
#: Bound on the drift of the energy rebuilt from finite differences of the poses in time,
#: relative to M g size. The 5-point stencil with step FD_STEP_T has truncation error
#: ~ (Ω h)⁴ / 30 ≈ 1e-12 and rounding ~ 1e-16 / h ≈ 1e-13, and differentiates the error of
#: the samples (~ 1e-15 for the quadrature path, ~ SOLVER_TOL |u| for DOP853's dense output,
#: which the 1/h of the stencil amplifies). Measured ≤ 1.1e-10 (table), ≤ 5.4e-10 (direct,
#: |ω| ≤ 3 rad/s).
ENERGY_FD_MAX = {'table': 1e-9, 'direct': 5e-9}
#: Kinematic mode: relative error of |ω| from the rotation matrices (same error sources;
#: measured ≤ 5e-11 table, ≤ 4.3e-9 direct).
SPEED_RTOL = {'table': 1e-9, 'direct': 3e-8}
#: u̇ against the 5-point difference of u (rad/s, |u̇| ≤ 6): truncation ~ h⁴ u⁽⁵⁾ / 30 and
#: the dense output's error / h; measured ≤ 2.3e-9 (table), ≤ 1.1e-8 (direct, kinematic).
RATE_ATOL = {'table': 2e-8, 'direct': 5e-8}
#: Step (s) of the 5-point differences in time of the simulated poses.
FD_STEP_T = 1e-3
#: Step (rad) of the 5-point differences in u of the cycle's poses.
FD_STEP_U = 1e-3
#: Small-oscillation period 2π √(m/V″) against m from differences of the poses in u (error
#: ~1e-12 at FD_STEP_U: measured 2.1e-12) and V″ from the paper's curvature at θ = ±π/2:
#: measured ≤ 2.2e-12 relative (Oloid, Figure 3 body, all four stable equilibria).
PERIOD_RTOL = 1e-11
#: Method agreement: max |position difference| / body size (issue: < ~1e-8).
AGREEMENT_MAX = 1e-8

STENCIL = np.array([-2, -1, 0, 1, 2])
FIRST = np.array([1.0, -8.0, 0.0, 8.0, -1.0]) / 12.0          # × 1/h
SECOND = np.array([-1.0, 16.0, -30.0, 16.0, -1.0]) / 12.0     # × 1/h²


# ----------------------------------------------------------------------------- helpers

@functools.lru_cache(maxsize=None)
def model(abd, mass_model='laminae', gravity=GRAVITY):
    """(body, cycle, mass properties, dynamics) for a shape (a, b, Δ) in m."""
    body = EllipseBody(*abd)
    cycle = RollingCycle(body)
    if mass_model == 'laminae':
        mass = laminae(*abd, MASS)
    else:
        mass = solid_hull(*abd, MASS)
    return body, cycle, mass, RollingDynamics(body, mass, gravity=gravity, cycle=cycle)


def vee(w):
    """The axial vector of the (antisymmetric part of the) 3x3 matrices w."""
    return 0.5 * np.stack([w[..., 2, 1] - w[..., 1, 2], w[..., 0, 2] - w[..., 2, 0],
                           w[..., 1, 0] - w[..., 0, 1]], axis=-1)


def stencil_times(t_end, n, h=FD_STEP_T):
    """n centres in [2h, t_end], each with the 5 points of a central stencil (flattened)."""
    centres = np.linspace(2 * h, t_end, n)
    return centres, (centres[:, None] + h * STENCIL).ravel()


@functools.lru_cache(maxsize=None)
def stencil_run(abd, t_end, n, method, mode='dynamic', **init):
    """simulate() of the laminae body abd on stencil_times(t_end, n), run once per module
    and shared (read only) by the tests that check the same run against different
    references (energy, kinematic speed, and the other method)."""
    _, t = stencil_times(t_end, n)
    return simulate(model(abd)[3], t, mode=mode, method=method, tolerance=SOLVER_TOL, **init)


def rates_in_time(motion, h=FD_STEP_T):
    """From a motion (or RollingState) sampled on stencil_times: R, G, A, B, ω (world) and Ġ
    at the centres."""
    state = motion.states() if hasattr(motion, 'states') else motion
    n = state.rotation.shape[0] // 5
    rot = state.rotation.reshape(n, 5, 3, 3)
    g = state.position_g.reshape(n, 5, 3)
    r0 = rot[:, 2]
    r_dot = np.einsum('k,nkij->nij', FIRST, rot) / h
    omega = vee(np.einsum('nij,nkj->nik', r_dot, r0))
    g_dot = np.einsum('k,nki->ni', FIRST, g) / h
    a = state.contact_a.reshape(n, 5, 3)[:, 2]
    b = state.contact_b.reshape(n, 5, 3)[:, 2]
    return r0, g[:, 2], a, b, omega, g_dot


def energy_from_poses(motion, mass, gravity, h=FD_STEP_T):
    """E = ½ ωᵀ I_G ω + ½ M |Ġ|² + M g z_G from finite differences of the poses (J)."""
    r0, g, _, _, omega, g_dot = rates_in_time(motion, h)
    omega_body = np.einsum('nji,nj->ni', r0, omega)
    return (0.5 * np.einsum('ni,ij,nj->n', omega_body, mass.inertia, omega_body)
            + 0.5 * mass.mass * np.sum(g_dot**2, axis=-1) + mass.mass * gravity * g[:, 2])


def assert_rate_is_derivative(phase, phase_rate, atol, h=FD_STEP_T):
    """The reported u̇ is du/dt of the reported u (5-point difference; samples on a stencil)."""
    u_fd = np.einsum('k,nk->n', FIRST, np.reshape(phase, (-1, 5))) / h
    assert_allclose(np.reshape(phase_rate, (-1, 5))[:, 2], u_fd, rtol=0, atol=atol)


def _along_u(function, u, h):
    """function at u + k h for the stencil offsets k, stacked on a new first axis."""
    return np.stack([function(u + k * h) for k in STENCIL])


def omega_per_phase(cycle, u, h=FD_STEP_U):
    """ω_u (body frame, rad per rad of u) from differences of the cycle's rotations in u."""
    rot = _along_u(lambda x: cycle.state(x).rotation, np.asarray(u, float), h)
    r_dot = np.einsum('k,k...ij->...ij', FIRST, rot) / h
    omega_world = vee(np.einsum('...ij,...kj->...ik', r_dot, rot[2]))
    return np.einsum('...ji,...j->...i', rot[2], omega_world)


def effective_mass_from_poses(cycle, mass, u, h=FD_STEP_U):
    """m(u) = ω_uᵀ I_G ω_u + M |dG/du|² from differences of the cycle's poses (kg m²)."""
    u = np.asarray(u, float)
    omega = omega_per_phase(cycle, u, h)
    g = _along_u(lambda x: cycle.positions(x)[0], u, h)
    g_u = np.einsum('k,k...i->...i', FIRST, g) / h
    return (np.einsum('...i,ij,...j->...', omega, mass.inertia, omega)
            + mass.mass * np.sum(g_u**2, axis=-1))


def height_curvature_half_pi(abd, u):
    """d²z_G/du² (m/rad²) at θ = ±π/2, from the closed forms of the physics notes.

    V″(θ) = −√2 b³ (b² − 2a² + 2Δ²) / (4a⁴) per unit M g, times (dθ/du)², where dθ/du =
    (dθ/dη)(dη/du) = (a/b) η_max cos u at η = ±π/2 and η_max = arccos(−a/(a + 2Δ)).
    """
    a, b, delta = abd
    eta_max = math.acos(-a / (a + 2 * delta))
    return curvature_at_half_pi(a, b, delta) * (a / b * eta_max * math.cos(u)) ** 2


def height_theta0(a, b, delta):
    """z_G at θ = 0 (physics notes, closed form): b(a + Δ)/√(b² + 4aΔ + 4Δ²) (m)."""
    return b * (a + delta) / math.sqrt(b * b + 4 * a * delta + 4 * delta * delta)


def crossing_times(t, values):
    """Times where the sampled ``values`` change sign (cubic-spline roots, t > 0)."""
    roots = CubicSpline(t, values).roots(extrapolate=False)
    return roots[roots > 1e-9]


# ----------------------------------------------------------------------------- energy

# Initial states per body: one rolling over the top (E > max V, u monotone) and one
# oscillating about a stable θ = ±π/2 (E < max V, u̇ changes sign). Checked in the test.
STATES = {
    OLOID: {'roll': dict(theta0=0.3, omega0=3.0), 'oscillate': dict(theta0=1.2, omega0=0.0)},
    FIGURE3: {'roll': dict(theta0=0.3, omega0=3.0), 'oscillate': dict(theta0=0.6, omega0=0.5)},
}


# (method, kind) -> simulated span (s): the direct method is slow (~1-2 ms per RHS call), so
# it rolls over for 1 s only; an oscillation needs > half a period (oloid: 4.1 s) to turn.
SPANS = {('table', 'roll'): 3.0, ('table', 'oscillate'): 3.0,
         ('direct', 'roll'): 1.0, ('direct', 'oscillate'): 2.5}


@pytest.mark.parametrize('method', ['table', pytest.param('direct', marks=pytest.mark.slow)])
@pytest.mark.parametrize('kind', ['roll', 'oscillate'])
@pytest.mark.parametrize('abd', [OLOID, FIGURE3], ids=['oloid', 'figure3'])
def test_energy_is_conserved(abd, kind, method):
    body, cycle, mass, dyn = model(abd)
    init = STATES[abd][kind]
    t_end = SPANS[method, kind]
    motion = stencil_run(abd, t_end, 30, method, **init)
    scale = MASS * GRAVITY * body.size

    # the state is what it claims to be: rolling over or oscillating, and it really moves
    u_dot = motion.phase_rate
    if kind == 'roll':
        assert np.all(u_dot > 0) and motion.phase[-1] - motion.phase[0] > 1.0
    else:
        assert u_dot.min() < 0 < u_dot.max()
    z = motion.positions()[0][:, 2]
    assert np.ptp(z) > 1e-3 * body.size

    # the module's own energy (tables) is constant, and u̇ is du/dt
    assert motion.energy_drift < ENERGY_DRIFT_MAX[method]
    assert_rate_is_derivative(motion.phase, motion.phase_rate, RATE_ATOL[method])

    # the energy rebuilt from the poses alone is constant, and equals the initial energy
    # computed from scratch: ½ ω0² (êᵀ I ê + M |ê × r1|²) + M g z_G(u0), ê = ω_u/|ω_u|
    energy = energy_from_poses(motion, mass, GRAVITY)
    assert np.ptp(energy) / scale < ENERGY_FD_MAX[method]
    u0 = float(body.phase_from_theta(init['theta0']))
    axis = omega_per_phase(cycle, u0)
    axis = axis / np.linalg.norm(axis)
    state0 = cycle.state(u0)
    r1 = state0.rotation.T @ (state0.contact_a - state0.position_g)
    e0 = (0.5 * init['omega0'] ** 2 * (axis @ mass.inertia @ axis
                                       + MASS * np.sum(np.cross(axis, r1) ** 2))
          + MASS * GRAVITY * state0.position_g[2])
    assert_allclose(energy, e0, rtol=0, atol=ENERGY_FD_MAX[method] * scale)


def test_solid_oloid_conserves_energy():
    """The solid hull mass model works in RollingDynamics (energy from the poses)."""
    body, cycle, mass, dyn = model(OLOID, 'solid')
    laminae_inertia = model(OLOID)[2].inertia
    assert mass.volume > 0 and not np.allclose(mass.inertia, laminae_inertia, rtol=1e-3)
    scale = MASS * GRAVITY * body.size
    for init in (STATES[OLOID]['roll'], STATES[OLOID]['oscillate']):
        _, t = stencil_times(2.0, 20)
        motion = simulate(dyn, t, tolerance=SOLVER_TOL, **init)
        assert motion.energy_drift < ENERGY_DRIFT_MAX['table']
        energy = energy_from_poses(motion, mass, GRAVITY)
        assert np.ptp(energy) / scale < ENERGY_FD_MAX['table']
        assert np.ptp(motion.positions()[0][:, 2]) > 1e-3


@pytest.mark.slow
def test_solid_oloid_direct_matches_table():
    _, _, _, dyn = model(OLOID, 'solid')
    t = np.linspace(0.0, 1.0, 21)
    init = STATES[OLOID]['oscillate']
    p_table = simulate(dyn, t, method='table', tolerance=SOLVER_TOL, **init).positions()
    p_direct = simulate(dyn, t, method='direct', tolerance=SOLVER_TOL, **init).positions()
    for x, y in zip(p_table, p_direct):
        assert_allclose(y, x, rtol=0, atol=AGREEMENT_MAX * dyn.body.size)


# ----------------------------------------------------------------------------- kinematic

#: (t_end, n) of stencil_times for the kinematic runs (4 s: u̇ varies along the cycle)
KINEMATIC_SPAN = (4.0, 60)


@pytest.mark.parametrize('method', ['table', 'direct'])
@pytest.mark.parametrize('omega0', [2.5, -1.7])
@pytest.mark.parametrize('abd', [OLOID, FIGURE3], ids=['oloid', 'figure3'])
def test_kinematic_mode_holds_angular_speed(abd, omega0, method):
    _, _, _, dyn = model(abd)
    motion = stencil_run(abd, *KINEMATIC_SPAN, method, mode='kinematic', theta0=0.4,
                         omega0=omega0)
    _, _, a, b, omega, _ = rates_in_time(motion)
    # |ω| from the rotation matrices alone
    assert_allclose(np.linalg.norm(omega, axis=-1), abs(omega0), rtol=SPEED_RTOL[method])
    # rolling without slipping at A and B: the body turns about the line AB
    ab = (b - a) / np.linalg.norm(b - a, axis=-1, keepdims=True)
    assert_allclose(np.cross(omega / abs(omega0), ab), 0.0, atol=1e-8)
    # the sign: omega0 > 0 means u (and θ on branch +1) increasing; u̇ is du/dt
    assert np.all(np.sign(np.diff(motion.phase)) == np.sign(omega0))
    assert_rate_is_derivative(motion.phase, motion.phase_rate, RATE_ATOL[method])
    # not trivially constant: u̇ varies along the cycle
    assert np.ptp(np.abs(motion.phase_rate)) > 0.05 * np.abs(motion.phase_rate).max()


# ----------------------------------------------------------------------------- same path

@pytest.mark.parametrize('kind', ['roll', 'oscillate'])
def test_dynamic_and_kinematic_modes_give_the_same_path(kind):
    body, _, _, dyn = model(OLOID)
    init = STATES[OLOID][kind]
    t_dyn = np.linspace(0.0, 3.0, 301)
    dynamic = simulate(dyn, t_dyn, tolerance=SOLVER_TOL, **init)
    kinematic = simulate(dyn, np.linspace(0.0, 3.0, 6001), mode='kinematic',
                         theta0=init['theta0'], omega0=4.0)
    u_kin = kinematic.phase
    assert u_kin[0] <= dynamic.phase.min() and dynamic.phase.max() <= u_kin[-1]
    # the kinematic motion's poses as a function of its own phase, read at the dynamic phases
    # (cubic spline on 6001 samples: measured ≤ 3.2e-12 of the size)
    for x_kin, x_dyn in zip(kinematic.positions(), dynamic.positions()):
        assert_allclose(CubicSpline(u_kin, x_kin)(dynamic.phase), x_dyn, rtol=0,
                        atol=1e-11 * body.size)
    # the trace of A against an independent integration of the paper's eqs. (4)-(6), at the
    # reference settings of test_cycle: measured ≤ 2.7e-13 of the size, heading ≤ 3.5e-13 rad
    trace = integrate_contact_trace(body, u_kin[-1], rtol=1e-13, atol=1e-16 * body.size)
    alpha, x_a, y_a = trace.sol(dynamic.phase)
    a_dyn = dynamic.positions()[1]
    assert_allclose(a_dyn[:, 0], x_a, rtol=0, atol=2e-12 * body.size)
    assert_allclose(a_dyn[:, 1], y_a, rtol=0, atol=2e-12 * body.size)
    assert_allclose(dynamic.states().heading, alpha, rtol=0, atol=2e-12)


# ----------------------------------------------------------------------------- equilibria

UNSTABLE_POINTS = [
    pytest.param(OLOID, 0.0, 1, id='oloid-theta0'),
    pytest.param(OLOID, 0.0, -1, id='oloid-theta0-mirror'),
    pytest.param(OLOID, 'max', 1, id='oloid-turning+'),
    pytest.param(OLOID, '-max', -1, id='oloid-turning-'),
    pytest.param(FIGURE3, 0.0, 1, id='figure3-theta0'),
    pytest.param(FIGURE3, 'max', 1, id='figure3-turning+'),
    pytest.param(FAT, math.pi / 2, 1, id='fat-halfpi'),
    pytest.param(FAT, -math.pi / 2, -1, id='fat-halfpi-mirror'),
    pytest.param(LONG, 0.0, 1, id='long-theta0'),
    pytest.param(LONG, 0.0, -1, id='long-theta0-mirror'),
    pytest.param(THIN, 'max', 1, id='thin-turning+'),
]


def _theta(body, theta0):
    return {'max': body.theta_max, '-max': -body.theta_max}.get(theta0, theta0)


def _closed_form_height(abd, theta0):
    # physics notes: z_G(π/2) = b/√2 for every a, Δ; the turning points have z_G(0)
    return abd[1] / math.sqrt(2.0) if theta0 in (math.pi / 2, -math.pi / 2) else \
        height_theta0(*abd)


@pytest.mark.parametrize('method', ['table', 'direct'])
@pytest.mark.parametrize('abd, theta0, branch', UNSTABLE_POINTS)
def test_rest_at_unstable_equilibrium_stays_there(abd, theta0, branch, method):
    body, _, _, dyn = model(abd)
    theta = _theta(body, theta0)
    u0 = float(body.phase_from_theta(theta, branch))
    # it is an unstable equilibrium (closed-form criterion b² − 2a² + 2Δ², and equilibria())
    margin = body.stability_margin
    assert margin > 0 if theta0 in (math.pi / 2, -math.pi / 2) else margin < 0
    near = [e for e in equilibria(body)
            if abs(math.remainder(e.phase - u0, 2 * math.pi)) < 1e-6]
    assert len(near) == 1 and near[0].stability == UNSTABLE
    t = np.linspace(0.0, 6.0, 31)
    motion = simulate(dyn, t, theta0=theta, branch=branch, method=method)
    g = motion.positions()[0]
    assert_allclose(g, np.broadcast_to(g[0], g.shape), rtol=0, atol=1e-12 * body.size)
    assert_allclose(g[:, 2], _closed_form_height(abd, theta0), rtol=1e-12)
    assert_allclose(motion.phase_rate, 0.0, atol=1e-12)


def test_perturbed_unstable_equilibrium_moves_away():
    """The test above is not vacuous: 1e-6 rad off the equilibrium the body falls."""
    body, _, _, dyn = model(OLOID)
    t = np.linspace(0.0, 8.0, 81)
    for theta in (1e-6, body.theta_max - 1e-6):
        g = simulate(dyn, t, theta0=theta).positions()[0]
        assert np.max(np.abs(g - g[0])) > 1e-2 * body.size


@pytest.mark.parametrize('method', ['table', pytest.param('direct', marks=pytest.mark.slow)])
@pytest.mark.parametrize('sign', [1, -1])
def test_start_at_turning_point_moves_on(sign, method):
    """θ0 = ±θ_max with ω0 ≠ 0: the body rolls through the turning point, θ turns back."""
    body, cycle, mass, dyn = model(OLOID)
    omega0 = -2.0 * sign      # into the cycle: θ decreases from +θ_max, increases from -θ_max
    _, t = stencil_times(0.6, 12)
    motion = simulate(dyn, t, theta0=sign * body.theta_max, branch=1, omega0=omega0,
                      method=method, tolerance=SOLVER_TOL)
    theta = motion.states().theta
    assert abs(theta[0] - sign * body.theta_max) < 1e-12
    assert np.all(sign * np.diff(theta) < 0)               # moves away from ±θ_max
    assert sign * theta[-1] < body.theta_max - 0.1
    # the initial angular speed is |omega0| (from the poses) and the energy is conserved
    _, _, _, _, omega, _ = rates_in_time(motion)
    assert_allclose(np.linalg.norm(omega[0]), abs(omega0), rtol=1e-5)   # 1.6e-6 after 2 ms
    energy = energy_from_poses(motion, mass, GRAVITY)
    assert np.ptp(energy) / (MASS * GRAVITY * body.size) < ENERGY_FD_MAX[method]
    # the other way (omega0 > 0 at +θ_max): u goes on past π/2, the branch flips
    motion = simulate(dyn, np.linspace(0.0, 0.5, 11), theta0=sign * body.theta_max,
                      omega0=-omega0, method=method, tolerance=SOLVER_TOL)
    state = motion.states()
    assert np.all(state.branch[1:] == -1)
    assert np.all(sign * np.diff(state.theta) < 0)


def test_omega0_sign_convention():
    """omega0 > 0: θ increases on branch +1, decreases on branch -1 (both modes)."""
    _, _, _, dyn = model(OLOID)
    t = np.linspace(0.0, 0.2, 5)
    for mode in ('dynamic', 'kinematic'):
        for branch in (1, -1):
            theta = simulate(dyn, t, mode=mode, theta0=0.2, branch=branch,
                             omega0=1.0).states().theta
            assert np.all(branch * np.diff(theta) > 0)


# ----------------------------------------------------------------------------- small oscillations

def simulated_period(dyn, theta0, periods, method='table', tolerance=1e-12, n=800):
    """Period (s) from the zero crossings of u̇ (start at rest: u̇ = 0 at t = 0)."""
    t = np.linspace(0.0, 1.05 * periods, n)
    motion = simulate(dyn, t, theta0=theta0, omega0=0.0, method=method, tolerance=tolerance)
    roots = crossing_times(t, motion.phase_rate)
    return roots[1]            # u̇ = 0 at 0, T/2, T


@pytest.mark.parametrize('abd', [OLOID, FIGURE3], ids=['oloid', 'figure3'])
def test_small_oscillation_period(abd):
    body, cycle, mass, dyn = model(abd)
    # θ = π/2 is stable for these bodies (closed form b² − 2a² + 2Δ² < 0, and equilibria())
    assert body.stability_margin < 0
    u_eq = float(body.phase_from_theta(math.pi / 2))
    stable = [e for e in equilibria(body) if e.stability == STABLE]
    assert any(abs(e.phase - u_eq) < 1e-12 and abs(e.theta - math.pi / 2) < 1e-12
               for e in stable)
    periods = dyn.small_oscillation_periods()
    assert len(periods) == 4            # θ = ±π/2 on both branches, all equivalent
    reported = [p for e, p in periods if abs(e.phase - u_eq) < 1e-12][0]
    assert_allclose([p for _, p in periods], reported, rtol=5e-14)   # measured 1.5e-14

    # from scratch: T = 2π √(m / k), m from the poses (measured 2.1e-12 from the closed form),
    # k = M g d²z_G/du² from the paper's curvature: measured 2.3e-15 apart
    m = float(effective_mass_from_poses(cycle, mass, u_eq))
    k = MASS * GRAVITY * height_curvature_half_pi(abd, u_eq)
    own = 2 * math.pi * math.sqrt(m / k)
    assert_allclose(reported, own, rtol=PERIOD_RTOL)

    # simulated: the deviation T(ε) − T0 is anharmonic, ∝ ε², positive and monotone
    eps = np.array([0.005, 0.01, 0.02, 0.04])
    up = np.array([simulated_period(dyn, math.pi / 2 + e, own) for e in eps])
    down = np.array([simulated_period(dyn, math.pi / 2 - e, own) for e in eps[:2]])
    deviation = up / own - 1
    assert np.all(deviation > 0) and np.all(np.diff(deviation) > 0)
    assert abs(deviation[0]) < 2e-5
    assert_allclose(deviation[1:] / deviation[:-1], 4.0, rtol=0.05)   # measured 4.01-4.09
    # symmetric in ±ε to O(ε³); Richardson on the even part removes the ε² term, leaving
    # O(ε⁴) ≈ 1e-9 (measured ≤ 2.4e-9 from both references)
    even = 0.5 * (up[:2] + down)
    extrapolated = (4 * even[0] - even[1]) / 3
    assert_allclose(extrapolated, own, rtol=1e-8)
    assert_allclose(extrapolated, reported, rtol=1e-8)


def test_equilibria_with_periods():
    """All eight equilibria; a period exactly at the stable ones, equal to the one from scratch."""
    body, cycle, mass, dyn = model(FIGURE3)
    entries = dyn.equilibria_with_periods()
    assert len(entries) == 8
    for eq, period in entries:
        if eq.stability != STABLE:
            assert period is None
            continue
        assert abs(abs(eq.theta) - math.pi / 2) < 1e-14      # s < 0: θ = ±π/2 is stable
        m = float(effective_mass_from_poses(cycle, mass, eq.phase))
        k = MASS * GRAVITY * height_curvature_half_pi(FIGURE3, eq.phase)
        assert_allclose(period, 2 * math.pi * math.sqrt(m / k), rtol=PERIOD_RTOL)
    assert sum(period is not None for _, period in entries) == 4
    no_gravity = model(FIGURE3, gravity=0.0)[3].equilibria_with_periods()
    assert len(no_gravity) == 8 and all(period is None for _, period in no_gravity)


@pytest.mark.slow
def test_small_oscillation_period_direct():
    """The direct method measures the same period as the table method (second method)."""
    _, _, _, dyn = model(FIGURE3)
    period = dyn.small_oscillation_periods()[0][1]
    theta0 = math.pi / 2 + 0.02
    direct = simulated_period(dyn, theta0, period, method='direct', tolerance=1e-10, n=300)
    table = simulated_period(dyn, theta0, period, method='table', tolerance=1e-12, n=300)
    assert_allclose(direct, table, rtol=1e-8)
    assert_allclose(direct, period, rtol=2e-4)      # anharmonic shift 6.4e-5 at ε = 0.02


def test_small_oscillation_period_scaling():
    """T ∝ √(L / g), independent of M: halve the size, quadruple g → T / 4."""
    _, _, _, dyn = model(OLOID)
    reference = dyn.small_oscillation_periods()[0][1]
    small = (0.25, 0.25, 0.125)
    body = EllipseBody(*small)
    scaled = RollingDynamics(body, laminae(*small, 7.0), gravity=4 * GRAVITY)
    periods = [p for _, p in scaled.small_oscillation_periods()]
    # docs/physics.md: periods × √(g/a) equal the unit body's to ≤ 3e-13; measured 1.5e-14
    assert_allclose(periods, reference * math.sqrt(0.25 / 4), rtol=1e-13)
    measured = simulated_period(scaled, math.pi / 2 + 0.005, periods[0])
    assert_allclose(measured, periods[0], rtol=2e-5)


# ----------------------------------------------------------------------------- methods agree

@pytest.mark.slow
@pytest.mark.parametrize('mode, kind', [('dynamic', 'roll'), ('dynamic', 'oscillate'),
                                        ('kinematic', 'roll')])
@pytest.mark.parametrize('abd', [OLOID, FIGURE3], ids=['oloid', 'figure3'])
def test_methods_agree(abd, mode, kind):
    # the runs (and spans) of test_energy_is_conserved (dynamic: 1 s of rolling over, 2.5 s
    # of oscillation) and test_kinematic_mode_holds_angular_speed (4 s), computed once
    body = model(abd)[0]
    if mode == 'kinematic':
        span, init = KINEMATIC_SPAN, dict(theta0=0.4, omega0=2.5)
    else:
        span, init = (SPANS['direct', kind], 30), STATES[abd][kind]
    table = stencil_run(abd, *span, 'table', mode=mode, **init)
    direct = stencil_run(abd, *span, 'direct', mode=mode, **init)
    assert np.ptp(table.phase) > 0.3
    for x_table, x_direct in zip(table.positions(), direct.positions()):
        assert_allclose(x_direct, x_table, rtol=0, atol=AGREEMENT_MAX * body.size)


# ----------------------------------------------------------------------------- constant height

@pytest.mark.parametrize('method, t_end', [('table', 4.0), ('direct', 1.0)])
def test_two_circle_roller_keeps_kinetic_energy(method, t_end):
    """z_G is constant, so ½ m(u) u̇² is: √m(u)·|u̇| = const (m built from the poses)."""
    body, cycle, mass, dyn = model(TCR)
    t = np.linspace(0.0, t_end, 81)
    motion = simulate(dyn, t, omega0=1.5, theta0=0.2, method=method, tolerance=SOLVER_TOL)
    g = motion.positions()[0]
    # notes: z_G = b/√2, to the tables' rounding (16 ulps of the size)
    assert_allclose(g[:, 2], 1 / math.sqrt(2.0), rtol=0, atol=ulps(16, body.size))
    m = effective_mass_from_poses(cycle, mass, motion.phase)
    invariant = np.sqrt(m) * np.abs(motion.phase_rate)
    # measured 1.8e-12 (table; m from differences of the poses), 3.9e-11 (direct, which
    # follows SOLVER_TOL)
    assert_allclose(invariant, invariant[0], rtol={'table': 1e-11, 'direct': 2e-10}[method])
    # not the kinematic motion: u̇ and m vary along the path
    assert np.ptp(m) > 0.05 * m.max()
    assert np.ptp(motion.phase_rate) > 0.02 * motion.phase_rate.max()


def test_zero_gravity_keeps_kinetic_energy():
    body, cycle, mass, dyn = model(OLOID, gravity=0.0)
    t = np.linspace(0.0, 4.0, 81)
    motion = simulate(dyn, t, omega0=-0.7, theta0=1.0)
    m = effective_mass_from_poses(cycle, mass, motion.phase)
    invariant = np.sqrt(m) * np.abs(motion.phase_rate)
    assert_allclose(invariant, invariant[0], rtol=1e-11)      # measured 3.5e-12
    assert np.ptp(m) > 0.05 * m.max() and motion.phase[-1] < motion.phase[0] - 1.0
    rest = simulate(dyn, t, theta0=1.0)          # no gravity, no speed: rest anywhere
    assert np.all(rest.phase == rest.phase[0])


# ----------------------------------------------------------------------------- input errors

BAD_INPUTS = [
    (dict(mode='Dynamic'), 'mode', 'dynamic'),
    (dict(mode=None), 'mode', 'kinematic'),
    (dict(method='DIRECT'), 'method', 'direct'),
    (dict(method='rk45'), 'method', 'table'),
    (dict(tolerance=0.0), 'tolerance', '(0, 1)'),
    (dict(tolerance=1.0), 'tolerance', '(0, 1)'),
    (dict(tolerance=-1e-6), 'tolerance', '(0, 1)'),
    (dict(tolerance=math.nan), 'tolerance', '(0, 1)'),
    (dict(t_eval=[]), 't_eval', 'increasing'),
    (dict(t_eval=[[0.0, 1.0]]), 't_eval', '1-d'),
    (dict(t_eval=[-0.1, 1.0]), 't_eval', '>= 0'),
    (dict(t_eval=[0.0, 2.0, 1.0]), 't_eval', 'increasing'),
    (dict(omega0=math.inf), 'omega0', 'finite'),
    (dict(omega0=-math.inf, mode='kinematic'), 'omega0', 'finite'),
    (dict(omega0=math.nan), 'omega0', 'finite'),
]


def _one_line_error(kwargs, name, allowed):
    _, _, _, dyn = model(OLOID)
    args = dict(t_eval=[0.0, 0.5], omega0=1.0)
    args.update(kwargs)
    t_eval = args.pop('t_eval')
    with pytest.raises(ValueError) as info:
        simulate(dyn, t_eval, **args)
    message = str(info.value)
    assert '\n' not in message and message.startswith(name)
    assert allowed in message


@pytest.mark.parametrize('kwargs, name, allowed', BAD_INPUTS)
def test_input_errors(kwargs, name, allowed):
    _one_line_error(kwargs, name, allowed)


@pytest.mark.filterwarnings('ignore::RuntimeWarning')
@pytest.mark.parametrize('kwargs, name, allowed', [
    pytest.param(dict(t_eval=[0.0, math.nan, 1.0], method='direct'), 't_eval', 'finite',
                 id='nan-direct'),
    pytest.param(dict(t_eval=[0.0, math.nan, 1.0]), 't_eval', 'finite', id='nan-table'),
    pytest.param(dict(t_eval=[0.0, math.inf]), 't_eval', 'finite', id='inf-table'),
    pytest.param(dict(t_eval=[0.0, 1.0, 1.0]), 't_eval', 'strictly increasing',
                 id='repeated-time'),
    pytest.param(dict(tolerance='abc'), 'tolerance', '(0, 1)', id='tolerance-str'),
    pytest.param(dict(omega0='fast'), 'omega0', 'finite', id='omega0-str'),
    pytest.param(dict(theta0=3.0), 'theta0', 'theta_max', id='theta0-range'),
])
def test_input_errors_non_finite_and_non_numeric(kwargs, name, allowed):
    _one_line_error(kwargs, name, allowed)


# ----------------------------------------------------------------------------- the node's stream

@pytest.mark.parametrize('mode, method, u_dot0', [
    ('dynamic', 'table', 0.0), ('kinematic', 'direct', -1.5), ('kinematic', 'table', 1.5),
    pytest.param('dynamic', 'direct', 0.0, marks=pytest.mark.slow)])
def test_motion_stream_continues_across_chunks(mode, method, u_dot0):
    """MotionStream restarts the solver every ``chunk`` s: nothing may jump at the seams."""
    body, cycle, mass, dyn = model(OLOID)
    chunk = 1.0
    u0 = float(body.phase_from_theta(1.2))
    centres = np.sort(np.concatenate([np.arange(1, 4) * chunk, np.linspace(0.13, 3.93, 9)]))
    t = (centres[:, None] + FD_STEP_T * STENCIL).ravel()
    assert np.all(np.diff(t) > 0)
    stream = MotionStream(dyn, u0, u_dot0, mode=mode, method=method, tolerance=SOLVER_TOL,
                          chunk=chunk)
    pieces = [stream.sample(part) for part in np.array_split(t, 7)]
    u = np.concatenate([p[0] for p in pieces])
    u_dot = np.concatenate([p[1] for p in pieces])
    r0, _, _, _, omega, _ = rates_in_time(cycle.state(u))
    # u̇ is the time derivative of u, also at the seams
    assert_rate_is_derivative(u, u_dot, RATE_ATOL[method])
    if mode == 'dynamic':
        energy = energy_from_poses(cycle.state(u), mass, GRAVITY)
        assert np.ptp(energy) / (MASS * GRAVITY * body.size) < ENERGY_FD_MAX[method]
        # measured 0 here: V from the dynamics' table against the cycle's z_G, each rounded
        # (16 ulps of M g L)
        assert_allclose(stream.initial_energy, MASS * GRAVITY * cycle.positions(u0)[0][2],
                        rtol=0, atol=ulps(16, MASS * GRAVITY * body.size))
        assert u_dot.min() < -0.1           # it really falls back from θ = 1.2
    else:
        # held angular speed |u̇0|·|ω_u(u0)|, ω_u from the poses
        speed = abs(u_dot0) * np.linalg.norm(omega_per_phase(cycle, u0))
        assert_allclose(np.linalg.norm(omega, axis=-1), speed, rtol=SPEED_RTOL[method])
        assert np.all(np.sign(np.diff(u)) == np.sign(u_dot0))
    # and it follows one integration over the whole span: measured ≤ 2.2e-16 rad (table: the
    # closed form does not restart), ≤ 3.5e-11 rad (direct: DOP853 restarted at SOLVER_TOL)
    # (table: the same closed form evaluated at the same t, to 16 ulps of |u|)
    whole = simulate_phase(dyn, t, u0, u_dot0, mode=mode, method=method, tolerance=SOLVER_TOL)
    rounding = ulps(16, np.max(np.abs(whole.phase)))
    assert_allclose(u, whole.phase, rtol=0, atol={'table': rounding, 'direct': 2e-10}[method])


# ----------------------------------------------------------------------------- extreme body

EXTREME = (1.0, 0.05, 0.02)   # the benchmark's extreme body: |ω_u| varies ~100× over a cycle


GAUSS_NODES, GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(20)


def elapsed_time(inverse_speed, u, panel):
    """t(u_k) − t(u_0) = ∫ du / |u̇| between the phases u_k (s), u monotone.

    Gauss–Legendre with 20 nodes on panels at most ``panel`` (rad) wide, vectorised: the
    integrand is analytic, so a panel of a fifth of the sharpest feature's width leaves
    ~1e-16 s (measured: halving the panels changes the result by ≤ 4.4e-16 s).
    """
    lo, hi = u[:-1], u[1:]
    counts = np.maximum(1, np.ceil(np.abs(hi - lo) / panel).astype(int))
    segment = np.repeat(np.arange(lo.size), counts)
    index = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    width = (hi - lo)[segment] / counts[segment]
    x = (lo[segment] + index * width)[:, None] + 0.5 * width[:, None] * (GAUSS_NODES + 1.0)
    values = inverse_speed(x.ravel()).reshape(x.shape) @ GAUSS_WEIGHTS * 0.5 * np.abs(width)
    return np.concatenate([[0.0], np.cumsum(np.bincount(segment, values, minlength=lo.size))])


@pytest.mark.parametrize('mode, omega0', [('kinematic', 3.0), ('kinematic', -3.0),
                                          ('dynamic', 30.0)])
def test_extreme_body_table_matches_quadrature(mode, omega0):
    """The table's t(u) inversion stays on the right cycle where |u̇| varies sharply.

    Reference: the time to reach each sampled phase, integrated here from the closed forms
    (1/|u̇| = |ω_u|/Ω kinematic, √(m / 2(E − V)) dynamic, E from the initial state).
    Regression: plain Newton from a linear guess diverged here (errors ~1e14 of the size).
    """
    body, cycle, _, dyn = model(EXTREME)
    t = np.linspace(0.0, 0.6, 121)          # 0.3 to 5 cycles
    table = simulate(dyn, t, mode=mode, omega0=omega0, theta0=0.1, method='table')
    u, rate = table.phase, table.phase_rate
    assert np.all(np.isfinite(u)) and np.all(np.isfinite(rate))
    assert np.all(np.diff(u) * np.sign(omega0) > 0)   # one direction, no jumps
    if mode == 'kinematic':
        speed = abs(rate[0]) * float(dyn.angular_speed_per_phase(u[0]))

        def inverse_speed(x):
            return dyn.angular_speed_per_phase(x) / speed
    else:
        energy = 0.5 * float(dyn.effective_mass(u[0])) * rate[0] ** 2 + float(dyn.potential(u[0]))

        def inverse_speed(x):
            return np.sqrt(dyn.effective_mass(x) / (2 * (energy - dyn.potential(x))))
    feature = min(1.0, body.b / body.a, body.a / body.b, 2 * math.sqrt(body.delta / body.a))
    reference = elapsed_time(inverse_speed, u, 0.2 * feature)
    # docs/physics.md (Motion): table pose errors ≤ 1.1e-11 L. Measured: time 5.7e-14 of the
    # span and G 4e-14 L (kinematic), 1.0e-12 and 8.1e-12 L (dynamic, 5.2 cycles).
    time_rtol, size_rtol = (3e-13, 3e-13) if mode == 'kinematic' else (3e-12, 3e-11)
    assert_allclose(reference, t, rtol=0, atol=time_rtol * t[-1])
    g_reference = cycle.positions(u - rate * (t - reference))[0]   # u at the exact times
    assert_allclose(table.positions()[0], g_reference, rtol=0, atol=size_rtol * body.size)


@pytest.fixture(scope='module')
def oloid_model():
    return model(OLOID)


@pytest.mark.parametrize('mode, omega0', [('dynamic', 8.0), ('kinematic', -6.0)])
def test_table_of_inverse_time_matches_newton(oloid_model, monkeypatch, mode, omega0):
    """u(t) of the quadrature path from its table of x(τ) (a call of more samples than the
    table has nodes) against Newton on t(u) (a second method: the table refused,
    INVERSE_TOLERANCE < 0) over 20 s (~20 cycles): the same phases to the table's claim,
    1e-13 rad, plus 16 ulps of |u| (u is u0 + s (x + 2πk), rounded to its own ulp; measured
    ≤ 2.8e-14 rad), the same u̇ (measured ≤ 5.2e-14 rad/s). Small calls (a node's blocks)
    take Newton: the same code on the same data as the refused table's, so the same bits."""
    _, _, _, dyn = oloid_model
    t = np.linspace(0.0, 20.0, 20001)
    table = simulate(dyn, t, mode=mode, omega0=omega0, method='table')
    assert table.solver == 'quadrature' and table.sol._inverse is not None
    small = table.sol(t[5000:5100])
    monkeypatch.setattr(QuadratureSolution, 'INVERSE_TOLERANCE', -1.0)
    newton = simulate(dyn, t, mode=mode, omega0=omega0, method='table')
    assert newton.sol._inverse is None
    bound = 1e-13 + ulps(16, np.max(np.abs(newton.phase)))
    assert_allclose(table.phase, newton.phase, rtol=0, atol=bound)
    # u̇ = ±1/τ′(x) at those phases: the slope of τ, ~10 rad/s, times the phase bound
    assert_allclose(table.phase_rate, newton.phase_rate, rtol=0, atol=100 * bound)
    np.testing.assert_array_equal(small, newton.sol(t[5000:5100]))

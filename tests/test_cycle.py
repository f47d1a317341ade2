"""Tests of :mod:`twodisk_ros.physics.bodies.cycle`: whole rolling cycles in the world frame.

World frame (m): Z up, the ground is Z = 0; ``state.rotation`` maps body → world.
References never come from the code under test:

* rolling without slipping is checked on the poses alone: Ω = Ṙ Rᵀ and Ġ by 5-point
  differences of ``state(u)``, then v_P = Ġ + ω × (P − G) at A and at B;
* the body lies on the ground: both ellipses sampled in the body frame and mapped by R, G;
* the oloid (a = b = 1, Δ = ½) has an elementary trace (Dirnböck & Stachel 1997, the paper's
  refs. [4, 5]), derived here: with sin w = (2/√3) sin(θ/2) on the first half-cycle,
  α = 2w − arctan(tan(w)/2), X_A = 4√3 (w/18 + sin(2w)/12 + arctan(tan(w)/2)/18),
  Y_A = 2√3 ((1 − cos²w)/3 + ln(4/(1 + 3cos²w))/18); one cycle moves it by 8√3π/9 = 4.83680;
* the heading turns by exactly 2π per cycle for every shape (Gauss–Bonnet: the convex hull
  is developable except along the two rolling arcs, which carry its total curvature 4π, half
  each by the disk-swap symmetry; A rolls over both sides of arc 1 once per cycle);
* no slip means the trace of A is as long as the arc of disk 1 it rolls over (twice the arc
  between ±θ_max, from the paper's eq. (1) by quad), likewise for B on disk 2;
* composition over N cycles by an explicit loop, and the direct DOP853 integration of the
  paper's eqs. (4)-(6) (``integrate_contact_trace``) as a second method.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import quad
from scipy.optimize import brentq

from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.cycle import RollingCycle, integrate_contact_trace

TWO_PI = 2 * math.pi
SQRT2, SQRT3 = math.sqrt(2.0), math.sqrt(3.0)

# -- tolerances --------------------------------------------------------------------------------
#: 5-point differences of the poses with step FD_STEP in u. Measured: |v_A|, |v_B| and the
#: error of ω ≤ 1e-10 of |ω|max·size over the hypothesis range (b/a ∈ [0.05, 20],
#: Δ/a ∈ [0.01, 0.99]; ≤ 3e-11 for the named bodies). h = 1e-3 leaves truncation up to 3e-5 at
#: the extremes, h = 1e-5 round-off ~1e-10; 1e-4 balances both.
FD_STEP = 1e-4
NO_SLIP_RTOL = 1e-8
#: Extreme shapes (b/a ∈ {0.01, 100}, Δ/a ∈ {1e-3, 1 − 1e-6}): features of width ~1e-3 in u
#: make the same differences truncation-limited, measured ≤ 1e-7.
EXTREME_NO_SLIP_RTOL = 1e-6
#: Lowest point of the body relative to its size: measured ≥ −4.7e-16 over the named, extreme
#: and 40 random shapes of the hypothesis range (1500 samples per rim); a rim point's height
#: is a sum of rounded products of the size: 16 ulps.
GROUND_RTOL = ulps(16)
#: R is a rotation: RᵀR = 1 and det R = 1, measured ≤ 1.3e-15.
ROTATION_ATOL = 5e-15
#: A and B, mapped back to the body frame by R, lie on their ellipses (relative to size).
#: Positions come from the cycle tables, R from the closed forms. Measured over 3 cycles:
#: ≤ 2.7e-14 (named and 40 random shapes), ≤ 1.5e-13 at the extremes ((1, 0.01, 1e-3)).
MATERIAL_RTOL = {'regular': 1e-13, 'extreme': 5e-13}
#: Constant height of G for the neutral bodies (TCR, Figure 4), relative to the size:
#: measured ≤ 4.4e-16 m; the tables' rounding, 16 ulps of the size.
NEUTRAL_HEIGHT_RTOL = ulps(16)
#: Composition over N ≤ 50 cycles against an explicit loop, relative to size and per cycle:
#: measured ≤ 2.4e-14 (rounding of the loop and of the closed-form power; docs/physics.md).
COMPOSE_RTOL = 1e-13
#: Direct DOP853 integration over 1.25 cycles (one wrap past u = 2π; composition over many
#: cycles: test_multi_cycle_composition), relative to size. The reference runs at
#: rtol 1e-13, atol 1e-16·size; its own error grows with the distance travelled (heading error
#: × length): over 5 cycles it reached 3.4e-9 for (1, 15.6, 0.5), where the tables' turn is 2π
#: to 3e-15. Measured over 1.25 cycles on 69 shapes (named, near-extremes, 60 random of the
#: hypothesis range): ≤ 8.9e-12 of the size, heading ≤ 9.7e-12 rad, the reference's level
#: (docs/physics.md: poses against the benchmarks' reference 1.3e-12 to 1.4e-11).
INTEGRATION_OPTIONS = {'rtol': 1e-13, 'atol': 1e-16}
INTEGRATION_RTOL = 5e-11
#: Trace lengths: polyline with Richardson extrapolation (2^15 and 2^16 segments per cycle)
#: against quad of eq. (1): measured ≤ 1.6e-15 (the plain 2^16 polyline is short by ~1e-9).
LENGTH_RTOL = 5e-15
#: Elementary oloid trace against the tabulated one, m: measured ≤ 3e-15.
OLOID_ATOL = 1.5e-14
#: Turn per cycle against 2π (Gauss–Bonnet), rad. docs/physics.md: ≤ 1e-14 for the named
#: bodies (measured 0 for b/a near 1, 2e-14 for (1, 0.05, 0.01)), ≤ 1.4e-14 over the hypothesis
#: range (200 random shapes), ≤ 5e-14 at the extremes (measured 4.7e-14 at (1, 0.01, 1 − 1e-6)).
#: For the named bodies that is rounding: the turn is a quadrature's sum of rounded terms,
#: 16 ulps of 2π (2.2e-14).
TURN_ATOL = {'named': ulps(16, TWO_PI), 'range': 5e-14, 'extreme': 1.5e-13}
#: u → −u mirrors the trace in the Y axis: measured ≤ 2.2e-14 of the size (trace) and
#: ≤ 1.3e-14 rad (heading) over 100 random shapes; Im S ≤ 8e-15 of the size over 200.
MIRROR_ATOL = 1e-13
#: Heights at the equilibria of the extreme shapes, relative: measured ≤ 1.5e-13.
EXTREME_HEIGHT_RTOL = 5e-13

SHAPES = st.tuples(st.floats(0.1, 10.0), st.floats(math.log(0.05), math.log(20.0)),
                   st.floats(0.01, 0.99))
NAMED = {
    'oloid': (1.0, 1.0, 0.5),
    'tcr': (1.0, 1.0, 1.0 / SQRT2),
    'figure3': (2.0, 1.0, 1.0),
    'figure4': (math.sqrt(1.5), 1.0, 1.0),
    'thin': (1.0, 0.05, 0.01),
    'tall': (1.0, 20.0, 0.99),
    'wide': (0.8, 2.0, 0.3),
}
EXTREMES = [(1.0, ba, da) for ba in (0.01, 100.0) for da in (1e-3, 1.0 - 1e-6)]

_CYCLES = {}


def _cycle(shape):
    """RollingCycle of a shape, built once per session (tables take up to ~1.5 s)."""
    if shape not in _CYCLES:
        _CYCLES[shape] = RollingCycle(EllipseBody(*shape))
    return _CYCLES[shape]


def _shape(drawn):
    scale, log_ba, da = drawn
    return scale, scale * math.exp(log_ba), scale * da


def _phases(cycles=3, count=600):
    """Phases over ``cycles`` whole cycles from u = −π, with every turning point and θ = 0."""
    u = np.linspace(-math.pi, -math.pi + TWO_PI * cycles, count)
    special = np.arange(-1, 2 * cycles) * math.pi / 2
    return np.sort(np.concatenate([u, special]))


def _size(a, b, delta):
    return max(a, b) + delta


def _theta_max(a, b, delta):
    """Root of Q(θ) on (π/2, π) (paper, after eq. (2))."""
    def q(t):
        s, c = math.sin(t), math.cos(t)
        return (a**4 * s * s + 4 * a * b * delta * c * math.hypot(a * s, b * c)
                + 4 * b * b * delta * delta * c * c)
    return brentq(q, math.pi / 2, math.pi, xtol=1e-16, rtol=8.9e-16)


def _arc(a, b, limit):
    """Arc of the boundary between polar angles ±limit from the paper's eq. (1) (m)."""
    def rate(t):
        s, c = math.sin(t), math.cos(t)
        polar2 = a * a * s * s + b * b * c * c
        return a * b * math.sqrt(a**4 * s * s + b**4 * c * c) / polar2**1.5
    # the integrand peaks sharply for thin shapes: split at the axes
    points = sorted({0.0, math.pi / 2, -math.pi / 2, limit, -limit})
    points = [p for p in points if -limit <= p <= limit]
    return sum(quad(rate, lo, hi, epsabs=0, epsrel=1e-13, limit=500)[0]
               for lo, hi in zip(points[:-1], points[1:]))


def _arc_disk2(a, b, delta, limit):
    """Arc of disk 2 between ψ = ±limit from |dr2/dψ| of the paper's parametrisation (m)."""
    def rate(p):
        s, c = math.sin(p), math.cos(p)
        d2 = a * a * s * s + b * b * c * c
        rho = a * b / math.sqrt(d2)
        drho = -a * b * (a * a - b * b) * s * c / d2**1.5
        return math.hypot(drho * c - rho * s, drho * s + rho * c)
    points = [p for p in sorted({0.0, math.pi / 2, -math.pi / 2, limit, -limit})
              if -limit <= p <= limit]
    return sum(quad(rate, lo, hi, epsabs=0, epsrel=1e-13, limit=500)[0]
               for lo, hi in zip(points[:-1], points[1:]))


def _ellipse_points(a, b, delta, count=1500):
    """Boundary points of both disks in the body frame (m), shape (2·count, 3)."""
    eta = np.linspace(0, TWO_PI, count, endpoint=False)
    zero = np.zeros_like(eta)
    disk1 = np.stack([b * np.sin(eta), -delta - a * np.cos(eta), zero], axis=-1)
    disk2 = np.stack([zero, delta + a * np.cos(eta), b * np.sin(eta)], axis=-1)
    return np.concatenate([disk1, disk2])


def _axial(skew):
    return 0.5 * np.stack([skew[..., 2, 1] - skew[..., 1, 2], skew[..., 0, 2] - skew[..., 2, 0],
                           skew[..., 1, 0] - skew[..., 0, 1]], axis=-1)


def _pose_rates(cycle, u, h=FD_STEP, rotation=None):
    """World ω (rad per unit u) and Ġ (m per unit u) by 5-point differences of the poses
    (``rotation``: the rotations at u if already evaluated)."""
    states = [cycle.state(u + k * h) for k in (-2, -1, 1, 2)]
    weights = np.array([1.0, -8.0, 8.0, -1.0]) / (12 * h)
    r_dot = sum(w * s.rotation for w, s in zip(weights, states))
    g_dot = sum(w * s.position_g for w, s in zip(weights, states))
    rotation = cycle.state(u).rotation if rotation is None else rotation
    omega_skew = np.einsum('...ij,...kj->...ik', r_dot, rotation)
    return _axial(omega_skew), g_dot, omega_skew


# -- the whole cycle ---------------------------------------------------------------------------
def _check_whole_cycles(shape, no_slip_rtol, cycle=None, material_rtol=MATERIAL_RTOL['regular']):
    a, b, delta = shape
    cycle = cycle or _cycle(shape)
    body = cycle.body
    size = _size(*shape)
    u = _phases()
    state = cycle.state(u)
    for name in ('position_g', 'contact_a', 'contact_b', 'rotation', 'heading'):
        assert np.all(np.isfinite(getattr(state, name))), name
    # a rotation matrix body → world
    rot = state.rotation
    assert_allclose(np.einsum('...ji,...jk->...ik', rot, rot), np.broadcast_to(np.eye(3),
                    rot.shape), atol=ROTATION_ATOL)
    assert_allclose(np.linalg.det(rot), 1.0, atol=ROTATION_ATOL)
    # both contact points on the ground, nothing below it, G above it
    assert_allclose(state.contact_a[:, 2], 0.0, atol=1e-14 * size)
    assert_allclose(state.contact_b[:, 2], 0.0, atol=1e-14 * size)
    points = _ellipse_points(a, b, delta)
    # world heights only: the third row of each rotation against the points (one matmul;
    # the full 'nij,pj->npi' einsum built all three rows at ~0.3 s a shape)
    z = rot[:, 2, :] @ points.T + state.position_g[:, None, 2]
    assert z.min() >= -GROUND_RTOL * size
    assert np.all(state.position_g[:, 2] > 0)
    # the contact points are material points of the disks
    to_body = np.einsum('nji,nj->ni', rot, state.contact_b - state.position_g)
    assert_allclose(to_body[:, 0], 0.0, atol=material_rtol * size)
    assert_allclose(((to_body[:, 1] - delta) / a) ** 2 + (to_body[:, 2] / b) ** 2, 1.0,
                    atol=material_rtol * size / min(a, b))
    to_body = np.einsum('nji,nj->ni', rot, state.contact_a - state.position_g)
    assert_allclose(to_body[:, 2], 0.0, atol=material_rtol * size)
    assert_allclose((to_body[:, 0] / b) ** 2 + ((to_body[:, 1] + delta) / a) ** 2, 1.0,
                    atol=material_rtol * size / min(a, b))
    # no slip at A and B, ω along AB, and the code's ω
    omega, g_dot, skew = _pose_rates(cycle, u, rotation=rot)
    omega_body = body.phase_angular_velocity(u)
    scale = np.linalg.norm(omega_body, axis=-1).max()
    assert_allclose(skew + np.swapaxes(skew, -1, -2), 0.0, atol=no_slip_rtol * scale)
    v_a = g_dot + np.cross(omega, state.contact_a - state.position_g)
    v_b = g_dot + np.cross(omega, state.contact_b - state.position_g)
    assert_allclose(v_a, 0.0, atol=no_slip_rtol * scale * size)
    assert_allclose(v_b, 0.0, atol=no_slip_rtol * scale * size)
    ab = state.contact_b - state.contact_a
    ab_unit = ab / np.linalg.norm(ab, axis=-1, keepdims=True)
    assert_allclose(np.cross(omega, ab_unit), 0.0, atol=no_slip_rtol * scale)
    assert_allclose(np.einsum('nji,nj->ni', rot, omega), omega_body, rtol=0,
                    atol=no_slip_rtol * scale)
    assert_allclose(cycle.velocity_g(u), g_dot, rtol=0, atol=no_slip_rtol * scale * size)


@pytest.mark.parametrize('name', sorted(NAMED))
def test_whole_cycles_named(name):
    _check_whole_cycles(NAMED[name], NO_SLIP_RTOL)
    turn = _cycle(NAMED[name]).displacement.turn
    assert_allclose(turn, TWO_PI, rtol=0, atol=TURN_ATOL['named' if name != 'thin' else 'range'])


@settings(max_examples=12, deadline=None)
@given(SHAPES)
def test_whole_cycles_across_shapes(drawn):
    shape = _shape(drawn)
    _check_whole_cycles(shape, NO_SLIP_RTOL, RollingCycle(EllipseBody(*shape)))


@pytest.mark.parametrize('shape', EXTREMES)
def test_whole_cycles_extremes(shape):
    _check_whole_cycles(shape, EXTREME_NO_SLIP_RTOL, material_rtol=MATERIAL_RTOL['extreme'])
    a, b, delta = shape
    cycle = _cycle(shape)
    # heights at the equilibria, exactly at the turning points too: V(0) = V(θ_max), b/√2.
    v0 = b * (a + delta) / math.sqrt(b * b + 4 * a * delta + 4 * delta * delta)
    u = np.array([-math.pi / 2, 0.0, math.pi / 2, math.pi, 1.5 * math.pi])
    assert_allclose(cycle.state(u).position_g[:, 2], v0, rtol=EXTREME_HEIGHT_RTOL)
    u_half_pi = math.asin(math.pi / 2 / cycle.body.eta_max)
    assert_allclose(cycle.state(np.array([u_half_pi, math.pi - u_half_pi])).position_g[:, 2],
                    b / SQRT2, rtol=EXTREME_HEIGHT_RTOL)
    # Gauss–Bonnet: 2π per cycle
    assert_allclose(cycle.displacement.turn, TWO_PI, rtol=0, atol=TURN_ATOL['extreme'])
    assert math.isfinite(cycle.displacement.shift.real) and cycle.displacement.shift.real > 0


@pytest.mark.parametrize('name', ['oloid', 'figure3', 'thin', 'tall'])
def test_contact_points_stop_at_the_cusps(name):
    """A stops on the ground where θ turns back (u = ±π/2), B where ψ does (θ = 0)."""
    cycle = _cycle(NAMED[name])
    size = _size(*NAMED[name])
    h = 1e-4
    for u0, field in [(math.pi / 2, 'contact_a'), (-math.pi / 2, 'contact_a'),
                      (0.0, 'contact_b'), (math.pi, 'contact_b')]:
        p_minus = getattr(cycle.state(u0 - h), field)
        p_plus = getattr(cycle.state(u0 + h), field)
        p_0 = getattr(cycle.state(u0), field)
        # the speed vanishes linearly: the displacement over ±h is O(h²), not O(h)
        assert np.linalg.norm(p_plus - p_0) < 1e-6 * size
        assert np.linalg.norm(p_minus - p_0) < 1e-6 * size
        # and the point moves back the way it came (a cusp): both steps point the same way
        cosine = np.dot(p_plus - p_0, p_minus - p_0) / (
            np.linalg.norm(p_plus - p_0) * np.linalg.norm(p_minus - p_0))
        assert cosine > 0.99


# -- height of G -------------------------------------------------------------------------------
@pytest.mark.parametrize('name', ['tcr', 'figure4'])
def test_neutral_bodies_keep_g_at_constant_height(name):
    cycle = _cycle(NAMED[name])
    u = np.concatenate([np.linspace(-math.pi, 5 * math.pi, 3001),
                        np.arange(-2, 11) * math.pi / 2])
    height = cycle.state(u).position_g[:, 2]
    # b/√2 (= V(π/2) for every shape) with b = 1
    assert_allclose(height, 1 / SQRT2, rtol=0, atol=NEUTRAL_HEIGHT_RTOL * _size(*NAMED[name]))


def test_oloid_height_range():
    cycle = _cycle(NAMED['oloid'])
    u = np.linspace(0, TWO_PI, 20001)
    height = cycle.state(u).position_g[:, 2]
    rounding = ulps(16, _size(*NAMED['oloid']))      # the tables' rounding (m)
    assert height.min() >= 1 / SQRT2 - rounding
    assert height.max() <= 0.75 + rounding
    # dense grid: within its own resolution of the bounds (the bounds are quadratic extrema)
    assert height.min() - 1 / SQRT2 < 1e-6
    assert 0.75 - height.max() < 1e-12
    # at the equilibria exactly: θ = 0 and the turning points give 3/4, θ = ±π/2 give 1/√2
    u_half_pi = math.asin(math.pi / 2 / cycle.body.eta_max)
    top = cycle.state(np.array([0.0, math.pi / 2, math.pi, 1.5 * math.pi])).position_g[:, 2]
    bottom = cycle.state(np.array([u_half_pi, math.pi - u_half_pi, math.pi + u_half_pi,
                                   TWO_PI - u_half_pi])).position_g[:, 2]
    assert_allclose(top, 0.75, rtol=0, atol=rounding)
    assert_allclose(bottom, 1 / SQRT2, rtol=0, atol=rounding)


# -- the oloid in closed form ------------------------------------------------------------------
def _oloid_half_cycle(theta):
    """(α, X_A, Y_A) of the oloid on the first half-cycle, elementary (see module doc)."""
    w = np.arcsin(np.clip(2 / SQRT3 * np.sin(theta / 2), -1.0, 1.0))
    half_turn = np.arctan(np.tan(w) / 2)
    alpha = 2 * w - half_turn
    x = 4 * SQRT3 * (w / 18 + np.sin(2 * w) / 12 + half_turn / 18)
    c2 = np.cos(w) ** 2
    y = 2 * SQRT3 * ((1 - c2) / 3 + np.log(4 / (1 + 3 * c2)) / 18)
    return alpha, x, y


def test_oloid_trace_is_elementary():
    cycle = _cycle(NAMED['oloid'])
    # first half-cycle, u ∈ (−π/2, π/2): θ runs over (−2π/3, 2π/3)
    u = np.linspace(-math.pi / 2, math.pi / 2, 401)[1:-1]
    state = cycle.state(u)
    alpha, x, y = _oloid_half_cycle(state.theta)
    assert_allclose(state.heading, alpha, rtol=0, atol=OLOID_ATOL)
    assert_allclose(state.contact_a[:, 0], x, rtol=0, atol=OLOID_ATOL)
    assert_allclose(state.contact_a[:, 1], y, rtol=0, atol=OLOID_ATOL)
    # second half-cycle: A rolls back over the other side of disk 1,
    # α = π − α₊(θ) and A = 2 Re A₊(θ_max) − conj(A₊(θ))
    u = np.linspace(math.pi / 2, 1.5 * math.pi, 401)
    state = cycle.state(u)
    alpha, x, y = _oloid_half_cycle(state.theta)
    x_end = 4 * SQRT3 * math.pi / 18
    assert_allclose(state.heading, math.pi - alpha, rtol=0, atol=OLOID_ATOL)
    assert_allclose(state.contact_a[:, 0], 2 * x_end - x, rtol=0, atol=OLOID_ATOL)
    assert_allclose(state.contact_a[:, 1], y, rtol=0, atol=OLOID_ATOL)


def test_oloid_cycle_displacement():
    disp = _cycle(NAMED['oloid']).displacement
    assert_allclose(disp.turn, TWO_PI, rtol=0, atol=TURN_ATOL['named'])
    assert_allclose(abs(disp.shift), 4.8368, rtol=0, atol=5e-5)          # physics notes
    assert_allclose(disp.shift.real, 8 * SQRT3 * math.pi / 9, rtol=1e-14)  # closed form
    # measured 7.8e-16: the shift is a quadrature's sum, 16 ulps of |S|
    assert_allclose(disp.shift.imag, 0.0, atol=ulps(16, abs(disp.shift)))


# -- every shape: one cycle is a pure translation along X --------------------------------------
@settings(max_examples=15, deadline=None)
@given(SHAPES)
def test_cycle_turn_and_symmetry(drawn):
    shape = _shape(drawn)
    cycle = RollingCycle(EllipseBody(*shape))
    size = _size(*shape)
    # Gauss–Bonnet (module doc): the heading turns by 2π per cycle
    assert_allclose(cycle.displacement.turn, TWO_PI, rtol=0, atol=TURN_ATOL['range'])
    # u → −u mirrors the trace in the Y axis (α odd, ds/du even), hence a shift along X
    u = np.linspace(0, 2.5 * math.pi, 61)
    plus, minus = cycle.trace_a(u), cycle.trace_a(-u)
    assert_allclose(minus[:, 0], -plus[:, 0], rtol=0, atol=MIRROR_ATOL * size)
    assert_allclose(minus[:, 1], plus[:, 1], rtol=0, atol=MIRROR_ATOL * size)
    assert_allclose(cycle.heading(-u), -cycle.heading(u), rtol=0, atol=MIRROR_ATOL)
    assert_allclose(cycle.displacement.shift.imag, 0.0, atol=MIRROR_ATOL * size)
    assert cycle.displacement.shift.real > 0


# -- lengths of the traces (no slip, integrated) -----------------------------------------------
def _trace_lengths(cycle, n):
    """{field: polygon length} of the traces of A and B over one cycle on n + 1 phases."""
    state = cycle.state(np.linspace(0, TWO_PI, n + 1))
    return {field: np.linalg.norm(np.diff(getattr(state, field), axis=0), axis=-1).sum()
            for field in ('contact_a', 'contact_b')}


_LENGTHS = {}


def _richardson_length(cycle, field):
    """The Richardson-extrapolated length of a trace; both traces of a cycle from the same
    states (one evaluation of 2^15 + 1 and 2^16 + 1 poses a cycle, not one per trace)."""
    if id(cycle) not in _LENGTHS:
        _LENGTHS[id(cycle)] = (cycle, _trace_lengths(cycle, 2**15), _trace_lengths(cycle, 2**16))
    _, coarse, fine = _LENGTHS[id(cycle)]
    return fine[field] + (fine[field] - coarse[field]) / 3


@pytest.mark.parametrize('name', sorted(NAMED))
def test_trace_lengths_equal_rolled_arcs(name):
    a, b, delta = NAMED[name]
    cycle = _cycle(NAMED[name])
    theta_max = _theta_max(a, b, delta)
    arc1 = _arc(a, b, theta_max)
    arc2 = _arc_disk2(a, b, delta, theta_max)   # ψ_max = θ_max (same ellipse, same Q)
    assert_allclose(_richardson_length(cycle, 'contact_a'), 2 * arc1, rtol=LENGTH_RTOL)
    assert_allclose(_richardson_length(cycle, 'contact_b'), 2 * arc2, rtol=LENGTH_RTOL)


def test_oloid_trace_length():
    """Oloid: A rolls over 240° of a unit circle, forward and back: 8π/3."""
    cycle = _cycle(NAMED['oloid'])
    assert_allclose(_richardson_length(cycle, 'contact_a'), 8 * math.pi / 3, rtol=LENGTH_RTOL)
    assert_allclose(_richardson_length(cycle, 'contact_b'), 8 * math.pi / 3, rtol=LENGTH_RTOL)


# -- many cycles -------------------------------------------------------------------------------
def _compose(state_g, rotation, turn, shift, cycles):
    """Apply the planar displacement (rotation by ``turn`` about Z, then ``shift``) N times."""
    c, s = math.cos(turn), math.sin(turn)
    rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    offset = np.array([shift.real, shift.imag, 0.0])
    g, r = state_g.copy(), rotation.copy()
    for _ in range(cycles):
        g = rz @ g + offset
        r = rz @ r
    return g, r


@pytest.mark.parametrize('name', ['oloid', 'figure3', 'thin', 'tall'])
def test_multi_cycle_composition(name):
    cycle = _cycle(NAMED[name])
    size = _size(*NAMED[name])
    disp = cycle.displacement
    for u0 in (0.3, math.pi / 2, 2.0):
        start = cycle.state(u0)
        for n in (1, 2, 7, 50):
            later = cycle.state(u0 + TWO_PI * n)
            g, r = _compose(start.position_g, start.rotation, disp.turn, disp.shift, n)
            tol = COMPOSE_RTOL * size * n
            assert_allclose(later.position_g, g, rtol=0, atol=tol)
            assert_allclose(later.rotation, r, rtol=0, atol=COMPOSE_RTOL * n)
            a, _ = _compose(start.contact_a, start.rotation, disp.turn, disp.shift, n)
            b, _ = _compose(start.contact_b, start.rotation, disp.turn, disp.shift, n)
            assert_allclose(later.contact_a, a, rtol=0, atol=tol)
            assert_allclose(later.contact_b, b, rtol=0, atol=tol)
            assert_allclose(later.heading, start.heading + n * disp.turn, rtol=0,
                            atol=COMPOSE_RTOL * n)
        # and backwards
        earlier = cycle.state(u0 - TWO_PI * 3)
        g, _ = _compose(earlier.position_g, earlier.rotation, disp.turn, disp.shift, 3)
        assert_allclose(start.position_g, g, rtol=0, atol=COMPOSE_RTOL * size * 3)


def _check_direct_integration(shape, rtol, cycle=None):
    cycle = cycle or _cycle(shape)
    size = _size(*shape)
    u = np.linspace(0, 1.25 * TWO_PI, 76)
    result = integrate_contact_trace(cycle.body, u[-1], rtol=INTEGRATION_OPTIONS['rtol'],
                                     atol=INTEGRATION_OPTIONS['atol'] * size, u_eval=u)
    alpha, x, y = result.y
    trace = cycle.trace_a(u)
    assert_allclose(trace[:, 0], x, rtol=0, atol=rtol * size)
    assert_allclose(trace[:, 1], y, rtol=0, atol=rtol * size)
    assert_allclose(cycle.heading(u), alpha, rtol=0, atol=rtol)


@pytest.mark.parametrize('name', sorted(NAMED))
def test_direct_integration_named(name):
    _check_direct_integration(NAMED[name], INTEGRATION_RTOL)


@settings(max_examples=6, deadline=None)
@given(SHAPES)
def test_direct_integration_across_shapes(drawn):
    shape = _shape(drawn)
    _check_direct_integration(shape, INTEGRATION_RTOL, RollingCycle(EllipseBody(*shape)))


@pytest.mark.parametrize('shape', [(1.0, 1.0, 1e-3), (1.0, 0.01, 0.5)])
def test_direct_integration_near_extremes(shape):
    _check_direct_integration(shape, INTEGRATION_RTOL)


def test_rejects_non_body():
    with pytest.raises(TypeError):
        RollingCycle((1.0, 1.0, 0.5))

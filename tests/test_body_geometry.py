"""Tests of the closed forms in :mod:`twodisk_ros.physics.bodies.ellipse` against an independent construction.

Body frame ``G e1 e2 e3`` (m): disk 1 in ``x3 = 0`` centred at ``(0, -delta, 0)``, disk 2 in
``x1 = 0`` centred at ``(0, +delta, 0)``, semi-axis ``a`` along e2 and ``b`` across.

The reference (:class:`Reference`) is built here from the paper's parametric ellipse equations
only (section 2), without any of the paper's derived closed forms:

* ψ(θ) is the root of the triple product ``<r2 - r1, r1'_θ, r2'_ψ> = 0`` found by a sign scan
  and ``scipy.optimize.brentq`` on the half ``0 < ψ < π`` (branch +1) or ``-π < ψ < 0``
  (branch -1); exactly one root per half is required;
* the ground normal is ``n ∝ t1 × (r2 - r1)`` oriented so that G lies above the ground
  (``-r1·n > 0``), the height of G is ``-r1·n``;
* θ_max is the root of ``Q(θ) = 0`` on ``(π/2, π)`` (brentq);
* V′ and V″ are 5-point finite differences of that height, taken in the eccentric anomaly η
  of A (``tan θ = (b/a) tan η``, in which every shape is smooth) and converted to θ by the
  chain rule.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import quad
from scipy.optimize import brentq

from paper_forms import curvature_at_half_pi, curvature_at_theta0, height_at_theta0
from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody

# -- tolerances (all measured with the reference below; the margin is ~100x) ----------------
#: ψ (rad) and unit vectors, interior points |η| ≤ 0.99 η_max of the hypothesis range
#: b/a ∈ [0.05, 20], Δ/a ∈ [0.01, 0.99] (129 shapes): measured ≤ 3e-14 for ψ, ≤ 3e-13 for n
#: (worst for b/a → 0.05). The root of the triple product becomes a double root at the turning
#: points, hence the 0.99 (the turning points are checked with their own construction).
ANGLE_ATOL = 1e-11
#: positions and heights, relative to the body size: measured ≤ 2e-14.
LENGTH_RTOL = 1e-12
#: V′ by 5-point differences (step 3e-3 of the narrowest feature in η), relative to the
#: largest |V′| at the sampled points: measured ≤ 4e-9 (round-off and truncation balance).
SLOPE_RTOL = 1e-7
#: V″ likewise, relative to the largest |V″| at the sampled points: measured ≤ 3e-8.
CURVATURE_RTOL = 1e-6
#: Round-off floor of the differences (step h = 3e-3 w, w the feature width in η): about
#: eps·size/h for V′ and eps·size/h² for V″ (matters where V is constant, e.g. the TCR).
SLOPE_NOISE, CURVATURE_NOISE = 1e-12, 1e-10
#: Extreme shapes (b/a ∈ {0.01, 100}, Δ/a ∈ {1e-3, 1 − 1e-6}), |η| ≤ (1 − 1e-5) η_max: unit
#: vectors and ψ agree to ≤ 3e-12, lengths to ≤ 2e-13 relative (θ_max = atan2(...), see
#: test_theta_max_full_precision; with acos it was 2.5e-9 and 7e-11). ψ is ill-conditioned in
#: θ near a turning point (ψ ~ √(θ_max − θ)), hence the 1 − 1e-5.
EXTREME_ANGLE_ATOL = 1e-10
EXTREME_LENGTH_RTOL = 1e-11
#: V(θ_max) = V(0) at the extreme shapes, relative (was 1.6e-10 with θ_max from acos).
EXTREME_HEIGHT_RTOL = 1e-12

SQRT2 = math.sqrt(2.0)

# Shapes of the hypothesis range: a scale (m), b/a log-uniform in [0.05, 20], Δ/a in [0.01, 0.99].
SHAPES = st.tuples(st.floats(0.1, 10.0), st.floats(math.log(0.05), math.log(20.0)),
                   st.floats(0.01, 0.99))
NAMED = [(1.0, 1.0, 0.5), (1.0, 1.0, 1.0 / SQRT2), (2.0, 1.0, 1.0), (math.sqrt(1.5), 1.0, 1.0),
         (2.0, 0.5, 0.3), (3.0, 1.0, 2.5), (1.0, 0.2, 0.9), (5.0, 1.0, 0.01), (0.8, 2.0, 0.3)]
EXTREMES = [(1.0, ba, da) for ba in (0.01, 100.0) for da in (1e-3, 1.0 - 1e-6)]


def _shape(drawn):
    scale, log_ba, da = drawn
    return scale, scale * math.exp(log_ba), scale * da


class Reference:
    """The contact geometry built from the paper's parametric ellipses (section 2) only."""

    def __init__(self, a, b, delta):
        self.a, self.b, self.delta = float(a), float(b), float(delta)
        self.theta_max = brentq(self.q, math.pi / 2, math.pi, xtol=1e-16, rtol=8.9e-16)
        self.eta_max = self.eta(self.theta_max)
        self.size = max(a, b) + delta

    # the ellipses: polar angle measured from -e2 (disk 1) and from +e2 (disk 2); vectorised
    def _polar(self, angle):
        s, c = np.sin(angle), np.cos(angle)
        d2 = self.a**2 * s * s + self.b**2 * c * c
        rho = self.a * self.b / np.sqrt(d2)
        drho = -self.a * self.b * (self.a**2 - self.b**2) * s * c / d2**1.5
        return s, c, rho, drho

    def r1(self, theta):
        """GA (m): paper, x1 = ab sinθ/D, x2 = −(Δ + ab cosθ/D)."""
        s, c, rho, _ = self._polar(theta)
        return np.stack([rho * s, -(self.delta + rho * c), 0.0 * s], axis=-1)

    def r1_prime(self, theta):
        """dr1/dθ (m/rad), differentiated by hand."""
        s, c, rho, drho = self._polar(theta)
        return np.stack([drho * s + rho * c, -(drho * c - rho * s), 0.0 * s], axis=-1)

    def r2(self, psi):
        """GB (m): paper, x2 = Δ + ab cosψ/D, x3 = −ab sinψ/D."""
        s, c, rho, _ = self._polar(psi)
        return np.stack([0.0 * s, self.delta + rho * c, -rho * s], axis=-1)

    def r2_prime(self, psi):
        """dr2/dψ (m/rad)."""
        s, c, rho, drho = self._polar(psi)
        return np.stack([0.0 * s, drho * c - rho * s, -(drho * s + rho * c)], axis=-1)

    def q(self, theta):
        """Q(θ) (m⁴), whose root in (π/2, π) is θ_max."""
        s, c = math.sin(theta), math.cos(theta)
        d = math.hypot(self.a * s, self.b * c)
        return (self.a**4 * s * s + 4 * self.a * self.b * self.delta * c * d
                + 4 * self.b**2 * self.delta**2 * c * c)

    def eta(self, theta):
        """Eccentric anomaly of A on disk 1 (rad): tan θ = (b/a) tan η."""
        return math.atan2(self.a * math.sin(theta), self.b * math.cos(theta))

    def theta(self, eta):
        return math.atan2(self.b * math.sin(eta), self.a * math.cos(eta))

    def triple(self, theta, psi):
        """<r2 − r1, r1′_θ, r2′_ψ> (m³); ``psi`` may be an array."""
        cross = np.cross(self.r1_prime(theta), self.r2_prime(psi))
        return np.sum((self.r2(psi) - self.r1(theta)) * cross, axis=-1)

    def psi(self, theta, branch=1):
        """ψ(θ) on a branch: the single root of the triple product on that half of disk 2."""
        grid = branch * np.linspace(0.0, math.pi, 65)
        values = self.triple(theta, grid)
        # the same triple product in floats for brentq (np.cross/np.stack on one point cost
        # ~30 µs a call): r1′ = (p1, p2, 0), r2′ = (0, q2, q3), so r1′ × r2′ = (p2 q3,
        # −p1 q3, p1 q2)
        (x1, y1, _), (p1, p2, _) = self.r1(theta).tolist(), self.r1_prime(theta).tolist()
        a, b, delta = self.a, self.b, self.delta

        def triple_at(angle):
            s, c = math.sin(angle), math.cos(angle)
            d2 = a * a * s * s + b * b * c * c
            rho = a * b / math.sqrt(d2)
            drho = -a * b * (a * a - b * b) * s * c / d2**1.5
            q2, q3 = drho * c - rho * s, -(drho * s + rho * c)
            return (-x1 * (p2 * q3) + (delta + rho * c - y1) * (-p1 * q3)
                    + (-rho * s) * (p1 * q2))
        roots = []
        for i in range(len(grid) - 1):
            if values[i] == 0.0:
                roots.append(grid[i])
            elif values[i] * values[i + 1] < 0:
                low, high = sorted((grid[i], grid[i + 1]))
                roots.append(brentq(triple_at, low, high,
                                    xtol=1e-16, rtol=8.9e-16, maxiter=200))
        assert len(roots) == 1, f'expected one contact point per branch, got ψ = {roots}'
        return roots[0]

    def contact(self, theta, branch=1, turning=False):
        """(ψ, r1, r2, n, height) at θ, with n ∝ t1 × (r2 − r1).

        At a turning point (``turning``) ψ = 0 and the tangent at A passes through B, so
        there the plane is spanned by the two tangents instead: n ∝ t1 × t2.
        """
        psi = 0.0 if turning else self.psi(theta, branch)
        r1, r2 = self.r1(theta), self.r2(psi)
        tangent = self.r1_prime(theta)
        n = np.cross(tangent, self.r2_prime(psi) if turning else r2 - r1)
        n /= np.linalg.norm(n)
        if -r1 @ n < 0:
            n = -n
        return psi, r1, r2, n, float(-r1 @ n)

    def height(self, theta, branch=1):
        return self.contact(theta, branch)[4]

    def feature_width(self):
        """The narrowest feature of z_G in η (rad): ~a/b for b > a, ~2√(Δ/a) for Δ → 0."""
        return min(1.0, self.a / self.b, 2 * math.sqrt(self.delta / self.a))

    def height_derivatives(self, theta, step_fraction=3e-3):
        """(dz_G/dθ, d²z_G/dθ²) by 5-point differences in η and the chain rule."""
        a, b = self.a, self.b
        eta = self.eta(theta)
        h = step_fraction * self.feature_width()
        f = [self.height(self.theta(eta + k * h)) for k in (-2, -1, 0, 1, 2)]
        d1 = (f[0] - 8 * f[1] + 8 * f[3] - f[4]) / (12 * h)
        d2 = (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)
        s, c = math.sin(eta), math.cos(eta)
        den = a * a * c * c + b * b * s * s
        t1 = a * b / den                                  # dθ/dη
        t2 = -2 * a * b * (b * b - a * a) * s * c / den**2  # d²θ/dη²
        slope = d1 / t1
        return slope, (d2 - slope * t2) / t1**2

    def sample_thetas(self, fraction=0.99, count=25):
        """θ at equally spaced η in [−fraction, fraction]·η_max, plus 0 and ±π/2."""
        etas = np.linspace(-fraction, fraction, count) * self.eta_max
        thetas = [self.theta(e) for e in etas] + [0.0, math.pi / 2, -math.pi / 2]
        return np.array(thetas)


def _compare_geometry(body, ref, thetas, angle_atol, length_rtol):
    for branch in (1, -1):
        expected = [ref.contact(t, branch) for t in thetas]
        psi = np.array([e[0] for e in expected])
        r2 = np.array([e[2] for e in expected])
        n = np.array([e[3] for e in expected])
        height = np.array([e[4] for e in expected])
        geo = body.geometry(thetas, branch)
        scale = ref.size
        assert_allclose(body.contact_angle_psi(thetas, branch), psi, rtol=0, atol=angle_atol)
        assert_allclose(geo.psi, psi, rtol=0, atol=angle_atol)
        assert_allclose(geo.contact_a, [ref.r1(t) for t in thetas], rtol=0,
                        atol=length_rtol * scale)
        assert_allclose(geo.contact_b, r2, rtol=0, atol=length_rtol * scale + angle_atol * scale)
        assert_allclose(body.ground_normal(thetas, branch), n, rtol=0, atol=angle_atol)
        assert_allclose(geo.height, height, rtol=0, atol=length_rtol * scale)
        assert_allclose(body.height(thetas), height, rtol=0, atol=length_rtol * scale)
        # cos φ = n·e3 (paper, section 3)
        assert_allclose(np.cos(body.tilt(thetas, branch)), n[:, 2], rtol=0, atol=angle_atol)


# -- closed forms against the construction ---------------------------------------------------
@pytest.mark.parametrize('shape', NAMED)
def test_closed_forms_named_bodies(shape):
    body, ref = EllipseBody(*shape), Reference(*shape)
    assert_allclose(body.theta_max, ref.theta_max, rtol=0, atol=ANGLE_ATOL)
    _compare_geometry(body, ref, ref.sample_thetas(), ANGLE_ATOL, LENGTH_RTOL)


@settings(max_examples=25, deadline=None)
@given(SHAPES)
def test_closed_forms_across_shapes(drawn):
    shape = _shape(drawn)
    body, ref = EllipseBody(*shape), Reference(*shape)
    assert_allclose(body.theta_max, ref.theta_max, rtol=0, atol=ANGLE_ATOL)
    assert_allclose(body.psi_max, ref.theta_max, rtol=0, atol=ANGLE_ATOL)
    _compare_geometry(body, ref, ref.sample_thetas(count=13), ANGLE_ATOL, LENGTH_RTOL)


def _check_derivatives(shape):
    body, ref = EllipseBody(*shape), Reference(*shape)
    thetas = ref.sample_thetas(fraction=0.9, count=9)
    fd = np.array([ref.height_derivatives(t) for t in thetas])
    slope, curvature = body.height_derivative(thetas), body.height_second_derivative(thetas)
    width = ref.feature_width()
    slope_floor = SLOPE_NOISE * ref.size / width
    curvature_floor = CURVATURE_NOISE * ref.size / width**2
    assert_allclose(slope, fd[:, 0], rtol=0,
                    atol=SLOPE_RTOL * np.abs(fd[:, 0]).max() + slope_floor)
    assert_allclose(curvature, fd[:, 1], rtol=0,
                    atol=CURVATURE_RTOL * np.abs(fd[:, 1]).max() + curvature_floor)
    # the paper's V″(0) and V″(π/2) (section 4, M g = 1) against the differences
    v2_0, v2_90 = ref.height_derivatives(0.0)[1], ref.height_derivatives(math.pi / 2)[1]
    scale = max(abs(v2_0), abs(v2_90)) + curvature_floor / CURVATURE_RTOL
    assert_allclose(curvature_at_theta0(*shape), v2_0, rtol=0, atol=CURVATURE_RTOL * scale)
    assert_allclose(curvature_at_half_pi(*shape), v2_90, rtol=0, atol=CURVATURE_RTOL * scale)
    assert_allclose(body.height_second_derivative(0.0), v2_0, rtol=0, atol=CURVATURE_RTOL * scale)


@pytest.mark.parametrize('shape', NAMED)
def test_height_derivatives_named_bodies(shape):
    _check_derivatives(shape)


@settings(max_examples=25, deadline=None)
@given(SHAPES)
def test_height_derivatives_across_shapes(drawn):
    _check_derivatives(_shape(drawn))


@settings(max_examples=40, deadline=None)
@given(SHAPES)
def test_heights_at_the_equilibria(drawn):
    """V(0) = b(a+Δ)/√(b²+4aΔ+4Δ²), V(π/2) = b/√2 and V(θ_max) = V(0) (disk swap), M g = 1."""
    shape = _shape(drawn)
    a, b, delta = shape
    body, ref = EllipseBody(*shape), Reference(*shape)
    v0 = height_at_theta0(*shape)
    tol = LENGTH_RTOL * ref.size
    assert_allclose(ref.height(0.0), v0, rtol=0, atol=tol)
    assert_allclose(ref.height(math.pi / 2), b / SQRT2, rtol=0, atol=tol)
    # the turning point: B at the tip of disk 2 (ψ = 0), plane through the tangent at A
    _, _, _, n, v_turn = ref.contact(ref.theta_max, turning=True)
    assert_allclose(n[2], 0.0, atol=ANGLE_ATOL)   # disk 1 stands vertical
    assert_allclose(v_turn, v0, rtol=0, atol=tol)
    assert_allclose(body.height(np.array([0.0, math.pi / 2, -math.pi / 2])),
                    [v0, b / SQRT2, b / SQRT2], rtol=0, atol=tol)
    assert_allclose(body.height(body.theta_max), v0, rtol=0, atol=100 * tol)
    geo = body.phase_geometry(np.array([-math.pi / 2, 0.0, math.pi / 2, math.pi]))
    assert_allclose(geo.height, v0, rtol=0, atol=100 * tol)
    assert_allclose(geo.psi[[0, 2]], 0.0, atol=ANGLE_ATOL)
    assert_allclose(geo.ground_normal[[0, 2], 2], 0.0, atol=ANGLE_ATOL)
    # V′ vanishes there; cos(π/2) is 6e-17 in floating point, so |V′| ≲ |V″|·1e-16, plus
    # the rounding of V′'s closed form (terms of the size per radian): 16 ulps of both
    v2 = abs(curvature_at_theta0(*shape)) + abs(curvature_at_half_pi(*shape))
    assert_allclose(body.height_derivative(np.array([0.0, math.pi / 2])), 0.0,
                    atol=ulps(16, v2 + ref.size))


def test_theta_max_matches_q_root_named():
    for shape in NAMED:
        a, b, delta = shape
        expected = math.acos(-a * a / math.sqrt(a**4 + 4 * a * delta * b * b
                                                + 4 * delta**2 * b * b))
        assert_allclose(Reference(*shape).theta_max, expected, rtol=0, atol=1e-12)
        assert_allclose(EllipseBody(*shape).theta_max, expected, rtol=0, atol=1e-12)


def test_theta_max_full_precision():
    for a, b, delta in [(1.0, 0.01, 1e-3), (1.0, 0.05, 0.01), (1.0, 0.01, 1e-5)]:
        body = EllipseBody(a, b, delta)
        exact = math.atan2(2 * b * math.sqrt(delta * (a + delta)), -a * a)
        # to rounding (16 ulps; arccos of ≈ −1 was 2.5e-9 off)
        assert_allclose(body.theta_max, exact, rtol=ulps(16))


# -- the phase form ---------------------------------------------------------------------------
@settings(max_examples=25, deadline=None)
@given(SHAPES)
def test_phase_form_matches_theta_form(drawn):
    shape = _shape(drawn)
    body, ref = EllipseBody(*shape), Reference(*shape)
    thetas = ref.sample_thetas(count=11)
    for branch in (1, -1):
        u = body.phase_from_theta(thetas, branch)
        geo = body.phase_geometry(u)
        assert_allclose(geo.theta, thetas, rtol=0, atol=ANGLE_ATOL)
        assert np.all(geo.branch == branch)
        # definition of the phase: η = η_max sin u, with η_max from the root of Q
        etas = np.array([ref.eta(t) for t in thetas])
        assert_allclose(ref.eta_max * np.sin(u), etas, rtol=0, atol=ANGLE_ATOL)
        expected = [ref.contact(t, branch) for t in thetas]
        scale = ref.size
        assert_allclose(geo.psi, [e[0] for e in expected], rtol=0, atol=ANGLE_ATOL)
        assert_allclose(geo.contact_a, [e[1] for e in expected], rtol=0,
                        atol=LENGTH_RTOL * scale)
        assert_allclose(geo.contact_b, [e[2] for e in expected], rtol=0,
                        atol=(LENGTH_RTOL + ANGLE_ATOL) * scale)
        assert_allclose(geo.ground_normal, [e[3] for e in expected], rtol=0, atol=ANGLE_ATOL)
        assert_allclose(geo.height, [e[4] for e in expected], rtol=0, atol=LENGTH_RTOL * scale)
        assert_allclose(body.phase_height(u), geo.height, rtol=0, atol=LENGTH_RTOL * scale)
    # turning points: θ = ±θ_max, ψ = 0, and back; periodic in u
    turning = body.phase_geometry(np.array([math.pi / 2, -math.pi / 2]))
    assert_allclose(turning.theta, [ref.theta_max, -ref.theta_max], rtol=0, atol=ANGLE_ATOL)
    assert_allclose(body.phase_from_theta(np.array([1.0, -1.0]) * body.theta_max),
                    [math.pi / 2, -math.pi / 2], rtol=0, atol=1e-12)
    u = np.linspace(-math.pi, math.pi, 17)
    a0, a1 = body.phase_geometry(u), body.phase_geometry(u + 2 * math.pi)
    assert_allclose(a1.ground_normal, a0.ground_normal, rtol=0, atol=1e-13)
    assert_allclose(a1.contact_b, a0.contact_b, rtol=0, atol=1e-13 * ref.size)


@pytest.mark.parametrize('shape', NAMED)
def test_phase_form_is_continuous_through_turning_points(shape):
    """σ√Q changes sign at u = ±π/2 while every vector stays continuous."""
    body = EllipseBody(*shape)
    for center in (math.pi / 2, -math.pi / 2):
        eps = 1e-7
        geo = body.phase_geometry(np.array([center - eps, center, center + eps]))
        assert geo.branch[0] * geo.branch[2] == -1
        assert geo.signed_sqrt_q[0] * geo.signed_sqrt_q[2] < 0
        for field in ('contact_b', 'ground_normal', 'height', 'psi', 'theta'):
            values = getattr(geo, field)
            assert_allclose(values[0], values[1], rtol=0, atol=1e-5 * body.size)
            assert_allclose(values[2], values[1], rtol=0, atol=1e-5 * body.size)


# -- symmetries -------------------------------------------------------------------------------
@settings(max_examples=40, deadline=None)
@given(SHAPES)
def test_branches_mirror_each_other(drawn):
    """geometry(θ, −1) is geometry(θ, +1) reflected in the plane of disk 1 (x3 → −x3)."""
    shape = _shape(drawn)
    body = EllipseBody(*shape)
    thetas = np.linspace(-1, 1, 21) * body.theta_max
    plus, minus = body.geometry(thetas, 1), body.geometry(thetas, -1)
    mirror = np.array([1.0, 1.0, -1.0])
    # the branches' closed forms, rounded: 16 ulps of the size, of |ψ| ≤ π, of a unit vector
    tol = ulps(16, body.size)
    assert_allclose(minus.psi, -plus.psi, rtol=0, atol=ulps(16, math.pi))
    assert_allclose(minus.contact_a, plus.contact_a, rtol=0, atol=tol)
    assert_allclose(minus.contact_b, plus.contact_b * mirror, rtol=0, atol=tol)
    assert_allclose(minus.ground_normal, plus.ground_normal * mirror, rtol=0, atol=ulps(16))
    assert_allclose(minus.height, plus.height, rtol=0, atol=tol)
    # and θ → −θ reflects x1 → −x1 (the shape is symmetric in its plane)
    flipped = body.geometry(-thetas, 1)
    assert_allclose(flipped.contact_b, plus.contact_b, rtol=0, atol=tol)
    assert_allclose(flipped.ground_normal, plus.ground_normal * [-1.0, 1.0, 1.0], rtol=0,
                    atol=ulps(16))


# -- other closed forms of the paper ----------------------------------------------------------
@pytest.mark.parametrize('shape', NAMED)
def test_arc_length_rate_and_curvature(shape):
    """Eq. (1) is |dr1/dθ|; k is the ellipse's curvature ab/(a² sin²η + b² cos²η)^{3/2}."""
    body, ref = EllipseBody(*shape), Reference(*shape)
    a, b, _ = shape
    thetas = ref.sample_thetas()
    speed = [np.linalg.norm(ref.r1_prime(t)) for t in thetas]
    assert_allclose(body.arc_length_rate(thetas), speed, rtol=1e-13)
    etas = np.array([ref.eta(t) for t in thetas])
    k = a * b / (a * a * np.sin(etas) ** 2 + b * b * np.cos(etas) ** 2) ** 1.5
    assert_allclose(body.disk_curvature(thetas), k, rtol=1e-13)


# -- extremes ---------------------------------------------------------------------------------
@pytest.mark.parametrize('shape', EXTREMES)
def test_extreme_shapes(shape):
    a, b, delta = shape
    body, ref = EllipseBody(*shape), Reference(*shape)
    thetas = np.array([ref.theta(e) for e in
                       np.concatenate([np.linspace(-0.999, 0.999, 21), [1 - 1e-5, -1 + 1e-5]])
                       * ref.eta_max] + [0.0, math.pi / 2])
    _compare_geometry(body, ref, thetas, EXTREME_ANGLE_ATOL, EXTREME_LENGTH_RTOL)
    u = np.array([-math.pi / 2, 0.0, math.pi / 2, math.pi, 1.0, 2.0])
    geo = body.phase_geometry(u)
    for field in ('theta', 'psi', 'contact_a', 'contact_b', 'ground_normal', 'height', 'tilt'):
        assert np.all(np.isfinite(getattr(geo, field))), field
    # a normalised vector's norm, 3 rounded squares summed: 16 ulps of 1
    assert_allclose(np.linalg.norm(geo.ground_normal, axis=-1), 1.0, rtol=ulps(16))
    v0 = height_at_theta0(*shape)
    assert_allclose(geo.height[:4], v0, rtol=EXTREME_HEIGHT_RTOL)
    assert_allclose(body.height(math.pi / 2), b / SQRT2, rtol=1e-14)
    assert_allclose(geo.theta[[0, 2]], [-ref.theta_max, ref.theta_max], rtol=0,
                    atol=EXTREME_ANGLE_ATOL)
    assert_allclose(geo.psi[[0, 2]], 0.0, atol=EXTREME_ANGLE_ATOL)
    assert_allclose(geo.ground_normal[[0, 2], 2], 0.0, atol=EXTREME_ANGLE_ATOL)


# -- the body's size --------------------------------------------------------------------------
def test_size_is_largest_distance():
    for shape in [(1.0, 1.5, 0.9), (1.0, 1.01, 0.5), (2.0, 1.0, 1.0), (1.0, 20.0, 0.5)]:
        a, b, delta = shape
        eta = np.linspace(0, 2 * math.pi, 200001)
        dist = np.hypot(b * np.sin(eta), delta + a * np.cos(eta)).max()
        assert_allclose(EllipseBody(*shape).size, dist, rtol=1e-9)


# -- input validation -------------------------------------------------------------------------
BAD_INPUTS = [
    ('a', (0.0, 1.0, 0.5)), ('a', (-1.0, 1.0, 0.5)), ('a', (math.nan, 1.0, 0.5)),
    ('a', (math.inf, 1.0, 0.5)), ('a', ('one', 1.0, 0.5)), ('a', (None, 1.0, 0.5)),
    ('b', (1.0, 0.0, 0.5)), ('b', (1.0, -2.0, 0.5)), ('b', (1.0, math.nan, 0.5)),
    ('b', (1.0, -math.inf, 0.5)), ('b', (1.0, 'x', 0.5)),
    ('delta', (1.0, 1.0, 1.0)), ('delta', (1.0, 1.0, 1.5)), ('delta', (1.0, 1.0, 0.0)),
    ('delta', (1.0, 1.0, -0.1)), ('delta', (1.0, 1.0, math.nan)),
    ('delta', (1.0, 1.0, math.inf)), ('delta', (1.0, 1.0, 'half')),
]


@pytest.mark.parametrize('name, args', BAD_INPUTS)
def test_invalid_parameters(name, args):
    with pytest.raises(ValueError) as info:
        EllipseBody(*args)
    message = str(info.value)
    assert '\n' not in message
    assert message.startswith(f'{name} ')
    bad = args[('a', 'b', 'delta').index(name)]
    assert repr(bad) in message or str(bad) in message
    assert '> 0' in message or '<' in message


def test_numeric_strings_are_rejected():
    with pytest.raises(ValueError, match='^a '):
        EllipseBody('1.0', 1.0, 0.5)


def test_theta_outside_range_is_rejected():
    body = EllipseBody(1.0, 1.0, 0.5)
    for bad in (body.theta_max * 1.001, -3.0, math.nan):
        with pytest.raises(ValueError, match='theta'):
            body.geometry(bad)
    with pytest.raises(ValueError, match='branch'):
        body.geometry(0.1, branch=0)


def test_reference_is_self_consistent():
    """The reference's hand derivatives match differences of its positions (guards the guard)."""
    ref = Reference(2.0, 0.7, 0.4)
    h = 1e-6
    for t in (-1.0, 0.3, 2.0):
        fd = (ref.r1(t + h) - ref.r1(t - h)) / (2 * h)
        assert_allclose(ref.r1_prime(t), fd, atol=1e-8)
        fd = (ref.r2(t + h) - ref.r2(t - h)) / (2 * h)
        assert_allclose(ref.r2_prime(t), fd, atol=1e-8)
    # the arc of disk 1 between ±θ_max from eq. (1) equals the one from |dr1/dθ|
    arc = quad(lambda t: np.linalg.norm(ref.r1_prime(t)), -ref.theta_max, ref.theta_max,
               epsabs=1e-13, epsrel=1e-13)[0]
    body = EllipseBody(2.0, 0.7, 0.4)
    arc1 = quad(lambda t: float(body.arc_length_rate(t)), -ref.theta_max, ref.theta_max,
                epsabs=1e-13, epsrel=1e-13)[0]
    assert_allclose(arc1, arc, rtol=1e-12)

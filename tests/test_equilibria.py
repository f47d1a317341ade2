"""Tests of :mod:`twodisk_ros.physics.stability.equilibria`: the eight rest positions per cycle and their stability.

Heights are those of G above the ground (m), i.e. the potential energy per unit M g.
The reference height used here is built independently of the code and of the triple-product
construction of ``test_body_geometry``: the tangent line of disk 1 at A meets the common axis
(x1 = x3 = 0) at P; B is the point of disk 2 whose tangent passes through P (polar line of P),
on the half x3 < 0 for branch +1; the ground normal is n ∝ t1 × (B − A), oriented so that G is
above. Curvatures are 5-point finite differences of that height, in θ, or in the cycle phase u
through the phase's definition η = η_max sin u, tan θ = (b/a) tan η (η_max from the root of Q).
"""

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.optimize import brentq

from paper_forms import curvature_at_half_pi, curvature_at_theta0, height_at_theta0, height_slope
from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.cycle import RollingCycle
from twodisk_ros.physics.stability.equilibria import (NEUTRAL, STABLE, UNSTABLE, equilibria,
                                                     stability_map)

SQRT2 = math.sqrt(2.0)

# -- tolerances ----------------------------------------------------------------------------
# Each names the claim of docs/physics.md ("Accuracy and its limits": equilibria) it checks.
# Measured on 1000 random shapes of SHAPES plus NAMED (seeded numpy draws, same ranges).
#: Heights at the equilibria against the closed forms, relative: docs ≤ 1.2e-14 (thin shapes;
#: ≤ 2e-15 for b/a near 1); measured 1.2e-14 at (6.5, 0.33, 0.48).
HEIGHT_RTOL = 4e-14
#: The reference's own height (polar construction) at the code's phases: measured ≤ 8.6e-14
#: (thin shape (1, 0.05, 0.01)).
REFERENCE_HEIGHT_RTOL = 3e-13
#: Where the equilibria are (rad): the code's θ and ψ measured ≤ 2.8e-14, the reference's
#: θ(u) at the code's phases ≤ 1.1e-13.
ANGLE_ATOL = 4e-13
#: Curvatures vanish on the neutral curve b² − 2a² + 2Δ² = 0 while their errors do not, so
#: they are compared relative to the curvature's scale |V″| max(a, b)² / |b² − 2a² + 2Δ²|
#: (``_rtol``); near b/a ≈ 1 this is the relative error.
#: θ-family curvature against the paper's V″(0), V″(π/2): docs ≤ 1.4e-14; measured 1.4e-14.
THETA_CURVATURE_RTOL = 5e-14
#: Turning-point curvature (coordinate ψ) against V″(0) (disk-swap symmetry): the code divides
#: its spectral d²z_G/du² by (dψ/du)²; docs ≤ 7.4e-12, measured 7.4e-12 over 1000 random
#: shapes. In the corner of thick-and-close bodies (b/a ≥ 12, Δ/a ≤ 0.1: docs ≤ 6e-11) more:
#: hypothesis found 3.3e-11 at (1, 18.87, 0.0117); a scan of 3000 shapes and a grid there
#: measured ≤ 5.9e-11, every shape above 7.4e-12 inside that corner.
TURNING_CURVATURE_RTOL = 3e-11
TURNING_CURVATURE_CORNER_RTOL = 1e-10


def _turning_rtol(shape):
    a, b, delta = shape
    corner = b / a >= 12 and delta / a <= 0.1
    return TURNING_CURVATURE_CORNER_RTOL if corner else TURNING_CURVATURE_RTOL
#: d²z_G/du² (``phase_curvature``), against closed forms: V″(θ*)·(dθ/du)² at θ* = 0, ±π/2
#: (V′ = 0 there), and z_G′(θ_max)·d²θ/du² at the turning points (dθ/du = 0 there, and z_G(θ)
#: is smooth through θ_max); dθ/du from the phase's definition. Measured ≤ 2.6e-11.
PHASE_CURVATURE_RTOL = 1e-10
#: Extreme shapes (b/a ∈ {0.01, 100}, Δ/a ∈ {1e-3, 1 − 1e-6}): heights measured ≤ 1.5e-13,
#: θ-family curvatures ≤ 3.7e-14, turning-point curvatures and d²z_G/du² there ≤ 6.4e-9
#: (docs: 6.4e-9 at the extremes; all relative to the curvature scale as above).
EXTREME_HEIGHT_RTOL = 5e-13
EXTREME_THETA_CURVATURE_RTOL = 1.5e-13
EXTREME_TURNING_RTOL = 2e-8
#: Constant z_G of the neutral shapes, relative to the size: the reference height at many θ
#: and the code's phase_height both measured ≤ 6.6e-16 of a (300 random neutral shapes); the
#: cycle tables of the Two-Circle-Roller ≤ 1.1e-16 m at a = 0.3 m. Sums of rounded terms of
#: the size: 16 ulps.
NEUTRAL_RTOL = ulps(16)

SHAPES = st.tuples(st.floats(0.1, 10.0), st.floats(math.log(0.05), math.log(20.0)),
                   st.floats(0.01, 0.99))
NAMED = [(1.0, 1.0, 0.5), (2.0, 1.0, 1.0), (1.0, 1.5, 0.3), (1.0, 0.05, 0.01),
         (1.0, 20.0, 0.99), (3.0, 1.0, 2.5), (0.8, 2.0, 0.3)]


def _shape(drawn):
    scale, log_ba, da = drawn
    return scale, scale * math.exp(log_ba), scale * da


class PolarReference:
    """z_G from the polar-line construction (module doc), in m."""

    def __init__(self, a, b, delta):
        self.a, self.b, self.delta = float(a), float(b), float(delta)

        def q(t):
            s, c = math.sin(t), math.cos(t)
            return (a**4 * s * s + 4 * a * b * delta * c * math.hypot(a * s, b * c)
                    + 4 * b * b * delta * delta * c * c)
        self.theta_max = brentq(q, math.pi / 2, math.pi, xtol=1e-16, rtol=8.9e-16)
        self.eta_max = math.atan2(a * math.sin(self.theta_max), b * math.cos(self.theta_max))

    def height(self, theta, branch=1):
        a, b, delta = self.a, self.b, self.delta
        s, c = math.sin(theta), math.cos(theta)
        rho = a * b / math.hypot(a * s, b * c)
        point_a = np.array([rho * s, -(delta + rho * c), 0.0])
        tangent = np.array([b * b * c, a * a * s, 0.0])        # ∝ dr1/dθ
        # 1/X with X = (x2 of P) − Δ, finite also when the tangent is parallel to the axis
        inv_x = tangent[0] / (tangent[0] * (point_a[1] - delta) - point_a[0] * tangent[1])
        ratio2 = min(1.0, (a * inv_x) ** 2)
        point_b = np.array([0.0, delta + a * a * inv_x, -branch * b * math.sqrt(1 - ratio2)])
        n = np.cross(tangent, point_b - point_a)
        if np.linalg.norm(n) < 1e-14 * np.linalg.norm(tangent) * (a + b):
            n = np.cross(tangent, [0.0, 0.0, 1.0])           # turning point: B at the tip
        n /= np.linalg.norm(n)
        if -point_a @ n < 0:
            n = -n
        return float(-point_a @ n)

    def theta_of_phase(self, u):
        """θ(u) from the phase's definition: η = η_max sin u, tan θ = (b/a) tan η."""
        eta = self.eta_max * math.sin(u)
        return math.atan2(self.b * math.sin(eta), self.a * math.cos(eta))

    def phase_height(self, u):
        branch = 1 if math.cos(u) >= 0 else -1
        return self.height(self.theta_of_phase(u), branch)

    def second_difference(self, function, x, h):
        f = [function(x + k * h) for k in (-2, -1, 0, 1, 2)]
        return (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)


def _rtol(shape, rtol):
    """rtol relative to the curvature's scale |V″| max(a, b)² / |b² − 2a² + 2Δ²|."""
    a, b, delta = shape
    return rtol * max(a, b) ** 2 / abs(b * b - 2 * a * a + 2 * delta * delta)


def _turning_phase_curvatures(shape, ref):
    """d²z_G/du² at u = π/2 and 3π/2 (θ = ±θ_max): z_G′(θ) · d²θ/du², as dθ/du = 0 there.

    θ(u) = atan2(b sin η, a cos η), η = η_max sin u, so d²θ/du² = ∓(dθ/dη) η_max with
    dθ/dη = ab / (a² cos²η + b² sin²η) at η = ±η_max.
    """
    a, b, delta = shape
    eta = ref.eta_max
    rate = a * b / (a * a * math.cos(eta) ** 2 + b * b * math.sin(eta) ** 2)
    return [height_slope(a, b, delta, sign * ref.theta_max) * (-sign * rate * eta)
            for sign in (1, -1)]


def _check_equilibria(shape):
    a, b, delta = shape
    body, ref = EllipseBody(*shape), PolarReference(*shape)
    found = equilibria(body)
    assert len(found) == 8
    phases = np.array([e.phase for e in found])
    assert np.all(np.diff(phases) > 0) and 0 <= phases[0] and phases[-1] < 2 * math.pi
    # where they are: θ = 0, π/2, θ_max, π/2, 0, −π/2, −θ_max, −π/2 along the cycle
    tm = ref.theta_max
    thetas = [0.0, math.pi / 2, tm, math.pi / 2, 0.0, -math.pi / 2, -tm, -math.pi / 2]
    assert_allclose([e.theta for e in found], thetas, rtol=0, atol=ANGLE_ATOL)
    assert_allclose([ref.theta_of_phase(u) for u in phases], thetas, rtol=0, atol=ANGLE_ATOL)
    assert [e.coordinate for e in found] == ['theta', 'theta', 'psi', 'theta'] * 2
    assert [e.branch for e in found] == [1, 1, 1, -1, -1, -1, -1, 1]
    assert_allclose([found[i].psi for i in (2, 6)], 0.0, atol=ANGLE_ATOL)
    # heights: V(0) at θ = 0 and at the turning points, b/√2 at θ = ±π/2
    v0 = height_at_theta0(*shape)
    expected_height = [v0, b / SQRT2, v0, b / SQRT2] * 2
    assert_allclose([e.height for e in found], expected_height, rtol=HEIGHT_RTOL)
    assert_allclose([ref.phase_height(u) for u in phases], expected_height,
                    rtol=REFERENCE_HEIGHT_RTOL)
    # curvature in the named coordinate
    v2 = [curvature_at_theta0(*shape), curvature_at_half_pi(*shape)]
    for e, family in zip(found, [0, 1, None, 1, 0, 1, None, 1]):
        if family is None:
            # disk swap: the turning point in ψ is the θ = 0 equilibrium of the other disk
            assert_allclose(e.curvature, v2[0], rtol=_rtol(shape, _turning_rtol(shape)))
        else:
            assert_allclose(e.curvature, v2[family], rtol=_rtol(shape, THETA_CURVATURE_RTOL))
    # d²z_G/du²: V″·(dθ/du)² with dθ/du = (dθ/dη)(dη/du), dθ/dη = b/a at θ = 0 and a/b at
    # θ = ±π/2, dη/du = η_max cos u; z_G′(θ)·d²θ/du² at the turning points
    rate2 = [(b / a * ref.eta_max * math.cos(u)) ** 2 if fam == 0 else
             (a / b * ref.eta_max * math.cos(u)) ** 2 for u, fam in
             zip(phases, [0, 1, 0, 1, 0, 1, 0, 1])]
    turning = _turning_phase_curvatures(shape, ref)
    expected = [v2[0] * rate2[0], v2[1] * rate2[1], turning[0], v2[1] * rate2[3],
                v2[0] * rate2[4], v2[1] * rate2[5], turning[1], v2[1] * rate2[7]]
    assert_allclose([e.phase_curvature for e in found], expected,
                    rtol=_rtol(shape, PHASE_CURVATURE_RTOL))
    # stability: the sign rule of the paper, alternating along the cycle
    margin = b * b - 2 * a * a + 2 * delta * delta
    zero_family = STABLE if margin > 0 else UNSTABLE
    other = UNSTABLE if margin > 0 else STABLE
    assert [e.stability for e in found] == [zero_family, other] * 4
    for e in found:
        assert (e.stability == STABLE) == (e.phase_curvature > 0)
    return found


@pytest.mark.parametrize('shape', NAMED)
def test_equilibria_named(shape):
    _check_equilibria(shape)


@settings(max_examples=40, deadline=None)
@given(SHAPES)
@example((1.0, 2.9375, 0.01171875))   # b/a = e^2.9375 = 18.87: found by hypothesis (the corner)
def test_equilibria_across_shapes(drawn):
    shape = _shape(drawn)
    margin = shape[1] ** 2 - 2 * shape[0] ** 2 + 2 * shape[2] ** 2
    if abs(margin) < 1e-6 * max(shape[0], shape[1]) ** 2:
        return   # neutral shapes: test_neutral_shapes
    _check_equilibria(shape)


@pytest.mark.parametrize('shape', [(1.0, 0.01, 1e-3), (1.0, 100.0, 1e-3), (1.0, 0.01, 1 - 1e-6),
                                   (1.0, 100.0, 1 - 1e-6)])
def test_equilibria_extremes(shape):
    found = equilibria(EllipseBody(*shape))
    assert len(found) == 8
    for e in found:
        for name in ('phase', 'theta', 'psi', 'height', 'curvature', 'phase_curvature'):
            assert math.isfinite(getattr(e, name)), (e.name, name)
    a, b, delta = shape
    assert_allclose([e.height for e in found], [height_at_theta0(*shape), b / SQRT2] * 4,
                    rtol=EXTREME_HEIGHT_RTOL)
    margin = b * b - 2 * a * a + 2 * delta * delta
    zero_family = STABLE if margin > 0 else UNSTABLE
    assert found[0].stability == found[2].stability == zero_family
    assert found[1].stability != zero_family
    theta_rtol = _rtol(shape, EXTREME_THETA_CURVATURE_RTOL)
    assert_allclose(found[0].curvature, curvature_at_theta0(*shape), rtol=theta_rtol)
    assert_allclose(found[1].curvature, curvature_at_half_pi(*shape), rtol=theta_rtol)
    turning_rtol = _rtol(shape, EXTREME_TURNING_RTOL)
    assert_allclose([found[2].curvature, found[6].curvature], curvature_at_theta0(*shape),
                    rtol=turning_rtol)
    assert_allclose([found[2].phase_curvature, found[6].phase_curvature],
                    _turning_phase_curvatures(shape, PolarReference(*shape)), rtol=turning_rtol)


# -- the neutral case -------------------------------------------------------------------------
@settings(max_examples=20, deadline=None)
@given(st.floats(0.1, 10.0), st.floats(0.05, 1.40))
def test_neutral_shapes(scale, b_over_a):
    """Δ = √(a² − b²/2): every equilibrium is neutral and z_G = b/√2 over the whole cycle."""
    a, b = scale, scale * b_over_a
    delta = math.sqrt(a * a - b * b / 2)
    if not 0 < delta < a:
        return
    body, ref = EllipseBody(a, b, delta), PolarReference(a, b, delta)
    found = equilibria(body)
    assert [e.stability for e in found] == [NEUTRAL] * 8
    assert stability_map(b_over_a, delta / a) == 0
    thetas = np.linspace(-0.999, 0.999, 41) * ref.theta_max
    for branch in (1, -1):
        heights = [ref.height(t, branch) for t in thetas]
        assert_allclose(heights, b / SQRT2, rtol=0, atol=NEUTRAL_RTOL * body.size)
    u = np.linspace(-math.pi, math.pi, 201)
    assert_allclose(body.phase_height(u), b / SQRT2, rtol=0, atol=NEUTRAL_RTOL * body.size)


def test_neutral_cycle_keeps_g_level():
    """The TCR through RollingCycle: G at b/√2 at every phase, also at the turning points."""
    cycle = RollingCycle(EllipseBody.two_circle_roller(0.3))
    u = np.concatenate([np.linspace(0, 2 * math.pi, 721), np.arange(4) * math.pi / 2])
    assert_allclose(cycle.state(u).position_g[:, 2], 0.3 / SQRT2, rtol=0,
                    atol=NEUTRAL_RTOL * cycle.body.size)
    assert [e.stability for e in equilibria(cycle.body)] == [NEUTRAL] * 8


def test_near_neutral_is_not_neutral():
    """Just off the neutral curve the sign rule applies (the neutral band is ~1e-9 of a²)."""
    a, b = 1.0, 1.0
    delta = math.sqrt(a * a - b * b / 2)
    for offset, zero_family in ((1e-6, STABLE), (-1e-6, UNSTABLE)):
        found = equilibria(EllipseBody(a, b, delta + offset))
        assert [e.stability for e in found][:3] == [
            zero_family, UNSTABLE if zero_family == STABLE else STABLE, zero_family]


# -- the stability map ------------------------------------------------------------------------
def test_stability_map_matches_numerical_curvature():
    """Sign of d²z_G/dθ² at θ = 0 from differences of the reference height, on a grid."""
    b_over_a = np.array([0.07, 0.2, 0.5, 0.9, 1.1, 1.3, 1.6, 2.2, 3.0])
    delta_over_a = np.array([0.03, 0.15, 0.35, 0.55, 0.72, 0.9, 0.97])
    grid = stability_map(b_over_a[:, None], delta_over_a[None, :])
    assert grid.shape == (9, 7)
    checked = 0
    for i, ba in enumerate(b_over_a):
        for j, da in enumerate(delta_over_a):
            ref = PolarReference(1.0, ba, da)
            h = 1e-3 * min(1.0, 2 * ba * math.sqrt(da))
            v2 = ref.second_difference(ref.height, 0.0, h)
            # the sign is meaningful: far above the round-off of the difference, ~eps·z_G/h²
            assert abs(v2) > 100 * 1e-15 * ref.height(0.0) / h**2, (ba, da, v2)
            assert grid[i, j] == int(np.sign(v2)), (ba, da, v2)
            # and the map is the stability of θ = 0 reported by equilibria()
            first = equilibria(EllipseBody(1.0, ba, da))[0]
            assert first.stability == (STABLE if grid[i, j] > 0 else UNSTABLE)
            checked += 1
    assert checked == 63
    # both families occur on the grid, and the neutral curve is recognised
    assert {-1, 1} <= set(grid.ravel().tolist())
    b_line = np.linspace(0.05, 1.4, 11)
    assert np.all(stability_map(b_line, np.sqrt(1 - b_line**2 / 2)) == 0)


def test_stability_map_broadcasts_and_scales():
    b = np.linspace(0.05, 3.0, 5)
    d = np.linspace(0.01, 0.99, 4)
    grid = stability_map(b[:, None], d[None, :])
    assert grid.shape == (5, 4)
    expected = np.sign(b[:, None] ** 2 - 2 + 2 * d[None, :] ** 2)
    assert np.array_equal(grid, expected)

"""physics/stability/symmetric.py (issue 20): the closed-form stability of the symmetric
equilibria against independent references.

References, sharing no code with the module under test:

* the height of G along the rolling motion from ContactSolver's contact geometry (the
  support-function solve of bodies/contact_solver.py), differentiated numerically here: z_G is sampled
  at six poses whose rolling angle γ (the signed angle between the ground normal n and its
  value at the equilibrium, both in the body frame) is about ±h, ±h/2, ±h/4, and
  z_G − z_G* = Σ_{j=1..6} c_j γ^j is solved exactly: d²z_G/dγ² = 2c₂. The same solve of
  degree 4 on the four inner poses gives a second value; their difference is the truncation
  estimate (the degree-4 error, ~c₅(h/2)³ or c₆(h/2)⁴, far above the degree-6 one, measured
  10× to 1000× the true error) and is the tolerance, itself held below 1e-5 of the size;
* at flat vertices (superellipse, n > 2), the height at |p| = 1e-3 and 1e-4, p the component
  of n named by the equilibrium, found by brentq on the charts, against the two-term
  expansion A|p|^q + B p², whose remainder is O(|p|^2q) (measured ≤ 0.45 L|p|^2q, L below);
* for ellipses, EllipseBody's closed forms (the paper's margin s = b² − 2a² + 2Δ², its
  d²z_G/dθ² with dγ/dθ from central differences of its ground normal), and the small-
  oscillation period of RollingDynamics (effective mass and V″ in the phase u).
"""

import functools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st
from scipy.optimize import brentq

from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.bodies.contact_solver import ContactSolver
from twodisk_ros.physics.laminae.shapes import Ellipse, Superellipse
from twodisk_ros.physics.laminae.support import Egg, SupportLamina
from twodisk_ros.physics.laminae.fit import Outline
from twodisk_ros.physics.mass.models import mass_properties
from twodisk_ros.physics.stability.symmetric import (NOT_AN_EQUILIBRIUM,
                                                     symmetric_equilibria)

#: rolling-angle step of the finite differences (rad); halved down to H / 64 while the
#: truncation estimate exceeds FD_CAP
H = 0.02
#: the finite differences' accuracy claim: truncation estimate ≤ 1e-5 of the size; rounding
#: of z_G (~2e-16 of the size, divided by (h/4)²) stays below FD_FLOOR
FD_CAP, FD_FLOOR = 1e-5, 1e-10
#: the remainder of the flat-vertex expansion: |z_G − z_G* − A|p|^q − B p²| ≤ 10 L |p|^2q plus
#: the rounding of z_G − z_G* (two heights, each a sum of rounded terms: 16 ulps of the size
#: each), L = size + A²/e (e the lamina's smallest extent: the vertex's own next term is
#: ~c²/e |t|^2q); measured ≤ 0.45 L |p|^2q (30 random superellipses, n from 2.01 to 100)
FLAT_REMAINDER, Z_ROUNDING = 10.0, ulps(32)
EPS = 4 * np.finfo(float).eps

ELLIPSES = [(1.0, 1.0, 0.5), (1.0, 0.2, 0.05), (1.0, 0.2, 0.9), (2.0, 6.0, 0.1),
            (1.0, 3.0, 0.4), (1.0, 3.0, 0.9), (2.0, 1.0, 1.0)]
SMOOTH = ([(Ellipse(a, b), d, 'parallel') for a, b, d in ELLIPSES]
          + [(Egg(1.3, 1.0, 0.08), 0.5, 'parallel'), (Egg(1.3, 1.0, 0.08), 0.95, 'parallel'),
             (Egg(1.3, 1.0, -0.08), 0.5, 'swapped'), (Egg(2.0, 1.0, -0.05), 0.6, 'parallel'),
             (Egg(2.0, 1.0, 0.06), 0.3, 'swapped'), (Egg(1.0, 1.2, 0.1), 0.7, 'swapped'),
             (Superellipse(1.0, 0.5, 2.0), 0.5, 'parallel'),
             (Outline([1.0, 0.05, 0.1, 0.02, 0.01]), 0.4, 'parallel'),
             (Outline([1.0, 0.0, -0.15, 0.0, 0.02]), 0.3, 'swapped')])
SMOOTH_IDS = [f'{lam!r}-{d}-{arr}' for lam, d, arr in SMOOTH]


# -- the numerical references ----------------------------------------------------------------
def _chart(body, eq):
    """Pose function of a chart coordinate x, x at the equilibrium, and the chart's range.

    Away from the turning points the coordinate is A's lamina parameter s (the poses of
    geometry(θ) at θ(s), without its bisection of θ back to s); x* = s(θ*)."""
    if eq.name == 'turning point':
        return body.geometry_at_tilt, math.pi / 2, body.tilt_range

    def pose(s):
        s = np.asarray(s, dtype=float)
        return body.geometry_at_parameter(s, body.elevation_of_parameter(s))
    return pose, float(body.parameter_of_theta(eq.theta)), (-body.s_max, body.s_max)


def _rolling_samples(chart, centre, h, span):
    """(γ, z_G − z_G*) at six poses with γ ≈ ±h, ±h/2, ±h/4, and the chart half-width used.

    The poses are found on a grid of 81 chart coordinates around the equilibrium whose half-
    width starts at span and grows (linear extrapolation of the reach, at least doubling)
    until γ covers ±h; only the targets come from the grid, γ is that of the poses found.
    """
    pose, x_star, (low, high) = chart
    n_star = centre.ground_normal

    def gamma(geo, x):
        n = geo.ground_normal
        angle = np.arctan2(np.linalg.norm(np.cross(n, n_star), axis=-1), n @ n_star)
        return np.sign(x - x_star) * angle
    for _ in range(60):
        x = np.clip(x_star + span * np.linspace(-1.0, 1.0, 81), low, high)
        g = gamma(pose(x), x)
        reach = min(-g.min(), g.max())
        if reach >= h:
            break
        span = max(2 * span, 1.1 * span * h / reach) if reach > 0 else 2 * span
    targets = h * np.array([-1.0, -0.5, -0.25, 0.25, 0.5, 1.0])
    x = np.interp(targets, g, x)
    poses = pose(x)
    return gamma(poses, x), poses.height - centre.height, span


def _height_jet(body, eq):
    """(dz_G/dγ, d²z_G/dγ², truncation estimate of the latter, pose at the equilibrium)."""
    chart = _chart(body, eq)
    centre = chart[0](np.array(chart[1]))
    h, span = H, 1e-3
    while True:
        gam, dz, span = _rolling_samples(chart, centre, h, span)
        full = np.linalg.solve(np.vander(gam, 7, increasing=True)[:, 1:], dz)
        inner = np.abs(gam) < 0.75 * np.max(np.abs(gam))
        part = np.linalg.solve(np.vander(gam[inner], 5, increasing=True)[:, 1:], dz[inner])
        estimate = abs(2 * full[1] - 2 * part[1])
        if estimate <= FD_CAP * body.size or h < H / 64:
            return full[0], 2 * full[1], estimate, centre
        h, span = h / 2, span / 2


def _flat_heights(body, eq, levels=(1e-3, 1e-4)):
    """(p, z_G − z_G*) at |p| = levels: p = n1 (θ > 0), n3 (tilt chart) or n2 (both sides)."""
    if eq.name == 'turning point':
        z0 = float(body.geometry_at_tilt(math.pi / 2).height)
        poses = [body.geometry_at_tilt(math.acos(p)) for p in levels]
        return [(float(g.ground_normal[2]), float(g.height) - z0) for g in poses]
    k, sides = (0, (1,)) if eq.name == 'theta=0' else (1, (1, -1))
    z0 = float(body.geometry(eq.theta).height)
    c0 = float(body.geometry(eq.theta).ground_normal[k])

    def pose(s):        # the pose of geometry(θ(s)) in A's lamina parameter s (no θ bisection)
        return body.geometry_at_parameter(s, body.elevation_of_parameter(s))
    s_star = float(body.parameter_of_theta(eq.theta))
    out = []
    for p in levels:
        for side in sides:
            end = side * body.s_max * (1 - 1e-12)
            s = brentq(lambda x: abs(float(pose(x).ground_normal[k]) - c0) - p,
                       *sorted((s_star, end)), xtol=1e-300, rtol=EPS, maxiter=500)
            g = pose(s)
            out.append((float(g.ground_normal[k]) - c0, float(g.height) - z0))
    return out


def _flat_remainder(body, eq, p):
    scale = body.size + eq.coefficients[0] ** 2 / min(body.lamina.extents[0],
                                                         -body.y_min, body.y_max)
    return FLAT_REMAINDER * scale * abs(p) ** (2 * eq.order) + Z_ROUNDING * body.size


def _agrees(value, reference, tolerance):
    return abs(value - reference) <= tolerance


# -- ellipses: the paper's margin and curvatures ---------------------------------------------
@pytest.mark.parametrize('a, b, delta', ELLIPSES)
def test_ellipse_reduces_to_the_paper_margin(a, b, delta):
    ref = EllipseBody(a, b, delta)
    s, w2 = ref.stability_margin, b * b + 4 * a * delta + 4 * delta * delta
    first, turning, side = symmetric_equilibria(Ellipse(a, b), delta)
    # claim: the criteria are b²(a + Δ)/(aW)·s at the tips and −s at the sides, exactly (the
    # closed forms take the tangent from brentq to 1e-15, hence 1e-13 of size²)
    scale = 1e-13 * max(a, b) ** 2
    for tip in (first, turning):
        assert tip.margin == pytest.approx(b * b * (a + delta) * s / (a * w2), abs=scale)
    assert side.margin == pytest.approx(-s, abs=scale)
    assert first.stability == ('stable' if s > 0 else 'unstable') == turning.stability
    assert side.stability == ('stable' if s < 0 else 'unstable')
    # d²z_G/dγ² = (d²z_G/dθ²)/(dγ/dθ)², dγ/dθ from the angle between n(θ ± 1e-6): truncation
    # (1e-6/w)², w ≥ (b/a)² = 0.04 the narrowest feature in θ, plus rounding 1e-16/1e-6
    for eq, theta in ((first, 0.0), (side, math.pi / 2)):
        step = 1e-6
        n = ref.ground_normal(np.array([theta - step, theta + step]))
        rate = math.atan2(np.linalg.norm(np.cross(n[0], n[1])), n[0] @ n[1]) / (2 * step)
        expected = float(ref.height_second_derivative(theta)) / rate**2
        assert eq.curvature == pytest.approx(expected, rel=1e-8)
        assert eq.height == pytest.approx(float(ref.height(theta)), abs=1e-14 * ref.size)
    assert turning.theta == pytest.approx(ref.theta_max, abs=1e-13)
    assert first.psi == pytest.approx(ref.psi_max, abs=1e-13)
    assert side.theta == side.psi == math.pi / 2


@pytest.mark.parametrize('a, b, delta', [(0.1, 0.1, 0.05), (1.0, 3.0, 0.4)])
def test_period_is_that_of_a_rotation_about_the_contact_line(a, b, delta):
    """T = 2π √(I_AB / (M g d²z_G/dγ²)) against RollingDynamics' 2π √(m(u)/V″(u))."""
    mass, gravity = 1.0, 9.81
    ref = EllipseBody(a, b, delta)
    dynamics = RollingDynamics(ref, mass_properties('laminae', a, b, delta, mass),
                               gravity=gravity)
    periods = {eq.name: period for eq, period in dynamics.equilibria_with_periods()}
    inertia = mass_properties('laminae', a, b, delta, mass).inertia
    for eq in symmetric_equilibria(Ellipse(a, b), delta):
        if not eq.has_linear_period:
            continue
        theta, key = {'theta=0': (0.0, 'theta=0 (branch +1)'),
                      'turning point': (ref.theta_max, 'turning theta=+theta_max (branch +1)'),
                      'side vertices': (math.pi / 2, 'theta=+pi/2 (branch +1)')}[eq.name]
        ga, gb = ref.contact_vector_a(theta), ref.contact_vector_b(theta)
        axis = (gb - ga) / np.linalg.norm(gb - ga)
        arm = -ga - np.dot(-ga, axis) * axis            # from the line AB to G
        i_ab = axis @ inertia @ axis + mass * arm @ arm
        expected = 2 * math.pi * math.sqrt(i_ab / (mass * gravity * eq.curvature))
        # claim: the two periods agree to the tables' V″ accuracy (~1e-9)
        assert periods[key] == pytest.approx(expected, rel=1e-8)


# -- any smooth lamina: the curvature against finite differences -----------------------------
def _mutants(eq):
    """Wrong formulas that the comparison must reject: sign, factor 2, radius doubled."""
    k = eq.curvature
    if eq.name == 'side vertices':
        w, spacing = eq.vertex.extent, eq.lever
        rho_term = math.sqrt(2) * eq.vertex.radius * w * w / (w * w + 2 * spacing**2)
    else:
        rho_term = k + eq.height
    return {'sign': -k, 'twice': 2 * k, 'radius twice': k + rho_term}


@pytest.mark.parametrize('lamina, delta, arrangement', SMOOTH, ids=SMOOTH_IDS)
def test_curvature_against_finite_differences(lamina, delta, arrangement):
    body = ContactSolver(lamina, delta, arrangement)
    size = body.size
    for eq in symmetric_equilibria(lamina, delta, arrangement):
        slope, curvature, estimate, centre = _height_jet(body, eq)
        assert estimate <= FD_CAP * size, eq.name
        tolerance = estimate + FD_FLOOR * size
        # the pose: height to rounding of the charts (1e-14 of the size), angles to 1e-13
        assert eq.height == pytest.approx(float(centre.height), abs=1e-14 * size)
        assert eq.theta == pytest.approx(abs(float(centre.theta)), abs=1e-13)
        assert eq.psi == pytest.approx(float(centre.psi), abs=1e-12)
        assert _agrees(eq.slope, slope, tolerance), (eq.name, eq.slope, slope)
        if eq.stability == NOT_AN_EQUILIBRIUM:
            assert abs(slope) > 1e3 * tolerance
            continue
        assert eq.order == 2.0 and eq.has_linear_period == (eq.stability == 'stable')
        assert _agrees(eq.curvature, curvature, tolerance), (eq.name, eq.curvature, curvature)
        assert eq.stability == ('stable' if curvature > 0 else 'unstable')
        assert np.sign(eq.margin) == np.sign(curvature)
        for name, wrong in _mutants(eq).items():
            assert not _agrees(wrong, curvature, tolerance), (eq.name, name)


def test_egg_bodies_of_opposite_eggs_swap_their_tips():
    """Body(Egg(ε), parallel) is Body(Egg(−ε), parallel) turned: θ = 0 ↔ turning point."""
    one = symmetric_equilibria(Egg(1.3, 1.0, 0.08), 0.9)
    other = symmetric_equilibria(Egg(1.3, 1.0, -0.08), 0.9)
    for a, b in ((one[0], other[1]), (one[1], other[0])):
        assert a.curvature == pytest.approx(b.curvature, rel=1e-12)
        assert a.height == pytest.approx(b.height, rel=1e-14)
    # the blunt end rests stably, the sharp one does not (measured below)
    assert (one[0].stability, one[1].stability) == ('unstable', 'stable')


# -- flat vertices: the leading term ---------------------------------------------------------
FLAT = [(n, b) for n in (2.05, 2.5, 4.0, 10.0, 100.0) for b in (1.0, 0.4)]


@functools.lru_cache(maxsize=None)
def _flat_body(n, b):
    """The superellipse body of FLAT at Δ = 0.5, built once (its tilt chart's steepest pose
    costs ~1 s): shared by the leading-term and tiny-well tests."""
    return ContactSolver(Superellipse(1.0, b, n), 0.5)


@pytest.mark.parametrize('n, b', FLAT)
def test_flat_vertices_leading_terms(n, b):
    body = _flat_body(n, b)
    lamina, delta = body.lamina, 0.5
    for eq in symmetric_equilibria(lamina, delta):
        q, (a_coef, b_coef) = eq.order, eq.coefficients
        assert q == pytest.approx(n / (n - 1), rel=ulps(16))
        assert math.isnan(eq.curvature) and not eq.has_linear_period
        for p, dz in _flat_heights(body, eq):
            remainder = _flat_remainder(body, eq, p)
            expected = a_coef * abs(p) ** q + b_coef * p * p
            assert _agrees(dz, expected, remainder), (eq.name, p, dz, expected)
            # a wrong leading coefficient (sign, factor 2) is rejected at every n
            for wrong in (-a_coef, 2 * a_coef, 0.5 * a_coef):
                assert not _agrees(dz, wrong * abs(p) ** q + b_coef * p * p, remainder)
        # the verdict is the sign of A (the share of the weight on the tip for tips)
        assert eq.stability == ('stable' if a_coef > 0 else 'unstable')
        if eq.name != 'side vertices':
            assert np.sign(a_coef) == np.sign(eq.load_share)
        if n >= 4:      # the |p|^q term alone decides z_G − z_G*'s sign at small p
            p, dz = _flat_heights(body, eq, levels=(1e-6,))[0]
            assert np.sign(dz) == np.sign(a_coef) and abs(b_coef) * p * p < 1e-3 * abs(dz)


def test_nearly_elliptic_flat_tip_has_a_tiny_well():
    """n = 2.05 on the oloid-like body: stable at θ = 0, but z_G > z_G* only for |γ| < ~8e-5."""
    body = _flat_body(2.05, 1.0)
    lamina = body.lamina
    first = symmetric_equilibria(lamina, 0.5)[0]
    assert first.stability == 'stable' and 1e-5 < first.well < 1e-3
    inside, outside = _flat_heights(body, first, levels=(first.well / 10, first.well * 10))
    assert inside[1] > 0 > outside[1]
    assert 'flat vertex' in first.verdict and 'no linear small-oscillation period' in first.verdict


# -- neutral cases -----------------------------------------------------------------------------
@pytest.mark.parametrize('a, b, delta', [(1.0, 1.0, 1 / math.sqrt(2)), (math.sqrt(1.5), 1, 1)])
def test_neutral_ellipses(a, b, delta):
    body = ContactSolver(Ellipse(a, b), delta)
    for eq in symmetric_equilibria(Ellipse(a, b), delta):
        assert eq.stability == 'neutral' and 'higher orders decide' in eq.verdict
        _, curvature, estimate, _ = _height_jet(body, eq)
        assert abs(curvature) <= estimate + FD_FLOOR * body.size


@pytest.mark.parametrize('lamina, arrangement, which', [
    (Egg(1.3, 1.0, 0.08), 'parallel', 1),          # the blunt tip, disk 2's
    (Egg(1.3, 1.0, -0.08), 'parallel', 0),         # the same body turned: disk 1's tip
    (Egg(1.0, 1.2, 0.1), 'swapped', 2),            # the side vertices
])
def test_neutral_delta_is_where_the_numerical_curvature_changes_sign(lamina, arrangement, which):
    def margin(delta):
        return symmetric_equilibria(lamina, delta, arrangement)[which].margin
    neutral = brentq(margin, 0.5, 0.95, xtol=1e-14)
    assert symmetric_equilibria(lamina, neutral, arrangement)[which].stability == 'neutral'
    curvatures = []
    for delta in (neutral - 0.05, neutral, neutral + 0.05):
        body = ContactSolver(lamina, delta, arrangement)
        eq = symmetric_equilibria(lamina, delta, arrangement)[which]
        _, curvature, estimate, _ = _height_jet(body, eq)
        curvatures.append((curvature, estimate + FD_FLOOR * body.size))
    (below, _), (at, tol), (above, _) = curvatures
    assert abs(at) <= tol and below * above < 0 and min(abs(below), abs(above)) > 1e3 * tol


# -- what the vertices do not decide ----------------------------------------------------------
class _BumpedCircle(SupportLamina):
    """h = r + η sin⁴ 2φ: the circle's extents, vertex radii and vertex positions, whatever η."""

    def __init__(self, radius, bump):
        self.r, self.eta = radius, bump

    def support_jet(self, phi):
        s, c = np.sin(2 * np.asarray(phi, dtype=float)), np.cos(2 * np.asarray(phi, dtype=float))
        return (self.r + self.eta * s**4, 8 * self.eta * s**3 * c,
                self.eta * (48 * s * s * c * c - 16 * s**4))


def test_the_tip_criterion_is_not_a_function_of_vertex_data():
    """Same vertices, Δ = r/√2 (the Two-Circle-Roller: neutral), opposite verdicts at θ = 0."""
    delta = 1 / math.sqrt(2)
    verdicts = []
    for bump in (0.02, -0.02):
        lamina = _BumpedCircle(1.0, bump)
        for axis in ('-y', '+y', '+x'):
            v = lamina.vertex(axis)
            assert (v.extent == pytest.approx(1.0, abs=ulps(16))
                    and v.radius == pytest.approx(1.0))
        body = ContactSolver(lamina, delta)
        first, _, side = symmetric_equilibria(lamina, delta)
        _, curvature, estimate, _ = _height_jet(body, first)
        assert _agrees(first.curvature, curvature, estimate + FD_FLOOR * body.size)
        assert side.stability == 'neutral'        # the side criterion uses vertex data only
        verdicts.append(first.stability)
    assert sorted(verdicts) == ['stable', 'unstable']


# -- random shapes ----------------------------------------------------------------------------
# 12 examples: each checks every equilibrium of its body (tips, turning point, sides) against
# the finite differences; 4 kinds × 2 arrangements are drawn ~1.5 times each per run, and the
# named shapes above (SMOOTH, FLAT) cover every kind and arrangement deterministically. An
# example costs ~1.5 s (the turning point's tilt chart needs ContactSolver.steepest).
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(kind=st.sampled_from(['ellipse', 'superellipse', 'egg', 'outline']),
       a=st.floats(0.3, 3.0), b=st.floats(0.3, 3.0), n=st.floats(2.0, 100.0),
       shape=st.floats(-1.0, 1.0), harmonics=st.lists(st.floats(-0.4, 0.4), min_size=4,
                                                      max_size=4),
       fraction=st.floats(0.02, 0.98), arrangement=st.sampled_from(['parallel', 'swapped']))
def test_any_shape_gives_an_answer_that_numerics_confirm_or_one_line(
        kind, a, b, n, shape, harmonics, fraction, arrangement):
    try:
        lamina = {'ellipse': lambda: Ellipse(a, b), 'superellipse': lambda: Superellipse(a, b, n),
                  'egg': lambda: Egg(a, b, shape * Egg.epsilon_max(a, b)),
                  # c_k = a·x_k/k², |x_k| ≤ 0.4: convex or not (h + h″ ≤ 0: refused)
                  'outline': lambda: Outline([a, 0.1 * shape * a] + [
                      x * a / k**2 for k, x in enumerate(harmonics, start=2)]),
                  }[kind]()
        x_max, y_min, y_max = lamina.extents
        delta = fraction * 0.5 * (y_max - y_min)
        found = symmetric_equilibria(lamina, delta, arrangement)
    except ValueError as error:
        assert str(error) and '\n' not in str(error)
        return
    body = ContactSolver(lamina, delta, arrangement)
    for eq in found:
        if eq.order == 2.0:
            slope, curvature, estimate, _ = _height_jet(body, eq)
            tolerance = estimate + FD_FLOOR * body.size
            assert _agrees(eq.slope, slope, tolerance)
            if eq.stability != NOT_AN_EQUILIBRIUM:
                assert _agrees(eq.curvature, curvature, tolerance), (eq, curvature)
        else:
            for p, dz in _flat_heights(body, eq, levels=(1e-3,)):
                remainder = _flat_remainder(body, eq, p)
                a_coef, b_coef = eq.coefficients
                assert _agrees(dz, a_coef * abs(p) ** eq.order + b_coef * p * p, remainder)


@pytest.mark.parametrize('args, match', [
    ((Ellipse(1.0, 1.0), 1.0), 'delta must be <'),
    ((Ellipse(1.0, 1.0), float('nan')), 'delta must be'),
    ((Ellipse(1.0, 1.0), 0.5, 'crossed'), 'arrangement must be'),
    (('ellipse', 0.5), 'lamina must be a Lamina'),
])
def test_refusals_are_one_line(args, match):
    with pytest.raises(ValueError, match=match) as info:
        symmetric_equilibria(*args)
    assert '\n' not in str(info.value)

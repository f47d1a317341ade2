"""physics/bodies/contact_solver.py (issue 20, step 2) against independent references.

References: EllipseBody's closed forms (the paper's, a different derivation: Q(θ), its exact
factorisation and the eccentric-anomaly phase) for ellipses; the oloid's literature values;
for other shapes, constructions written here from the boundary points alone: a dense sampling
of both rims (is anything below the ground?), central-difference rim tangents (is the ground
tangent at A and B?), the tangent line from the far tip of disk 2 to disk 1 (θ_max), the
shoelace centroid (G), and the body's symmetries.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.contact_solver import ContactSolver
from twodisk_ros.physics.laminae.shapes import Ellipse, Superellipse
from twodisk_ros.physics.laminae.support import Egg

#: (a, b, Δ): oloid, Two-Circle-Roller, thin (b/a = 0.2) and wide (b/a = 3) at several Δ/a
ELLIPSE_BODIES = [(1.0, 1.0, 0.5), (1.0, 1.0, 1 / math.sqrt(2)), (1.0, 0.2, 0.05),
                  (1.0, 0.2, 0.3), (1.0, 0.2, 0.9), (2.0, 6.0, 0.1), (1.0, 3.0, 0.4),
                  (1.0, 3.0, 0.9)]
#: The ellipse claim of the brief: the general path agrees with the closed forms to ≤ 1e-11
#: of the size (measured: ≤ 4e-13 in the θ chart, ≤ 3e-15 in the tilt chart).
ELLIPSE_TOL = 1e-11
#: Where |θ| is within this fraction of θ_max, ψ(θ) is ill-conditioned (ψ ~ √(θ_max − |θ|))
#: and the comparison uses the tilt chart, in which both paths are regular.
NEAR_TURN = 1e-3
OTHER_SHAPES = [(Superellipse(1.0, 1.0, 2.5), 0.5), (Superellipse(1.0, 0.6, 4.0), 0.4),
                (Superellipse(1.0, 1.5, 4.0), 0.3), (Egg(1.3, 1.0, 0.08), 0.5),
                (Egg(2.0, 1.0, -0.05), 0.6)]
#: θ/θ_max for the disk-swap checks: θ near 0 maps to the ill-conditioned turning point
AWAY_FROM_ZERO = np.concatenate([np.linspace(-0.98, -0.2, 12), np.linspace(0.2, 0.98, 12)])
OTHER_IDS = [f'{lam!r}-d{d}' for lam, d in OTHER_SHAPES]


def _phase_grid():
    u = np.linspace(-np.pi / 2, 3 * np.pi / 2, 801)
    near = np.pi / 2 + np.concatenate([-np.logspace(-12, -1, 12), np.logspace(-12, -1, 12)])
    return np.concatenate([u, near, near - np.pi])


@pytest.mark.parametrize('arrangement', ['parallel', 'swapped'])
@pytest.mark.parametrize('a, b, delta', ELLIPSE_BODIES)
def test_ellipse_agrees_with_closed_forms(a, b, delta, arrangement):
    ref = EllipseBody(a, b, delta)
    body = ContactSolver(Ellipse(a, b), delta, arrangement)
    size = ref.size
    assert body.theta_max == pytest.approx(ref.theta_max, abs=ELLIPSE_TOL)
    assert body.psi_max == pytest.approx(ref.psi_max, abs=ELLIPSE_TOL)
    assert body.size == pytest.approx(size, abs=ELLIPSE_TOL * size)
    u = _phase_grid()
    exact = ref.phase_geometry(u)
    near = ref.theta_max - np.abs(exact.theta) < NEAR_TURN * ref.theta_max
    far = body.geometry(exact.theta[~near], exact.branch[~near])
    turn = body.geometry_at_tilt(exact.tilt[near], np.where(exact.theta[near] < 0, -1, 1))
    for mask, got in ((~near, far), (near, turn)):
        assert np.all(got.branch == exact.branch[mask])
        for name in ('theta', 'psi', 'tilt'):
            np.testing.assert_allclose(getattr(got, name), getattr(exact, name)[mask],
                                       rtol=0, atol=ELLIPSE_TOL, err_msg=name)
        np.testing.assert_allclose(got.height, exact.height[mask], rtol=0,
                                   atol=ELLIPSE_TOL * size)
        for name in ('contact_a', 'contact_b', 'ground_normal', 'tangent_a'):
            scale = size if name.startswith('contact') else 1.0
            np.testing.assert_allclose(getattr(got, name), getattr(exact, name)[mask],
                                       rtol=0, atol=ELLIPSE_TOL * scale, err_msg=name)
    # the θ-named functions mirror bodies/ellipse.py's one to one
    theta = ref.theta_max * np.linspace(-0.99, 0.99, 41)
    for branch in (1, -1):
        np.testing.assert_allclose(body.contact_angle_psi(theta, branch),
                                   ref.contact_angle_psi(theta, branch), rtol=0, atol=ELLIPSE_TOL)
        np.testing.assert_allclose(body.contact_vector_b(theta, branch),
                                   ref.contact_vector_b(theta, branch), rtol=0,
                                   atol=ELLIPSE_TOL * size)
        np.testing.assert_allclose(body.ground_normal(theta, branch),
                                   ref.ground_normal(theta, branch), rtol=0, atol=ELLIPSE_TOL)
    np.testing.assert_allclose(body.contact_vector_a(theta), ref.contact_vector_a(theta),
                               rtol=0, atol=ELLIPSE_TOL * size)
    np.testing.assert_allclose(body.height(theta), ref.height(theta), rtol=0,
                               atol=ELLIPSE_TOL * size)


@pytest.mark.parametrize('radius', [1.0, 2.5])
def test_oloid_height_range_literature(radius):
    """Circles, Δ = r/2: z_G runs over [r/√2, 3r/4] (the oloid's literature values)."""
    body = ContactSolver(Ellipse(radius, radius), radius / 2)
    # claim: the extremes are attained at θ = π/2 and θ = 0, to rounding of the size
    assert float(body.height(np.pi / 2)) == pytest.approx(radius / math.sqrt(2),
                                                          abs=1e-14 * radius)
    assert float(body.height(0.0)) == pytest.approx(0.75 * radius, abs=1e-14 * radius)
    heights = body.height(body.theta_max * np.linspace(-1, 1, 2001))
    assert heights.min() >= radius / math.sqrt(2) - 1e-14 * radius
    assert heights.max() <= 0.75 * radius + 1e-14 * radius


def _rim_points(body, samples=1 << 15):
    """Dense samples of both rims in the body frame (from O), and their lamina parameters."""
    s = np.linspace(-np.pi, np.pi, samples, endpoint=False)
    p = body.lamina.point(s)
    zero = np.zeros_like(s)
    rim1 = np.stack([p[:, 0], p[:, 1] - body.delta, zero], axis=-1)
    rim2 = np.stack([zero, body.delta + body.sigma * p[:, 1], p[:, 0]], axis=-1)
    return s, rim1, rim2


def _rim_tangent(lamina, s, h=1e-5):
    """Unit rim tangent by central differences of the points (error O(h²))."""
    d = lamina.point(s + h) - lamina.point(s - h)
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _parameter_of(lamina, point):
    """The lamina parameter of a boundary point, by minimising the distance over s."""
    s = np.linspace(-np.pi, np.pi, 4097)
    j = int(np.argmin(np.linalg.norm(lamina.point(s) - point, axis=-1)))
    found = minimize_scalar(lambda x: float(np.linalg.norm(lamina.point(x) - point)),
                            bounds=(s[max(j - 1, 0)], s[min(j + 1, 4096)]), method='bounded',
                            options={'xatol': 1e-14})
    return float(found.x)


@pytest.mark.parametrize('arrangement', ['parallel', 'swapped'])
@pytest.mark.parametrize('lamina, delta', OTHER_SHAPES, ids=OTHER_IDS)
def test_ground_supports_and_touches_both_laminae(lamina, delta, arrangement):
    body = ContactSolver(lamina, delta, arrangement)
    size = body.size
    theta = body.theta_max * np.concatenate([np.linspace(-1, 1, 13), [0.999999]])
    _, rim1, rim2 = _rim_points(body)
    # G independently: the shoelace centroid of the sampled outline, both laminae equal
    p = lamina.point(np.linspace(-np.pi, np.pi, 1 << 15, endpoint=False))
    x, y = p[:, 0], p[:, 1]
    cross = x * np.roll(y, -1) - np.roll(x, -1) * y
    y_bar = np.sum((y + np.roll(y, -1)) * cross) / (3 * np.sum(cross))
    g_ref = np.array([0.0, (-body.delta + y_bar + body.delta + body.sigma * y_bar) / 2, 0.0])
    for branch in (1, -1):
        geo = body.geometry(theta, branch)
        a_o = geo.contact_a + body.centroid
        b_o = geo.contact_b + body.centroid
        n = geo.ground_normal
        # both contacts on the ground: equal heights of A and B along n (solved to rounding)
        np.testing.assert_allclose(np.sum(n * (b_o - a_o), axis=-1), 0, atol=1e-13 * size)
        # nothing below the ground: no rim sample lower than A, to rounding; and the lowest
        # samples of each rim within the sampling error (spacing² × curvature) of the plane
        for rim in (rim1, rim2):
            low = np.min(rim @ n.T - np.sum(n * a_o, axis=-1), axis=0)
            assert np.all(low >= -1e-13 * size)
            assert np.all(low <= 1e-6 * size)
        # the ground is tangent to disk 1 at A and to disk 2 at B (finite-difference tangents,
        # O(h²) = 1e-10), and each contact's in-plane normal is parallel to the ground's
        t1 = _rim_tangent(lamina, geo.parameter_a)
        t1 = np.concatenate([t1, np.zeros_like(t1[:, :1])], axis=-1)
        assert np.all(np.abs(np.sum(t1 * n, axis=-1)) <= 1e-9)
        for j in range(theta.size):
            lam_b = np.array([b_o[j, 2], body.sigma * (b_o[j, 1] - body.delta)])
            t2 = _rim_tangent(lamina, _parameter_of(lamina, lam_b))
            tangent_b = np.array([0.0, body.sigma * t2[1], t2[0]])
            assert abs(tangent_b @ n[j]) <= 1e-7   # the distance minimiser finds s to ~1e-8
        nu = lamina.normal(geo.parameter_a)
        planar = -n[:, :2] / np.linalg.norm(n[:, :2], axis=-1, keepdims=True)
        np.testing.assert_allclose(planar, nu, atol=1e-13)
        # G's height above the ground with the independent centroid (shoelace: 1e-9 of size)
        np.testing.assert_allclose(geo.height, n @ g_ref - np.sum(n * a_o, axis=-1),
                                   atol=1e-8 * size)


@pytest.mark.parametrize('arrangement', ['parallel', 'swapped'])
@pytest.mark.parametrize('lamina, delta', OTHER_SHAPES, ids=OTHER_IDS)
def test_theta_max_is_the_tangent_from_the_far_tip(lamina, delta, arrangement):
    """At θ_max disk 1 stands vertical and the ground passes through disk 2's far tip: the
    tangent from that tip T to disk 1 in its plane (root of (r − T) × r′ by brentq, 1e-12)."""
    body = ContactSolver(lamina, delta, arrangement)
    _, y_min, y_max = lamina.extents
    tip = 2 * delta + (y_max if arrangement == 'parallel' else -y_min)

    def cross(s):
        r = lamina.point(s)
        t = _rim_tangent(lamina, s, 1e-6)
        return r[0] * t[1] - (r[1] - tip) * t[0]
    s = brentq(cross, np.pi / 2 * 0.5, np.pi * (1 - 1e-9), xtol=1e-14)
    r = lamina.point(s)
    assert body.theta_max == pytest.approx(math.atan2(r[0], -r[1]), abs=1e-9)
    geo = body.geometry(body.theta_max)
    assert abs(float(geo.ground_normal[2])) <= 1e-7
    b_o = geo.contact_b + body.centroid
    assert b_o[1] == pytest.approx(tip - delta, abs=1e-7 * body.size)
    # across the tip B moves like τ^(1/(n−1)) at a superellipse's flat vertex, and τ at the
    # turning point is known to ~√ε: 1e-4 of the size for n = 4 (1e-7 where curved)
    assert abs(b_o[2]) <= 1e-3 * body.size
    with pytest.raises(ValueError):
        body.geometry(body.theta_max * (1 + 1e-9))


@pytest.mark.parametrize('lamina, delta', OTHER_SHAPES, ids=OTHER_IDS)
def test_symmetries(lamina, delta):
    """Mirrors x1 → −x1 (θ → −θ) and x3 → −x3 (branch), to rounding (1e-13); the swapped body
    is invariant under the disk swap (x1, x2, x3) ↦ (x3, −x2, x1): (θ, ψ) ↦ (−ψ, −θ)."""
    theta = np.linspace(-0.98, 0.98, 25)
    for arrangement in ('parallel', 'swapped'):
        body = ContactSolver(lamina, delta, arrangement)
        th = theta * body.theta_max
        up, down, left = body.geometry(th, 1), body.geometry(th, -1), body.geometry(-th, 1)
        flip1, flip3 = np.array([-1.0, 1, 1]), np.array([1.0, 1, -1])
        np.testing.assert_allclose(down.psi, -up.psi, atol=1e-13)
        np.testing.assert_allclose(left.psi, up.psi, atol=1e-13)
        for name in ('contact_a', 'contact_b', 'ground_normal'):
            np.testing.assert_allclose(getattr(down, name), getattr(up, name) * flip3,
                                       atol=1e-13 * body.size)
            np.testing.assert_allclose(getattr(left, name), getattr(up, name) * flip1,
                                       atol=1e-13 * body.size)
        np.testing.assert_allclose(down.height, up.height, atol=1e-13 * body.size)
    swap = np.array([[0.0, 0, 1], [0, -1, 0], [1, 0, 0]])
    # θ near 0 maps to ψ near 0, the turning point, where the θ chart is ill-conditioned
    geo = body.geometry(body.theta_max * AWAY_FROM_ZERO, 1)   # swapped body, branch +1
    assert body.psi_max == pytest.approx(body.theta_max, abs=1e-12)
    image = body.geometry(-geo.psi, np.where(geo.ground_normal[:, 0] < 0, -1, 1))
    np.testing.assert_allclose(image.psi, -geo.theta, atol=1e-12)
    np.testing.assert_allclose(image.ground_normal, geo.ground_normal @ swap.T, atol=1e-12)
    np.testing.assert_allclose(image.contact_a, geo.contact_b @ swap.T, atol=1e-12 * body.size)
    np.testing.assert_allclose(image.height, geo.height, atol=1e-12 * body.size)


def test_egg_parallel_bodies_of_opposite_eggs_are_one_body_turned():
    """Egg(ε) and Egg(−ε) in the parallel arrangement are the same body turned by the disk
    swap, so (θ, ψ) ↦ (−ψ, −θ) maps one's poses to the other's; G is off the centres."""
    one = ContactSolver(Egg(1.3, 1.0, 0.08), 0.5)
    other = ContactSolver(Egg(1.3, 1.0, -0.08), 0.5)
    assert one.centroid[1] > 0 > other.centroid[1]   # G towards the blunt ends
    geo = one.geometry(one.theta_max * AWAY_FROM_ZERO)
    assert one.psi_max == pytest.approx(other.theta_max, abs=1e-12)
    image = other.geometry(-geo.psi, np.where(geo.ground_normal[:, 0] < 0, -1, 1))
    np.testing.assert_allclose(image.psi, -geo.theta, atol=1e-12)
    np.testing.assert_allclose(image.height, geo.height, atol=1e-12 * one.size)


def test_superellipse_converges_to_the_ellipse():
    """Superellipse n → 2: pose differences shrink like n − 2; n = 2 is the ellipse (1e-13)."""
    theta = np.linspace(-0.95, 0.95, 21)
    ref = ContactSolver(Ellipse(1.0, 0.7), 0.4)
    errors = []
    for excess in (0.0, 1e-2, 1e-3, 1e-4):
        body = ContactSolver(Superellipse(1.0, 0.7, 2.0 + excess), 0.4)
        th = theta * min(body.theta_max, ref.theta_max)
        got, want = body.geometry(th, 1), ref.geometry(th, 1)
        errors.append(max(np.max(np.abs(got.height - want.height)),
                          np.max(np.abs(got.contact_b - want.contact_b)),
                          abs(body.theta_max - ref.theta_max)))
    assert errors[0] <= 1e-13
    for excess, error in zip((1e-2, 1e-3, 1e-4), errors[1:]):
        assert 1e-3 * excess < error < 1.0 * excess   # first order in n − 2, not faster


@pytest.mark.parametrize('args, match', [
    ((Ellipse(1.0, 1.0), 1.0), 'delta must be <'),
    ((Ellipse(1.0, 1.0), 0.0), 'delta must be'),
    ((Ellipse(1.0, 1.0), float('nan')), 'delta must be'),
    ((Ellipse(1.0, 1.0), 0.5, 'crossed'), 'arrangement must be'),
    (('ellipse', 0.5), 'lamina must be a Lamina'),
    ((Egg(1.0, 1.0, -0.1), 0.05, 'swapped'), 'no single rolling cycle'),
])
def test_refusals_are_one_line(args, match):
    with pytest.raises(ValueError, match=match) as info:
        ContactSolver(*args)
    assert '\n' not in str(info.value)


# -- the bracketing root finder -------------------------------------------------------------
def test_root_finder_pins_each_root_between_adjacent_floats_in_few_evaluations():
    """``_bisect`` (secant steps guarded by bisection): every returned r has the root between
    r and a neighbouring float, as evaluated (f(r) ≤ 0 < f(r⁺) or f(r⁻) ≤ 0 < f(r)), or
    f(r) = 0; roots at either end of the bracket (θ = 0 in ``parameter_of_theta``: plain
    bisection crept ~1075 steps to the subnormals) and the even form (f smooth in t²) too.
    References: the roots are cbrt(k) and sqrt(k) (to 16 ulps: the root as evaluated is within
    an ulp or two of the exact one); the evaluations are
    counted (plain bisection: ~55 per root, ~1075 with a root at 0)."""
    from twodisk_ros.physics.bodies.contact_solver import _bisect
    k = np.concatenate([[0.0, 8.0], np.linspace(1e-6, 7.9, 97)])
    calls = []

    def cubic(x):
        calls.append(1)
        return x**3 - k

    root = _bisect(cubic, np.zeros_like(k), np.full_like(k, 2.0))
    assert len(calls) <= 60, len(calls)     # 37 and 9 here; plain bisection 414
    below, above = np.nextafter(root, -np.inf), np.nextafter(root, np.inf)
    value = root**3 - k
    pinned = (value == 0) | ((value <= 0) & (above**3 - k > 0)) | (
        (value > 0) & (below**3 - k <= 0))
    assert np.all(pinned)
    np.testing.assert_allclose(root, np.cbrt(k), rtol=16 * np.finfo(float).eps, atol=0)
    calls.clear()

    def even(t):
        calls.append(1)
        return t * t - k

    root = _bisect(even, np.zeros_like(k), np.full_like(k, 3.0), even=True)
    assert len(calls) <= 60, len(calls)     # 37 and 9 here; plain bisection 414
    np.testing.assert_allclose(root, np.sqrt(k), rtol=16 * np.finfo(float).eps, atol=0)

"""Lamina.vertex (laminae/shapes.py): extent, radius of curvature and order of contact at the vertices.

References: the ellipse's and the egg's closed forms written here (b²/a, a²/b, b²/a ∓ 8ε,
a ± ε, the egg's widest point at y = 3ε); for the superellipse, the support function taken by
brute force from boundary points (max of r·d over the curve, refined by minimize_scalar),
which shares nothing with the closed-form h of the class; for a fitted outline, the circle
through three close boundary points.
"""

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from rounding import ulps
from twodisk_ros.physics.laminae.shapes import Ellipse, Lamina, Superellipse
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.physics.laminae.fit import Outline
from twodisk_ros.physics.stability.symmetric import symmetric_equilibria


@pytest.mark.parametrize('a, b', [(2.0, 1.0), (1.0, 3.0), (1.0, 1.0)])
def test_ellipse_vertices(a, b):
    for lamina in (Ellipse(a, b), Superellipse(a, b, 2.0)):
        for axis, extent, radius, point in (('-y', a, b * b / a, (0, -a)),
                                            ('+y', a, b * b / a, (0, a)),
                                            ('+x', b, a * a / b, (b, 0))):
            v = lamina.vertex(axis)
            # claim: closed forms to rounding (16 ulps)
            assert v.extent == pytest.approx(extent, rel=ulps(16))
            assert v.radius == pytest.approx(radius, rel=1e-14)
            assert (v.order, v.coefficient) == (2.0, pytest.approx(radius / 2, rel=1e-14))
            np.testing.assert_allclose(v.point, point, rtol=0, atol=ulps(16, max(a, b)))


@pytest.mark.parametrize('epsilon', [0.08, -0.05, 0.0])
def test_egg_vertices(epsilon):
    a, b = 1.3, 1.0
    lamina = Egg(a, b, epsilon)
    expected = {'-y': (a + epsilon, b * b / a - 8 * epsilon),
                '+y': (a - epsilon, b * b / a + 8 * epsilon), '+x': (b, a * a / b)}
    for axis, (extent, radius) in expected.items():
        v = lamina.vertex(axis)
        assert v.extent == pytest.approx(extent, rel=ulps(16))
        assert v.radius == pytest.approx(radius, rel=1e-14)
    # the widest point, by brute force over the boundary: y = 3ε
    s = np.linspace(0.0, np.pi, 20001)
    j = int(np.argmax(lamina.point(s)[:, 0]))
    found = minimize_scalar(lambda x: -float(lamina.point(x)[0]), method='bounded',
                            bounds=(s[j - 1], s[j + 1]), options={'xatol': 1e-12})
    assert float(lamina.point(found.x)[1]) == pytest.approx(3 * epsilon, abs=1e-6)
    assert float(lamina.vertex('+x').point[1]) == pytest.approx(3 * epsilon,
                                                                abs=ulps(16, lamina.size))


def _support_by_points(lamina, direction):
    """max over the boundary of r·d, from boundary points alone (grid, then refined)."""
    s = np.linspace(-np.pi, np.pi, 40001)
    values = lamina.point(s) @ direction
    j = int(np.argmax(values))
    found = minimize_scalar(lambda x: -float(lamina.point(x) @ direction), method='bounded',
                            bounds=(s[j - 1], s[j + 1]), options={'xatol': 1e-14})
    return max(float(values[j]), -float(found.fun))


@pytest.mark.parametrize('n', [2.5, 4.0, 10.0, 100.0])
@pytest.mark.parametrize('axis', ['-y', '+x'])
def test_superellipse_flat_vertex_order_and_coefficient(n, axis):
    lamina = Superellipse(1.0, 0.6, n)
    v = lamina.vertex(axis)
    assert v.radius == math.inf and v.order == pytest.approx(n / (n - 1), rel=ulps(16))
    d, d_perp = np.array(v.direction), np.array([-v.direction[1], v.direction[0]])
    excess = {}
    for t in (1e-2, 1e-3):
        excess[t] = _support_by_points(lamina, d + t * d_perp) - v.extent
        # claim: h = e + c|t|^q + O(|t|^2q): relative remainder ≤ (1/q)·(c/e)|t|^q (the next
        # term of (1 + x)^(1/q)), plus the brute force's rounding (16 ulps of e, / (c|t|^q))
        relative = v.coefficient / v.extent * t**v.order / v.order
        rounding = ulps(16, v.extent) / (v.coefficient * t**v.order)
        assert excess[t] == pytest.approx(v.coefficient * t**v.order, rel=relative + rounding)
    slope = math.log(excess[1e-2] / excess[1e-3]) / math.log(10.0)
    assert slope == pytest.approx(v.order, abs=1e-2)


def test_outline_vertex_radius_from_three_points():
    lamina = Outline([1.0, 0.05, 0.1, 0.02, 0.01])
    for axis, phi in (('-y', 0.0), ('+y', math.pi), ('+x', math.pi / 2)):
        v = lamina.vertex(axis)
        p0, p1, p2 = lamina.point(np.array([phi - 1e-4, phi, phi + 1e-4]))
        # circumradius |p0p1||p1p2||p2p0| / (2 |cross|); truncation ~(1e-4)², rounding 1e-8
        sides = [np.linalg.norm(p1 - p0), np.linalg.norm(p2 - p1), np.linalg.norm(p0 - p2)]
        cross = abs((p1 - p0)[0] * (p2 - p0)[1] - (p1 - p0)[1] * (p2 - p0)[0])
        assert v.radius == pytest.approx(np.prod(sides) / (2 * cross), rel=1e-6)
        assert v.extent == pytest.approx(float(np.dot(v.point, v.direction)), rel=ulps(16))


class _NoOrder(Superellipse):
    """A superellipse that, like a generic lamina, does not say how flat its vertices are."""

    vertex = Lamina.vertex


def test_refusals_are_one_line():
    for make, words in ((lambda: Ellipse(1, 1).vertex('x'), 'axis must be one of'),
                        (lambda: _NoOrder(1, 1, 4).vertex('+x'), r'flat at its \+x vertex'),
                        (lambda: symmetric_equilibria(_NoOrder(1, 1, 4), 0.5), 'flat at its')):
        with pytest.raises(ValueError, match=words) as info:
            make()
        assert '\n' not in str(info.value)

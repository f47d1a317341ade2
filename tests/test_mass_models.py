"""Tests of :mod:`twodisk_ros.physics.mass_models` against independent references.

Body frame ``G e1 e2 e3`` (m): disk 1 in ``x3 = 0`` centred at ``(0, -delta, 0)``, disk 2 in
``x1 = 0`` centred at ``(0, +delta, 0)``, semi-axis ``a`` along e2 and ``b`` across.
References used here never come from the code under test: closed forms from the literature
(oloid volume and area), the closed-form limit ``delta -> 0``, ``scipy.integrate.dblquad`` over
the ellipses, and the convex hull (``scipy.spatial.ConvexHull``) of points sampled on the two
ellipses, split into tetrahedra with exact moments.
"""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import dblquad
from scipy.spatial import ConvexHull
from scipy.special import ellipe, ellipk

from twodisk_ros.physics import hull, mass_models
from twodisk_ros.physics.mass_models import MassProperties, custom, laminae, mass_properties, solid_hull

# Oloid volume / r**3 = (2/3) (2 E(m) + K(m)) with parameter m = 3/4 (Dirnboeck & Stachel 1997,
# "The development of the oloid"; numerically 3.0524184684...). Its surface area is 4 pi r**2.
OLOID_VOLUME = 2.0 / 3.0 * (2.0 * ellipe(0.75) + ellipk(0.75))

# (a, b, delta) in m: Oloid, Two-Circle-Roller, b > a, small delta, delta close to a, b << a.
BODIES = [
    (1.0, 1.0, 0.5),
    (1.0, 1.0, 1.0 / math.sqrt(2.0)),
    (0.8, 2.0, 0.3),
    (1.0, 0.7, 0.01),
    (0.5, 0.5, 0.495),
    (2.0, 0.1, 1.2),
]
EXTREMES = [
    (1.0, 0.01, 1e-3),
    (1.0, 100.0, 1e-3),
    (1.0, 0.01, 1.0 - 1e-6),
    (1.0, 100.0, 1.0 - 1e-6),
]


def sampled_hull_moments(a, b, delta, n):
    """Volume (m**3) and second moments ``int x x^T dV`` (m**5) of a sampled hull.

    Parameters
    ----------
    a, b, delta : float
        Geometry (m), body frame as in the module docstring.
    n : int
        Number of equally spaced samples (in the ellipse angle) on each boundary ellipse.

    Returns
    -------
    volume : float
        Volume of the convex hull of the samples (an inscribed polytope).
    second : numpy.ndarray, shape (3, 3)
        Its second moments about G, from tetrahedra (G, facet) with the exact formula
        ``int_T x x^T dV = vol / 20 (sum_k v_k v_k^T + s s^T)``, ``s = sum_k v_k``.
    """
    t = 2.0 * np.pi * np.arange(n) / n
    zero = np.zeros(n)
    disk1 = np.stack([b * np.sin(t), -delta - a * np.cos(t), zero], axis=-1)
    disk2 = np.stack([zero, delta + a * np.cos(t), b * np.sin(t)], axis=-1)
    hull = ConvexHull(np.vstack([disk1, disk2]))
    tri = hull.points[hull.simplices]  # (m, 3 vertices, 3 coordinates); G is inside the hull
    vol = np.abs(np.einsum('ij,ij->i', tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0
    s = tri.sum(axis=1)
    second = np.einsum('i,ijk,ijl->kl', vol / 20.0, tri, tri)
    second += np.einsum('i,ik,il->kl', vol / 20.0, s, s)
    return vol.sum(), second


def second_moments(props):
    """Second moments ``int x x^T dm`` (kg m**2) from an inertia tensor about G."""
    inertia = props.inertia
    return 0.5 * np.trace(inertia) * np.eye(3) - inertia


# ----------------------------------------------------------------------------- the solid


def test_oloid_volume_matches_closed_form():
    props = solid_hull(1.0, 1.0, 0.5, 1.0)
    assert props.model == 'solid'
    assert_allclose(props.volume, OLOID_VOLUME, rtol=1e-8)
    assert_allclose(props.volume, 3.0524184684, rtol=1e-10)
    assert props.relative_error <= 1e-9


def test_oloid_surface_area_is_that_of_the_sphere():
    # Checks the ruled surface (both sheets, both ends) that the solid is built from.
    for r in (1.0, 0.04):
        area = hull.hull_surface_area(r, r, r / 2.0, n=256)
        assert_allclose(area, 4.0 * np.pi * r * r, rtol=1e-12)


def test_oloid_scaling():
    ref = solid_hull(1.0, 1.0, 0.5, 1.0)
    for r, mass in ((0.037, 2.5), (3.0, 0.2)):
        props = solid_hull(r, r, r / 2.0, mass)
        assert_allclose(props.volume, OLOID_VOLUME * r ** 3, rtol=1e-8)
        assert_allclose(props.inertia, ref.inertia * mass * r * r, rtol=1e-12,
                        atol=1e-14 * mass * r * r)
        lam = laminae(r, r, r / 2.0, mass)
        assert_allclose(lam.inertia, laminae(1.0, 1.0, 0.5, 1.0).inertia * mass * r * r,
                        rtol=1e-14)


@pytest.mark.parametrize('a, b, delta', BODIES + EXTREMES)
def test_solid_symmetries(a, b, delta):
    props = solid_hull(a, b, delta, 2.0)
    inertia = props.inertia
    scale = np.sqrt(np.diag(inertia))
    # Disk-swap symmetry (x1, x2, x3) -> (x3, -x2, x1) and the reflections x1 -> -x1, x3 -> -x3.
    assert_allclose(props.center_of_mass, 0.0, atol=1e-12 * max(a, b))
    assert_allclose(inertia[0, 0], inertia[2, 2], rtol=1e-11)
    off = inertia / np.outer(scale, scale) - np.eye(3)
    assert_allclose(off, 0.0, atol=1e-12)
    assert props.relative_error <= 1e-9
    assert props.mass == 2.0


@pytest.mark.parametrize('a, b, delta', BODIES)
def test_solid_matches_sampled_convex_hull(a, b, delta):
    props = solid_hull(a, b, delta, 1.0)
    second = second_moments(props) * props.volume / props.mass
    v1, s1 = sampled_hull_moments(a, b, delta, 800)
    v2, s2 = sampled_hull_moments(a, b, delta, 1600)
    # The sampled hull is inscribed: strictly smaller, with an error ~ 1/n**2 (~3e-6 here).
    assert v1 < v2 < props.volume
    assert_allclose(v2, props.volume, rtol=2e-5)
    assert_allclose(np.diag(s2), np.diag(second), rtol=2e-5)
    # Richardson extrapolation of the 1/n**2 term leaves ~2e-7 (the arc ends are not nodes).
    assert_allclose((4.0 * v2 - v1) / 3.0, props.volume, rtol=2e-6)
    scale = np.sqrt(np.outer(np.diag(second), np.diag(second)))
    assert_allclose((4.0 * s2 - s1) / 3.0 / scale, second / scale, atol=2e-6)


@pytest.mark.parametrize('a, b', [(1.0, 1.0), (1.0, 0.3), (0.5, 4.0)])
def test_solid_limit_of_coinciding_centres(a, b):
    # delta -> 0: the hull is {|x1| + |x3| <= b sqrt(1 - x2**2 / a**2)} (its slices are the
    # squares spanned by the two chords, and this set is already convex), so
    # V = 8 a b**2 / 3, int x1**2 dV = int x3**2 dV = 16 a b**4 / 45 and
    # int x2**2 dV = 8 a**3 b**2 / 15. The change is O(delta**2), ~1e-11 here.
    props = solid_hull(a, b, 1e-6 * a, 1.0, rtol=1e-11)
    volume = 8.0 * a * b * b / 3.0
    assert_allclose(props.volume, volume, rtol=1e-9)
    second = second_moments(props) * props.volume / props.mass
    expected = np.diag([16.0 * a * b ** 4 / 45.0, 8.0 * a ** 3 * b * b / 15.0,
                        16.0 * a * b ** 4 / 45.0])
    assert_allclose(second, expected, rtol=1e-9, atol=1e-12 * np.max(expected))


@pytest.mark.parametrize('a, b, delta', EXTREMES + [(1.0, 1.0, 0.5)])
def test_solid_extremes_converge(a, b, delta):
    # (its cost is measured in benchmarks: `make bench`, docs/benchmarks.md)
    props = solid_hull(a, b, delta, 1.0, rtol=1e-9)
    assert props.relative_error <= 1e-9
    # A tighter tolerance only refines the result within the looser one.
    fine = solid_hull(a, b, delta, 1.0, rtol=1e-12)
    assert fine.relative_error <= 1e-12
    assert_allclose(props.volume, fine.volume, rtol=1e-9)
    assert_allclose(np.diag(props.inertia), np.diag(fine.inertia), rtol=1e-9)


def test_solid_extremes_match_sampled_convex_hull():
    for a, b, delta in EXTREMES:
        props = solid_hull(a, b, delta, 1.0)
        second = second_moments(props) * props.volume / props.mass
        volume, sampled = sampled_hull_moments(a, b, delta, 1000)
        assert volume < props.volume
        assert_allclose(volume, props.volume, rtol=3e-5)
        assert_allclose(np.diag(sampled), np.diag(second), rtol=5e-5)


def test_solid_unreachable_tolerance_raises():
    with pytest.raises(RuntimeError, match='cannot reach rtol'):
        solid_hull(1.0, 1.0, 0.5, 1.0, rtol=1e-17)


@settings(max_examples=25, deadline=None)
@given(
    a=st.floats(1e-3, 1e3),
    b_over_a=st.floats(0.01, 100.0),
    delta_over_a=st.floats(1e-3, 1.0 - 1e-6),
    mass=st.floats(1e-3, 1e3),
)
def test_solid_invariants(a, b_over_a, delta_over_a, mass):
    b, delta = a * b_over_a, a * delta_over_a
    props = solid_hull(a, b, delta, mass)
    inertia = props.inertia
    moments = np.linalg.eigvalsh(inertia)
    assert np.all(moments > 0.0)
    i1, i2, i3 = np.diag(inertia)
    assert i1 + i2 > i3 and i2 + i3 > i1 and i3 + i1 > i2  # strict for a solid
    assert_allclose(i1, i3, rtol=1e-11)
    assert_allclose(inertia, inertia.T, rtol=0, atol=1e-15 * i1)
    assert props.relative_error <= 1e-9
    # Inscribed sampled polytope <= hull <= bounding box [-b, b] x [-a-delta, a+delta] x [-b, b].
    coarse, _ = sampled_hull_moments(a, b, delta, 64)
    assert coarse < props.volume < 8.0 * b * b * (a + delta)
    # The body is convex and symmetric in x1, x2, x3 (x2 via the disk swap), so each marginal
    # density is unimodal (Brunn-Minkowski): mean x_i**2 <= half-width**2 / 3.
    second = second_moments(props) / mass
    assert second[0, 0] <= b * b / 3.0 and second[2, 2] <= b * b / 3.0
    assert second[1, 1] <= (a + delta) ** 2 / 3.0


# ----------------------------------------------------------------------------- laminae


def lamina_second_moments(a, b, delta, mass):
    """Second moments ``int x x^T dm`` (kg m**2) of the two laminae by dblquad."""
    density = 0.5 * mass / (np.pi * a * b)  # kg / m**2 on each disk

    def half_width(y, centre):
        return b * math.sqrt(max(0.0, 1.0 - ((y - centre) / a) ** 2))

    def integrate(func, centre):
        value, _ = dblquad(func, centre - a, centre + a, lambda y: -half_width(y, centre),
                           lambda y: half_width(y, centre), epsabs=1e-13, epsrel=1e-11)
        return density * value

    second = np.zeros((3, 3))
    # Disk 1: points (x1, x2, 0); dblquad integrates func(inner=x1, outer=x2).
    second[0, 0] += integrate(lambda x1, x2: x1 * x1, -delta)
    second[1, 1] += integrate(lambda x1, x2: x2 * x2, -delta)
    second[0, 1] += integrate(lambda x1, x2: x1 * x2, -delta)
    # Disk 2: points (0, x2, x3); inner = x3, outer = x2.
    second[2, 2] += integrate(lambda x3, x2: x3 * x3, delta)
    second[1, 1] += integrate(lambda x3, x2: x2 * x2, delta)
    second[1, 2] += integrate(lambda x3, x2: x2 * x3, delta)
    second[1, 0], second[2, 1] = second[0, 1], second[1, 2]
    return second


@pytest.mark.parametrize('a, b, delta, mass', [
    (1.0, 1.0, 0.5, 1.0),
    (0.8, 2.0, 0.3, 0.25),
    (2.0, 0.1, 1.9, 3.0),
])
def test_laminae_match_direct_integration(a, b, delta, mass):
    second = lamina_second_moments(a, b, delta, mass)
    expected = np.trace(second) * np.eye(3) - second
    props = laminae(a, b, delta, mass)
    assert props.model == 'laminae' and props.volume is None and props.relative_error == 0.0
    assert_allclose(props.inertia, expected, rtol=1e-9, atol=1e-12 * np.max(expected))
    assert_allclose(props.center_of_mass, 0.0, atol=0.0)
    # The formula of the task statement, literally.
    i11 = mass * (2 * a * a + b * b) / 8 + mass * delta * delta
    assert_allclose(np.diag(props.inertia), [i11, mass * b * b / 4, i11], rtol=1e-14)


@settings(max_examples=200, deadline=None)
@given(
    a=st.floats(1e-4, 1e4),
    b_over_a=st.floats(0.01, 100.0),
    delta_over_a=st.floats(1e-6, 1.0 - 1e-9),
    mass=st.floats(1e-4, 1e4),
)
def test_laminae_invariants(a, b_over_a, delta_over_a, mass):
    props = laminae(a, a * b_over_a, a * delta_over_a, mass)
    inertia = props.inertia
    assert np.all(np.linalg.eigvalsh(inertia) > 0.0)
    i1, i2, i3 = np.diag(inertia)
    assert i1 == i3
    assert i1 + i2 >= i3 and i2 + i3 >= i1 and i3 + i1 >= i2
    assert np.count_nonzero(inertia - np.diag(np.diag(inertia))) == 0


# ----------------------------------------------------------------------------- custom, dispatch


def test_custom_and_dispatch():
    props = custom(2.0, (0.3, 0.2, 0.3))
    assert props.model == 'custom' and props.volume is None
    assert_allclose(props.inertia, np.diag([0.3, 0.2, 0.3]), rtol=0)
    assert_allclose(props.center_of_mass, np.zeros(3), atol=0)
    assert_allclose(props.principal_moments, [0.3, 0.2, 0.3], rtol=0)
    # A flat plate sits on the edge of the triangle inequality; rounding must not reject it.
    custom(1.0, (0.1, 0.2, 0.1 + 0.2))
    moments = [0.3, 0.2, 0.3]
    assert mass_properties('custom', 1.0, 1.0, 0.5, 2.0, principal_moments=moments) == props
    assert mass_properties('laminae', 1.0, 1.0, 0.5, 2.0) == laminae(1.0, 1.0, 0.5, 2.0)
    solid = mass_properties('solid', 1.0, 1.0, 0.5, 2.0, rtol=1e-10)
    assert solid.model == 'solid' and solid.relative_error <= 1e-10
    assert_allclose(solid.volume, OLOID_VOLUME, rtol=1e-10)


def test_mass_properties_is_immutable():
    props = laminae(1.0, 1.0, 0.5, 1.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        props.mass = 2.0
    with pytest.raises(ValueError):
        props.inertia[0, 0] = 1.0
    assert props != laminae(1.0, 1.0, 0.5, 2.0)


NAN, INF = float('nan'), float('inf')


@pytest.mark.parametrize('kwargs, words', [
    ({'mass': -1.0}, ['mass must be finite and > 0 kg, got -1.0']),
    ({'mass': 0}, ['mass', '> 0 kg', 'got 0.0']),
    ({'mass': NAN}, ['mass', 'got nan']),
    ({'mass': 'heavy'}, ['mass must be a real number', "got 'heavy'"]),
    ({'mass': True}, ['mass', 'got True']),
    ({'a': 0.0}, ['a must be finite and > 0 m, got 0.0']),
    ({'a': INF}, ['a must', 'got inf']),
    ({'a': [1.0, 2.0]}, ['a must be a real number', 'got [1.0, 2.0]']),
    ({'b': -0.5}, ['b must be finite and > 0 m, got -0.5']),
    ({'delta': 0.0}, ['delta must be', '0 < delta < a = 1.0 m', 'got 0.0']),
    ({'delta': 1.0}, ['delta must be', 'got 1.0']),
    ({'delta': -0.2}, ['delta must be', 'got -0.2']),
    ({'delta': NAN}, ['delta must be', 'got nan']),
    ({'model': 'oloid'}, ["model must be one of 'laminae', 'solid', 'custom', got 'oloid'"]),
    ({'model': None}, ['model must be one of', 'got None']),
    ({'model': 'solid', 'rtol': 0.0}, ['rtol must be', '0 < rtol < 1', 'got 0.0']),
    ({'model': 'solid', 'rtol': 1.0}, ['rtol must be', 'got 1.0']),
    ({'model': 'solid', 'rtol': NAN}, ['rtol must be', 'got nan']),
    ({'model': 'custom'}, ['principal_moments must be given', "'custom'", 'got None']),
    ({'model': 'laminae', 'principal_moments': (1, 1, 1)},
     ['principal_moments must be None', "model 'laminae'", 'got (1, 1, 1)']),
    ({'model': 'custom', 'principal_moments': (1.0, 1.0, 3.0)},
     ['principal_moments must satisfy the triangle inequalities', 'got (1.0, 1.0, 3.0)',
      'I1 + I2 = 2.0 < I3 = 3.0']),
    ({'model': 'custom', 'principal_moments': (3.0, 1.0, 1.0)},
     ['triangle inequalities', 'I2 + I3 = 2.0 < I1 = 3.0']),
    ({'model': 'custom', 'principal_moments': (1.0, -1.0, 1.0)},
     ['principal_moments must be', '> 0 kg m**2', 'got (1.0, -1.0, 1.0)']),
    ({'model': 'custom', 'principal_moments': (1.0, NAN, 1.0)},
     ['principal_moments must be', 'got (1.0, nan, 1.0)']),
    ({'model': 'custom', 'principal_moments': (1.0, 2.0)},
     ['principal_moments must be a sequence of 3', 'got (1.0, 2.0)']),
    ({'model': 'custom', 'principal_moments': np.ones((3, 3))},
     ['principal_moments must be a sequence of 3', 'got array(']),
])
def test_invalid_input_gives_one_line_value_error(kwargs, words):
    args = {'model': 'laminae', 'a': 1.0, 'b': 1.0, 'delta': 0.5, 'mass': 1.0, **kwargs}
    with pytest.raises(ValueError) as info:
        mass_properties(**args)
    message = str(info.value)
    assert '\n' not in message
    for word in words:
        assert word in message


@pytest.mark.parametrize('call', [
    lambda: laminae(1.0, 1.0, 1.5, 1.0),
    lambda: solid_hull(1.0, 1.0, 0.5, -2.0),
    lambda: solid_hull(1.0, 1.0, 0.5, 1.0, rtol=-1e-9),
    lambda: custom(0.0, (1.0, 1.0, 1.0)),
    lambda: custom(1.0, 'abc'),
    lambda: MassProperties('custom', 1.0, np.zeros(2), np.eye(3)),
])
def test_direct_calls_validate(call):
    with pytest.raises(ValueError) as info:
        call()
    assert '\n' not in str(info.value)

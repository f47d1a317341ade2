"""Tests of :mod:`twodisk_ros.physics.mass.models` against independent references.

Body frame ``G e1 e2 e3`` (m): disk 1 in ``x3 = 0`` centred at ``(0, -delta, 0)``, disk 2 in
``x1 = 0`` centred at ``(0, +delta, 0)``, semi-axis ``a`` along e2 and ``b`` across.
References used here never come from the code under test: closed forms from the literature
(oloid volume and area), the closed-form limit ``delta -> 0``, Green's theorem on each disk's
rim (exact for the laminae, and it integrates each disk on its own, so I1 = I3 is a result),
and for the solid the convex hull (``scipy.spatial.ConvexHull``) of points sampled on the two
ellipses, split into tetrahedra with exact moments, extrapolated in the number of samples.
Each tolerance names the accuracy claim of docs/physics.md it checks.
"""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.spatial import ConvexHull
from scipy.special import ellipe, ellipk

from rounding import ulps
from twodisk_ros.physics.mass import hull, models as mass_models
from twodisk_ros.physics.mass.models import (MassProperties, custom, laminae, mass_properties,
                                             solid_hull)

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


def ruled_polytope_moments(a, b, delta, n):
    """Volume (m**3) and ``int x_i**2 dV`` (m**5) of a polytope inscribed in the hull.

    Parameters
    ----------
    a, b, delta : float
        Geometry (m), body frame as in the module docstring.
    n : int
        Number of samples: ``t = t_max sin(2 pi k / n)`` on the arc of ellipse 1 that bounds
        the hull (``cos t_max = -a / (a + 2 delta)``), and for each the point of ellipse 2
        whose tangent line passes where the tangent of ellipse 1 meets the common axis (the
        polar line of that point), on both sides ``x3 = +-``.

    Returns
    -------
    numpy.ndarray, shape (4,)
        Volume and the diagonal second moments about G of the convex hull of the samples
        (``scipy.spatial.ConvexHull``), from tetrahedra (G, facet) with the exact formula
        ``int_T x x^T dV = vol / 20 (sum_k v_k v_k^T + s s^T)``, ``s = sum_k v_k``.

    Notes
    -----
    Every sample lies on the two rims, so the polytope is inscribed. Sampling the two rims at
    matching points (the ends of the hull's rulings) makes its error a smooth function of
    ``h = 2 pi / n``: measured ``c2 h**2 + c3 h**3 + ...``, which :func:`hull_reference`
    extrapolates away.
    """
    t_max = math.acos(-a / (a + 2.0 * delta))
    u = 2.0 * np.pi * np.arange(n) / n
    t = t_max * np.sin(u)
    c = np.cos(t)
    denominator = a + 2.0 * delta * c
    # (x2 - delta) / a = -a c / D on ellipse 2; 1 - ((x2 - delta) / a)**2 in factored form, the
    # factor cos t - cos t_max without cancellation near the ends of the arc.
    gap = 2.0 * np.sin(0.5 * (t_max + np.abs(t))) * np.sin(0.5 * (t_max - np.abs(t)))
    one_minus_r2 = (a + 2.0 * delta) * gap * (a - (a - 2.0 * delta) * c) / denominator ** 2
    sheet = np.where(np.cos(u) >= 0.0, 1.0, -1.0)
    zero = np.zeros(n)
    disk1 = np.stack([b * np.sin(t), -delta - a * c, zero], axis=-1)
    disk2 = np.stack([zero, delta - a * a * c / denominator,
                      sheet * b * np.sqrt(np.maximum(one_minus_r2, 0.0))], axis=-1)
    hull = ConvexHull(np.vstack([disk1, disk2]))
    tri = hull.points[hull.simplices]  # (m, 3 vertices, 3 coordinates); G is inside the hull
    vol = np.abs(np.einsum('ij,ij->i', tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0
    s = tri.sum(axis=1)
    second = (np.einsum('i,ijk,ijk->k', vol / 20.0, tri, tri)
              + np.einsum('i,ik,ik->k', vol / 20.0, s, s))
    return np.concatenate([[vol.sum()], second])


def hull_reference(a, b, delta, levels):
    """Richardson-extrapolated volume and ``int x_i**2 dV`` of the hull, and their error.

    The inscribed polytopes of :func:`ruled_polytope_moments` at ``n`` and ``2 n`` samples
    are combined to cancel the ``h**2``, ``h**3``, ``h**4``, ``h**5`` terms in turn.

    Returns
    -------
    value : numpy.ndarray, shape (4,)
        Volume (m**3) and ``int x1**2 dV``, ``int x2**2 dV``, ``int x3**2 dV`` (m**5).
    error : float
        Relative change when the coarsest level is dropped: an upper estimate of the error
        (measured with 256 to 4096 samples: <= 6.5e-14 for delta / a >= 0.3; with 128 to 2048:
        2e-12 to 7.4e-11, and 3e-10 at delta / a = 1e-3).
    """
    table = [ruled_polytope_moments(a, b, delta, n) for n in levels]
    columns = [table]
    for power in (2, 3, 4, 5)[:len(levels) - 1]:
        factor = 2.0 ** power
        previous = columns[-1]
        columns.append([(factor * fine - coarse) / (factor - 1.0)
                        for coarse, fine in zip(previous[:-1], previous[1:])])
    value = columns[-1][0]
    error = float(np.max(np.abs(columns[-2][-1] / value - 1.0)))
    return value, error


def second_moments(props):
    """Second moments ``int x x^T dm`` (kg m**2) from an inertia tensor about G."""
    inertia = props.inertia
    return 0.5 * np.trace(inertia) * np.eye(3) - inertia


# ----------------------------------------------------------------------------- tolerances
# Each states the accuracy claim of docs/physics.md (section "Mass models", and "Accuracy and
# its limits") that it checks, and what was measured on this machine.

#: The Oloid's volume against its closed form: docs claim a relative 6e-16; measured 6.7e-16
#: (3 ulps; the trapezoidal sums are converged far below rounding). A sum of rounded terms:
#: 16 ulps.
OLOID_VOLUME_RTOL = ulps(16)
#: The Oloid's surface area against 4 pi r**2 (a check of the ruled surface): measured 6.7e-16;
#: a sum of rounded terms, 16 ulps.
OLOID_AREA_RTOL = ulps(16)
#: The solid depends on delta / a only and is mapped by diag(b, a, b) (docs): scaling is exact
#: up to rounding. Measured 6.7e-16 (volume), 9e-17 (inertia, of its largest moment): 16 ulps.
SCALING_RTOL = ulps(16)
#: Quantities that vanish or agree by the body's symmetries, which the quadrature keeps on its
#: grid (every grid is mapped onto itself by the disk swap): centre of mass (of the size),
#: products of inertia and I1 - I3 (of the moments). Measured <= 7e-16 over BODIES, EXTREMES
#: and the hypothesis range.
SYMMETRY_ATOL = 4e-15
#: The laminae model is exact (closed form); the reference is Green's theorem on the rims,
#: exact to rounding. Measured <= 8.9e-16 relative over 20 000 random bodies (a in
#: [1e-4, 1e4] m, b / a in [0.01, 100], delta / a in [1e-6, 1 - 1e-9]); products of inertia
#: 0 in the code, <= 6.4e-17 of the largest moment in the reference (its rounding). Sums of
#: rounded terms: 16 ulps (of each moment; of the largest for the products).
LAMINAE_RTOL = ulps(16)
LAMINAE_OFF_ATOL = ulps(16)


# ----------------------------------------------------------------------------- the solid


def test_oloid_volume_matches_closed_form():
    props = solid_hull(1.0, 1.0, 0.5, 1.0)
    assert props.model == 'solid'
    # docs/physics.md: the Oloid's volume is reproduced to a relative 6e-16
    assert_allclose(props.volume, OLOID_VOLUME, rtol=OLOID_VOLUME_RTOL)
    # the digits printed in docs/physics.md (11 significant digits: half a unit is 1.6e-11)
    assert_allclose(OLOID_VOLUME, 3.0524184684, rtol=1.7e-11)
    assert props.relative_error <= 1e-9


def test_oloid_surface_area_is_that_of_the_sphere():
    # Checks the ruled surface (both sheets, both ends) that the solid is built from.
    for r in (1.0, 0.04):
        area = hull.hull_surface_area(r, r, r / 2.0, n=256)
        assert_allclose(area, 4.0 * np.pi * r * r, rtol=OLOID_AREA_RTOL)


def test_oloid_scaling():
    ref = solid_hull(1.0, 1.0, 0.5, 1.0)
    unit_laminae = laminae(1.0, 1.0, 0.5, 1.0)
    for r, mass in ((0.037, 2.5), (3.0, 0.2)):
        props = solid_hull(r, r, r / 2.0, mass)
        assert_allclose(props.volume, OLOID_VOLUME * r ** 3, rtol=OLOID_VOLUME_RTOL)
        scale = mass * r * r
        assert_allclose(props.inertia, ref.inertia * scale, rtol=0,
                        atol=SCALING_RTOL * scale * np.max(ref.inertia))
        lam = laminae(r, r, r / 2.0, mass)
        assert_allclose(lam.inertia, unit_laminae.inertia * scale, rtol=0,
                        atol=SCALING_RTOL * scale * np.max(unit_laminae.inertia))


def check_symmetries(props, a, b):
    """Centre of mass at G, no products of inertia, I1 = I3 (module docstring)."""
    inertia = props.inertia
    assert_allclose(props.center_of_mass, 0.0, atol=SYMMETRY_ATOL * max(a, b))
    largest = np.max(np.diag(inertia))
    assert_allclose(inertia - np.diag(np.diag(inertia)), 0.0, atol=SYMMETRY_ATOL * largest)
    assert abs(inertia[0, 0] - inertia[2, 2]) <= SYMMETRY_ATOL * largest


@pytest.mark.parametrize('a, b, delta', BODIES + EXTREMES)
def test_solid_symmetries(a, b, delta):
    props = solid_hull(a, b, delta, 2.0)
    # Disk-swap symmetry (x1, x2, x3) -> (x3, -x2, x1) and the reflections x1 -> -x1, x3 -> -x3.
    check_symmetries(props, a, b)
    assert props.relative_error <= 1e-9
    assert props.mass == 2.0


def check_against_reference(a, b, delta, levels, reference_bound, rtols):
    """Volume and each second moment against :func:`hull_reference`, for each rtol."""
    reference, error = hull_reference(a, b, delta, levels)
    assert error <= reference_bound
    for rtol in rtols:
        # docs/physics.md: `solid` meets its rtol (floor about 1e-13). Each rtol checked here
        # is at least 2.5x the reference's measured error.
        props = solid_hull(a, b, delta, 1.0, rtol=rtol)
        assert props.relative_error <= rtol
        values = np.concatenate([[props.volume],
                                 np.diag(second_moments(props)) * props.volume / props.mass])
        assert np.max(np.abs(values / reference - 1.0)) <= rtol


REGULAR = [body for body in BODIES if body[2] >= 0.3 * body[0]]


@pytest.mark.parametrize('a, b, delta', REGULAR)
def test_solid_matches_extrapolated_inscribed_polytopes(a, b, delta):
    # Reference (256 to 4096 samples): error estimate <= 6.5e-14, and it differs from the
    # solid at rtol 1e-13 by <= 3.7e-14. So the volume, I1, I2 and I3 are each checked (I1 = I3
    # included, from different integrands) at the default rtol and at rtol 1e-12.
    check_against_reference(a, b, delta, (256, 512, 1024, 2048, 4096), 1e-13, (1e-9, 1e-12))


@pytest.mark.parametrize('a, b, delta', [body for body in BODIES if body not in REGULAR]
                         + EXTREMES)
def test_solid_small_delta_and_extremes_match_inscribed_polytopes(a, b, delta):
    # (the solid's cost is measured in benchmarks: `make bench`, docs/benchmarks.md)
    # Reference (128 to 2048 samples; Qhull slows down beyond): it differs from the solid at
    # rtol 1e-13 by 2.1e-11 (delta / a = 0.01), 3.7e-10 (1e-3: rulings sharp near the axis),
    # 7.2e-12 (1 - 1e-6 with b / a = 0.01: the reference's rounding; 1.5e-14 for b = a). Its
    # own estimate is <= 3.8e-10. So the default rtol 1e-9 is checked.
    check_against_reference(a, b, delta, (128, 256, 512, 1024, 2048), 4e-10, (1e-9,))


@pytest.mark.parametrize('a, b', [(1.0, 1.0), (1.0, 0.3), (0.5, 4.0)])
def test_solid_limit_of_coinciding_centres(a, b):
    # delta -> 0: the hull is {|x1| + |x3| <= b sqrt(1 - x2**2 / a**2)} (its slices are the
    # squares spanned by the two chords, and this set is already convex), so
    # V = 8 a b**2 / 3, int x1**2 dV = int x3**2 dV = 16 a b**4 / 45 and
    # int x2**2 dV = 8 a**3 b**2 / 15. The change is O(delta**2 ln(a / delta)) (measured
    # 3.6e-11 at delta / a = 1e-6 and 4.2e-13 at 1e-7), and the solid meets its rtol 1e-12.
    props = solid_hull(a, b, 1e-7 * a, 1.0, rtol=1e-12)
    volume = 8.0 * a * b * b / 3.0
    assert_allclose(props.volume, volume, rtol=1e-12)
    second = second_moments(props) * props.volume / props.mass
    expected = np.diag([16.0 * a * b ** 4 / 45.0, 8.0 * a ** 3 * b * b / 15.0,
                        16.0 * a * b ** 4 / 45.0])
    assert_allclose(np.diag(second), np.diag(expected), rtol=1e-12)
    assert_allclose(second - np.diag(np.diag(second)), 0.0, atol=SYMMETRY_ATOL * np.max(expected))


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
    assert np.all(np.linalg.eigvalsh(inertia) > 0.0)
    i1, i2, i3 = np.diag(inertia)
    assert i1 + i2 > i3 and i2 + i3 > i1 and i3 + i1 > i2  # strict for a solid
    check_symmetries(props, a, b)
    assert props.relative_error <= 1e-9
    # Inscribed polytope <= hull <= bounding box [-b, b] x [-a-delta, a+delta] x [-b, b].
    coarse = ruled_polytope_moments(a, b, delta, 64)
    assert coarse[0] < props.volume < 8.0 * b * b * (a + delta)
    # The body is convex and symmetric in x1, x2, x3 (x2 via the disk swap), so each marginal
    # density is unimodal (Brunn-Minkowski): mean x_i**2 <= half-width**2 / 3.
    second = second_moments(props) / mass
    assert second[0, 0] <= b * b / 3.0 and second[2, 2] <= b * b / 3.0
    assert second[1, 1] <= (a + delta) ** 2 / 3.0


# ----------------------------------------------------------------------------- laminae


def plate_moments(x, y, dx, dy, n=32):
    """Area and ``int x**2``, ``int y**2``, ``int x y`` over a plate, by Green's theorem.

    Parameters
    ----------
    x, y, dx, dy : callable
        The rim ``(x(t), y(t))`` (m) and its derivatives, 2 pi-periodic in t.
    n : int
        Trapezoidal nodes in t; exact for trigonometric polynomials of degree < n (an
        ellipse's integrands have degree <= 4).

    Returns
    -------
    area, xx, yy, xy : float
        m**2 and m**4, whichever way the rim turns.
    """
    t = 2.0 * np.pi * np.arange(n) / n
    weight = 2.0 * np.pi / n
    xt, yt, dxt, dyt = x(t), y(t), dx(t), dy(t)
    area = 0.5 * weight * np.sum(xt * dyt - yt * dxt)
    sign = np.sign(area)
    return (sign * area, sign * weight * np.sum(xt ** 3 * dyt) / 3.0,
            -sign * weight * np.sum(yt ** 3 * dxt) / 3.0,
            sign * weight * np.sum(xt * xt * yt * dyt) / 2.0)


def lamina_inertia(a, b, delta, mass):
    """Inertia about G (kg m**2) of the two plates, each disk integrated on its own rim."""
    area1, xx1, yy1, xy1 = plate_moments(  # disk 1 in its plane: (x1, x2)
        lambda t: b * np.sin(t), lambda t: -delta - a * np.cos(t),
        lambda t: b * np.cos(t), lambda t: a * np.sin(t))
    area2, yy2, zz2, yz2 = plate_moments(  # disk 2 in its plane: (x2, x3)
        lambda t: delta + a * np.cos(t), lambda t: b * np.sin(t),
        lambda t: -a * np.sin(t), lambda t: b * np.cos(t))
    rho1, rho2 = 0.5 * mass / area1, 0.5 * mass / area2  # kg / m**2
    s11, s33 = rho1 * xx1, rho2 * zz2
    s22 = rho1 * yy1 + rho2 * yy2
    # I = tr(S) 1 - S, each diagonal entry summed directly (no cancellation when b << a)
    return np.array([[s22 + s33, -rho1 * xy1, 0.0],
                     [-rho1 * xy1, s11 + s33, -rho2 * yz2],
                     [0.0, -rho2 * yz2, s11 + s22]])


def check_laminae(a, b, delta, mass):
    props = laminae(a, b, delta, mass)
    expected = lamina_inertia(a, b, delta, mass)
    # docs/physics.md: `laminae` is exact. I1 and I3 come from different disks here.
    assert_allclose(np.diag(props.inertia), np.diag(expected), rtol=LAMINAE_RTOL)
    largest = np.max(np.diag(expected))
    off = props.inertia - np.diag(np.diag(props.inertia))
    assert_allclose(off, expected - np.diag(np.diag(expected)), rtol=0,
                    atol=LAMINAE_OFF_ATOL * largest)
    assert_allclose(props.center_of_mass, 0.0, atol=0.0)
    return props


@pytest.mark.parametrize('a, b, delta, mass', [
    (1.0, 1.0, 0.5, 1.0),
    (0.8, 2.0, 0.3, 0.25),
    (2.0, 0.1, 1.9, 3.0),
])
def test_laminae_match_direct_integration(a, b, delta, mass):
    props = check_laminae(a, b, delta, mass)
    assert props.model == 'laminae' and props.volume is None and props.relative_error == 0.0


@settings(max_examples=200, deadline=None)
@given(
    a=st.floats(1e-4, 1e4),
    b_over_a=st.floats(0.01, 100.0),
    delta_over_a=st.floats(1e-6, 1.0 - 1e-9),
    mass=st.floats(1e-4, 1e4),
)
def test_laminae_across_shapes(a, b_over_a, delta_over_a, mass):
    props = check_laminae(a, a * b_over_a, a * delta_over_a, mass)
    assert np.all(np.linalg.eigvalsh(props.inertia) > 0.0)
    i1, i2, i3 = np.diag(props.inertia)
    # plates: I3 = I1' + I2' per plate, so the triangle inequality is tight up to rounding
    # (16 ulps of the moments)
    assert i1 + i2 >= i3 * (1 - ulps(16)) and i2 + i3 >= i1 * (1 - ulps(16))


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
    assert_allclose(solid.volume, OLOID_VOLUME, rtol=OLOID_VOLUME_RTOL)


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

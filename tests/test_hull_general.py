"""The mass models of bodies of any lamina (mass.models.mass_properties_of, mass/hull_laminae.py).

Independent references, never the code's own output:
- the ellipse's closed-form path (hull.py: another parametrisation, another derivation) for
  the general path on elliptic laminae given as Superellipse(n = 2) or Ellipse;
- the oloid's volume (2/3)(2E(3/4) + K(3/4)) r³;
- scipy.spatial.ConvexHull (Qhull) of points on the two rims at the ends of the hull's rulings,
  split into tetrahedra with exact moments, Richardson-extrapolated in the sample count (as
  test_mass_models.py does for ellipses); the points are on the rims whatever the code under
  test does, so the polytope is inscribed in the true hull and converges to it;
- the plates' moments integrated on each disk's own rim in 3D (triangle fans of rim samples,
  exact per triangle, Richardson-extrapolated): not the lamina's area moments the code uses;
- symmetries: x1 → −x1 and x3 → −x3 (no products of inertia), the disk swap for swapped or
  symmetric laminae (centre of mass at G, I1 = I3).
Each tolerance names the accuracy claim of docs/physics.md (section "Mass models") it checks.
"""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.spatial import ConvexHull
from scipy.special import ellipe, ellipk

from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.contact_solver import ContactSolver
from twodisk_ros.physics.mass.hull import unit_hull_moments
from twodisk_ros.physics.mass.hull_laminae import SWAP, MirroredLamina, general_hull_moments
from twodisk_ros.physics.laminae.shapes import Ellipse, Superellipse
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.physics.laminae.fit import Outline
from twodisk_ros.physics.mass.models import mass_properties, mass_properties_of
from rounding import ulps

OLOID_VOLUME = 2.0 / 3.0 * (2.0 * ellipe(0.75) + ellipk(0.75))


def _outline():
    """A fitted outline (laminae/fit.py) of 200 points sampled on a small egg (m)."""
    s = np.linspace(0.0, 2 * np.pi, 200, endpoint=False)
    return Outline.from_points(Egg(0.05, 0.04, 0.002).point(s))


# (lamina, delta): non-elliptic shapes of the brief, both arrangements each
SHAPES = [
    (Superellipse(1.0, 0.8, 4.0), 0.4),
    (Superellipse(1.0, 1.0, 10.0), 0.5),
    (Egg(1.0, 0.8, 0.05), 0.4),
    (_outline(), 0.02),
]
IDS = ['superellipse4', 'superellipse10', 'egg', 'outline']

# ----------------------------------------------------------------------------- tolerances
#: The general path on elliptic laminae against the closed-form path, both at rtol 1e-13:
#: docs claim ≤ 1e-14 relative (measured ≤ 1.7e-15 over the bodies below, both arrangements,
#: Ellipse and Superellipse(n = 2)).
ELLIPSE_RTOL = 1e-14
#: Against Qhull polytopes extrapolated from 64 … 1024 samples per arc: the reference's own
#: error is the limit (measured ≤ 8e-13 for n = 4, egg, outline; 1.4e-11 for n = 10, whose
#: polytopes converge more slowly; 2.3e-13 for n = 10 with 128 … 2048 samples). Volume, e2
#: centre of mass (of the size) and each diagonal second moment.
POLYTOPE_RTOL = 5e-11
#: Symmetries kept exactly by the quadrature's pieces (measured ≤ 2e-15 of the moments).
SYMMETRY_ATOL = 1e-14
#: laminae_of against plates integrated on their rims (fans of 256 … 2048 samples,
#: extrapolated: measured ≤ 4e-15).
PLATES_RTOL = 2e-14


def central_second_moments(props):
    """∫x xᵀ dV (m⁵) about the centre of mass of a solid from its inertia and density."""
    density = props.mass / props.volume
    second = 0.5 * np.trace(props.inertia) * np.eye(3) - props.inertia   # about the c.o.m.
    return second / density


# ----------------------------------------------------------------------------- ellipses


@pytest.mark.parametrize('a, b, delta', [(1.0, 1.0, 0.5), (1.0, 0.7, 0.3), (0.8, 2.0, 0.3),
                                         (1.0, 0.2, 0.8)])
@pytest.mark.parametrize('arrangement', ['parallel', 'swapped'])
def test_general_path_on_ellipses_matches_closed_form(a, b, delta, arrangement):
    vol0, first0, second0, _ = unit_hull_moments(delta / a, 1e-13)
    scale, jac = np.array([b, a, b]), a * b * b
    reference = np.concatenate([[jac * vol0], jac * scale * first0,
                                np.diag(jac * np.outer(scale, scale) * second0)])
    size = max(a + delta, b)
    for lamina in (Superellipse(a, b, 2.0), Ellipse(a, b)):
        vol, first, second, error = general_hull_moments(lamina, delta, arrangement, 1e-13)
        assert error <= 1e-13
        assert abs(vol / reference[0] - 1) <= ELLIPSE_RTOL
        assert np.all(np.abs(first) <= ELLIPSE_RTOL * vol * size)
        assert_allclose(np.diag(second), reference[4:], rtol=ELLIPSE_RTOL)


def test_oloid_volume_on_the_general_path():
    vol, _, _, _ = general_hull_moments(Superellipse(1.0, 1.0, 2.0), 0.5, 'parallel', 1e-13)
    assert abs(vol / OLOID_VOLUME - 1) <= ELLIPSE_RTOL


@pytest.mark.parametrize('model', ['laminae', 'solid', 'custom'])
def test_two_disk_body_takes_the_general_path_to_the_closed_forms(model):
    """An ellipse's body (either kind, either arrangement) on the general path agrees with
    the closed forms of a, b, Δ: 'custom' exactly, 'laminae' to rounding (sums of rounded
    area moments), 'solid' to the quadrature's ELLIPSE_RTOL at rtol 1e-13."""
    moments = (0.3, 0.2, 0.3) if model == 'custom' else None
    expected = mass_properties(model, 1.0, 0.7, 0.3, 2.0, principal_moments=moments, rtol=1e-13)
    for body in (EllipseBody(1.0, 0.7, 0.3), ContactSolver(Ellipse(1.0, 0.7), 0.3, 'swapped')):
        props = mass_properties_of(model, body, 2.0, moments, rtol=1e-13)
        if model == 'custom':
            assert props == expected
        bound = ulps(16, np.max(expected.inertia)) if model == 'laminae' else \
            ELLIPSE_RTOL * np.max(expected.inertia)
        assert np.max(np.abs(props.inertia - expected.inertia)) <= bound
        assert np.max(np.abs(props.center_of_mass)) <= ulps(16, body.size)
        assert props.volume == (None if model != 'solid' else
                                pytest.approx(expected.volume, rel=ELLIPSE_RTOL))


# ----------------------------------------------------------------------------- the solid


def ruling_ends(lamina, delta, arrangement, n):
    """Points on both rims at the ends of the hull's rulings, from O (m).

    ContactSolver's poses at n + 1 equal steps of A's lamina parameter over |s| ≤ s_c
    (both branches; s_c halfway between the side vertex and the turning point) and, around the
    turning points, the dual body's poses (disk 2 seen as disk 1) at n/2 + 1 steps of B's.
    """
    body = ContactSolver(lamina, delta, arrangement)
    mirrored = MirroredLamina(lamina) if arrangement == 'parallel' else lamina
    dual = ContactSolver(mirrored, delta, arrangement)
    side = float(lamina.support(np.array([1.0, 0.0])).parameter)
    cut = 0.5 * (side + body.s_max)
    s = np.linspace(-cut, cut, n + 1)
    tau = body.elevation_of_parameter(s)      # from the parameters: no θ -> s bisection
    points = []
    for branch in (1, -1):
        pose = body.geometry_at_parameter(s, tau, branch)
        points += [pose.contact_a + body.centroid, pose.contact_b + body.centroid]
    for sign in (1, -1):
        b = body.geometry_at_parameter(sign * cut, body.elevation_of_parameter(sign * cut),
                                       1).contact_b + body.centroid
        limit = float(dual.parameter_of_theta(abs(math.atan2(b[2], b[1] - delta))))
        s = np.linspace(-limit, limit, n // 2 + 1)
        pose = dual.geometry_at_parameter(s, dual.elevation_of_parameter(s), -sign)
        points += [(pose.contact_a + dual.centroid) @ SWAP,
                   (pose.contact_b + dual.centroid) @ SWAP]
    return np.vstack(points)


def polytope_moments(points):
    """Volume, ∫x dV and the diagonal of ∫x xᵀ dV of the convex hull of points (Qhull)."""
    hull = ConvexHull(points)
    tri = hull.points[hull.simplices]
    vol = np.abs(np.einsum('ij,ij->i', tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0
    s = tri.sum(axis=1)
    second = (np.einsum('i,ijk,ijk->k', vol / 20.0, tri, tri)
              + np.einsum('i,ik,ik->k', vol / 20.0, s, s))
    return np.concatenate([[vol.sum()], np.einsum('i,ik->k', vol / 4.0, s), second])


def polytope_reference(lamina, delta, arrangement, levels=(64, 128, 256, 512, 1024)):
    """Richardson extrapolation (h², h³, h⁴, h⁵) of the inscribed polytopes."""
    column = [polytope_moments(ruling_ends(lamina, delta, arrangement, n)) for n in levels]
    for power in (2, 3, 4, 5)[:len(levels) - 1]:
        f = 2.0 ** power
        column = [(f * fine - coarse) / (f - 1.0) for coarse, fine in zip(column, column[1:])]
    return column[0]


@pytest.mark.parametrize('lamina, delta, arrangement', [
    shape + (arrangement,) for shape in SHAPES for arrangement in ('parallel', 'swapped')
    if not (isinstance(shape[0], Outline) and arrangement == 'swapped')])   # 12 s each
def test_solid_matches_extrapolated_inscribed_polytopes(lamina, delta, arrangement):
    reference = polytope_reference(lamina, delta, arrangement)
    props = mass_properties_of('solid', ContactSolver(lamina, delta, arrangement), 1.5,
                               rtol=1e-12)
    assert props.relative_error <= 1e-12
    g = ContactSolver(lamina, delta, arrangement).centroid
    com = props.center_of_mass + g                                    # from O
    size = lamina.size + delta
    assert abs(props.volume / reference[0] - 1) <= POLYTOPE_RTOL
    assert abs(com[1] - reference[2] / reference[0]) <= POLYTOPE_RTOL * size
    second_o = np.diag(central_second_moments(props)) + props.volume * com ** 2
    assert_allclose(second_o, reference[4:], rtol=POLYTOPE_RTOL)


@pytest.mark.parametrize('arrangement', ['parallel', 'swapped'])
@pytest.mark.parametrize('lamina, delta', SHAPES, ids=IDS)
def test_solid_symmetries(lamina, delta, arrangement):
    props = mass_properties_of('solid', ContactSolver(lamina, delta, arrangement), 1.0)
    inertia, size = props.inertia, lamina.size + delta
    largest = np.max(np.diag(inertia))
    assert_allclose(inertia - np.diag(np.diag(inertia)), 0.0, atol=SYMMETRY_ATOL * largest)
    assert abs(props.center_of_mass[0]) <= SYMMETRY_ATOL * size
    assert abs(props.center_of_mass[2]) <= SYMMETRY_ATOL * size
    symmetric = arrangement == 'swapped' or isinstance(lamina, Superellipse)
    if symmetric:   # the disk swap is a symmetry of the body
        assert abs(props.center_of_mass[1]) <= SYMMETRY_ATOL * size
        assert abs(inertia[0, 0] - inertia[2, 2]) <= SYMMETRY_ATOL * largest
    else:           # the egg's hull is heavier towards its blunt ends
        assert abs(props.center_of_mass[1]) > 1e-3 * size
    assert np.all(np.linalg.eigvalsh(inertia) > 0)


def test_mirrored_egg_is_the_egg_of_opposite_epsilon():
    # Egg(a, b, −ε) is the mirror image of Egg(a, b, ε) (laminae/shapes.py): the same hull.
    a = general_hull_moments(MirroredLamina(Egg(1.0, 0.8, 0.05)), 0.4, 'parallel', 1e-12)
    b = general_hull_moments(Egg(1.0, 0.8, -0.05), 0.4, 'parallel', 1e-12)
    assert abs(a[0] / b[0] - 1) <= 1e-12
    assert_allclose(a[1], b[1], atol=1e-12 * a[0])
    assert_allclose(np.diag(a[2]), np.diag(b[2]), rtol=1e-12)


# ----------------------------------------------------------------------------- the plates


def plate_second_moments(points_3d):
    """∫x xᵀ dA (m⁴) and the area of a planar polygon in 3D, from a fan at its first point."""
    v0 = points_3d[0]
    v1, v2 = points_3d[1:-1], points_3d[2:]
    area = 0.5 * np.linalg.norm(np.cross(v1 - v0, v2 - v0), axis=1)
    tri = np.stack([np.broadcast_to(v0, v1.shape), v1, v2], axis=1)
    s = tri.sum(axis=1)
    second = (np.einsum('i,ijk,ijl->kl', area / 12.0, tri, tri)
              + np.einsum('i,ik,il->kl', area / 12.0, s, s))
    return second, area.sum()


def plates_reference(lamina, delta, sigma, mass, levels=(256, 512, 1024, 2048)):
    """Inertia about G of the two plates, each integrated on its own rim, extrapolated."""
    column = []
    for n in levels:
        s = 2 * np.pi * np.arange(n) / n
        p = lamina.point(s)
        zero = np.zeros(n)
        total = np.zeros((3, 3))
        for rim in (np.stack([p[:, 0], p[:, 1] - delta, zero], axis=-1),
                    np.stack([zero, delta + sigma * p[:, 1], p[:, 0]], axis=-1)):
            second, area = plate_second_moments(rim)
            total += 0.5 * mass / area * second
        column.append(total)
    for power in (2, 4, 6)[:len(levels) - 1]:
        f = 2.0 ** power
        column = [(f * fine - coarse) / (f - 1.0) for coarse, fine in zip(column, column[1:])]
    second = column[0]
    g = 0.5 * (1 + sigma) * float(lamina.moments.centroid[1])
    second[1, 1] -= mass * g * g
    return np.trace(second) * np.eye(3) - second


@pytest.mark.parametrize('arrangement', ['parallel', 'swapped'])
@pytest.mark.parametrize('lamina, delta', SHAPES, ids=IDS)
def test_laminae_match_plates_integrated_on_their_rims(lamina, delta, arrangement):
    sigma = 1.0 if arrangement == 'parallel' else -1.0
    props = mass_properties_of('laminae', ContactSolver(lamina, delta, arrangement), 2.0)
    expected = plates_reference(lamina, delta, sigma, 2.0)
    assert_allclose(np.diag(props.inertia), np.diag(expected), rtol=PLATES_RTOL)
    assert_allclose(props.center_of_mass, 0.0, atol=0.0)
    assert props.model == 'laminae' and props.volume is None


# ----------------------------------------------------------------------------- bad input


@pytest.mark.parametrize('call, words', [
    (lambda: mass_properties_of('oloid', EllipseBody(1, 1, 0.5), 1.0), ['model must be one of']),
    (lambda: mass_properties_of('solid', object(), 1.0), ['body must be a rolling body']),
    (lambda: mass_properties_of('solid', ContactSolver(Egg(1, 0.8, 0.05), 0.4), -1.0),
     ['mass must be finite and > 0 kg']),
    (lambda: mass_properties_of('custom', ContactSolver(Egg(1, 0.8, 0.05), 0.4), 1.0),
     ['principal_moments must be given']),
    (lambda: mass_properties_of('solid', ContactSolver(Egg(1, 0.8, 0.05), 0.4), 1.0,
                                rtol=0.0), ['rtol must be']),
])
def test_bad_input_gives_one_line_value_error(call, words):
    with pytest.raises(ValueError) as info:
        call()
    message = str(info.value)
    assert '\n' not in message
    for word in words:
        assert word in message

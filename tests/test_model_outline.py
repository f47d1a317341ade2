"""Drawing any lamina (physics/bodies/outline.py, physics/bodies/rulings.py and their users) against references.

Independent references: the laminae's own definitions (the superellipse's implicit equation
|x/b|ⁿ + |y/a|ⁿ = 1, the support function h of laminae/shapes.py, evaluated on a dense circle of
directions); the placement of the laminae written out here from bodies/contact_solver.py's docstring
(disk 1's point (x, y) at (x, y − Δ, 0) − G, disk 2's at (0, Δ + σy, x) − G); trimesh (a
second library) for closedness, winding and volume; scipy.spatial.ConvexHull of densely
sampled rims (20 001 points of lamina.point per rim, not physics/bodies/outline.py's polygon: 1e-7
relative in volume) for the hull's volume; the shoelace area of a polygon.

Accuracy claims checked: physics/bodies/outline.py's polygon misses the curve by at most the stated
tolerance × the lamina's size in every direction (max over vertices of p·n ≥ h(n) − that),
its vertices lie on the curve to rounding; model/mesh.py's ruled hull is closed, wound
outward and converges at second order to the convex hull of the rims (measured |error| n²
0.19–4.3 over the shapes below at n = 128–512, asserted ≤ 6).
"""

import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull

from rounding import ulps
from twodisk_ros.model.frames import disk_frames, disk_rims
from twodisk_ros.model.mesh import body_mesh, mesh_parts
from twodisk_ros.physics.bodies.outline import frame_rims, lamina_outline
from twodisk_ros.model.stl import cached_stl
from twodisk_ros.physics import EllipseBody
from twodisk_ros.physics.bodies.contact_solver import ContactSolver
from twodisk_ros.physics.laminae.shapes import Ellipse, Superellipse
from twodisk_ros.physics.laminae.support import Egg

LAMINAE = [Ellipse(1.0, 0.3), Ellipse(0.5, 0.5), Superellipse(1.0, 1.0, 6),
           Superellipse(1.0, 0.5, 100), Superellipse(0.3, 0.8, 2.5), Egg(1.0, 0.8, 0.06),
           Egg(0.2, 0.16, -0.012)]
# (lamina, Δ, arrangement): symmetric and asymmetric laminae, both arrangements
BODIES = [(Superellipse(1.0, 1.0, 6), 0.5, 'parallel'),
          (Superellipse(1.0, 0.5, 100), 0.3, 'parallel'), (Egg(1.0, 0.8, 0.06), 0.4, 'parallel'),
          (Egg(1.0, 0.8, 0.06), 0.4, 'swapped'),
          (Ellipse(1.0, 1.0), 0.5, 'parallel')]
DIRECTIONS = np.stack([np.cos(np.linspace(0, 2 * np.pi, 20001)),
                       np.sin(np.linspace(0, 2 * np.pi, 20001))], axis=-1)


def _ids(value):
    return repr(value) if not isinstance(value, tuple) else f'{value[0]!r}-{value[1]}-{value[2]}'


@pytest.mark.parametrize('tolerance', [1e-3, 1e-5])
@pytest.mark.parametrize('lamina', LAMINAE, ids=repr)
def test_outline_misses_the_support_function_by_at_most_its_tolerance(lamina, tolerance):
    points = lamina_outline(lamina, tolerance)
    h = lamina.support(DIRECTIONS).height
    reach = (DIRECTIONS @ points.T).max(axis=1)
    size = lamina.size
    # inscribed: no vertex beyond the curve (rounding of h, of the points and of p·n:
    # 16 ulps of the size) ...
    assert np.max(reach - h) <= ulps(16, size)
    # ... and the polygon reaches the curve to the stated error in every direction
    assert np.max(h - reach) <= tolerance * size
    # not far finer than asked for: the error is at least a tenth of it somewhere
    assert np.max(h - reach) >= 0.1 * tolerance * size
    # the layout: counterclockwise (positive shoelace area), tips on the axis at 0 and N/2,
    # symmetric about the common axis
    n = len(points)
    x, y = points.T
    assert 0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)) > 0
    assert n % 2 == 0 and x[0] == 0 and x[n // 2] == 0 and y[0] < 0 < y[n // 2]
    assert np.array_equal(points[1:n // 2][::-1] * [-1, 1], points[n // 2 + 1:])


def test_outline_of_a_fitted_outline():
    # a lamina fitted from points (laminae.fit.Outline: a support-function lamina whose
    # parameter is the normal angle) is drawn to the same guarantee
    from twodisk_ros.physics.laminae.fit import Outline
    given = Egg(1.0, 0.7, 0.05).point(np.linspace(0, 2 * np.pi, 200, endpoint=False))
    lamina = Outline.from_points(given)
    points = lamina_outline(lamina, 1e-4)
    h = lamina.support(DIRECTIONS).height
    reach = (DIRECTIONS @ points.T).max(axis=1)
    assert np.max(reach - h) <= ulps(16, lamina.size)              # rounding, as above
    assert 1e-5 * lamina.size <= np.max(h - reach) <= 1e-4 * lamina.size


@pytest.mark.parametrize('lamina', [Superellipse(1.0, 1.0, 6), Superellipse(1.0, 0.5, 100),
                                    Superellipse(0.3, 0.8, 2.5)], ids=repr)
def test_superellipse_outline_vertices_satisfy_its_equation(lamina):
    points = lamina_outline(lamina, 1e-4)
    x, y = points.T
    # |x/b|ⁿ + |y/a|ⁿ = 1 to rounding (n ≤ 100 multiplies relative errors by ≤ 100)
    residual = np.abs(np.abs(x / lamina.b) ** lamina.n + np.abs(y / lamina.a) ** lamina.n - 1)
    assert residual.max() <= 1e-13
    # the corners of n = 100 are where the vertices gather (the curve turns there)
    if lamina.n == 100:
        corner = (np.abs(x) > 0.9 * lamina.b) & (np.abs(y) > 0.9 * lamina.a)
        assert corner.sum() >= 0.5 * len(points)


def test_outline_refuses_a_bad_tolerance_in_one_line():
    for bad in (0.0, -1e-3, 0.5, float('nan'), '1e-3', True):
        with pytest.raises(ValueError) as error:
            lamina_outline(Ellipse(1.0, 1.0), bad)
        assert '\n' not in str(error.value) and 'tolerance' in str(error.value)


@pytest.mark.parametrize('body', BODIES, ids=_ids)
def test_rims_sit_where_general_body_puts_the_laminae(body):
    lamina, delta, arrangement = body
    general = ContactSolver(lamina, delta, arrangement)
    rim_1, rim_2 = disk_rims(general, 1e-4, closed=False)
    sigma = 1.0 if arrangement == 'parallel' else -1.0
    g = general.centroid
    # back to lamina coordinates by the placement of bodies/contact_solver.py's docstring
    lamina_1 = np.stack([rim_1[:, 0] + g[0], rim_1[:, 1] + g[1] + delta], axis=-1)
    lamina_2 = np.stack([rim_2[:, 2] + g[2], sigma * (rim_2[:, 1] + g[1] - delta)], axis=-1)
    assert np.all(rim_1[:, 2] == 0) and np.all(rim_2[:, 0] == 0)
    for points in (lamina_1, lamina_2):
        reach = (DIRECTIONS @ points.T).max(axis=1)
        h = lamina.support(DIRECTIONS).height
        assert np.max(reach - h) <= 1e-14 * lamina.size
        assert np.max(h - reach) <= 1e-4 * lamina.size
    # the far tips first: disk 1's at the lowest x2, disk 2's at the highest
    assert rim_1[0, 1] == rim_1[:, 1].min() and rim_2[0, 1] == rim_2[:, 1].max()
    # the contact points of the exact geometry lie on the rims' polygons' curves: A and B
    # of a few poses, in the disk frames, against the frame rims (within their error)
    pose = general.geometry(np.linspace(-0.9, 0.9, 7) * general.theta_max, 1)
    for frame, rim, contact in zip(disk_frames(general), frame_rims(general, 1e-6),
                                   (pose.contact_a, pose.contact_b)):
        local = frame.to_disk(contact)
        assert np.max(np.abs(local[:, 2])) <= ulps(16, general.size)     # rounding
        distance = np.min(np.linalg.norm(local[:, None, :2] - rim[None], axis=-1), axis=1)
        step = np.max(np.linalg.norm(np.diff(rim, axis=0), axis=1))
        assert np.max(distance) <= 0.5 * step + 1e-6 * lamina.size


def _dense_hull_volume(lamina, delta, arrangement, centroid):
    s = np.linspace(0.0, 2 * np.pi, 20001)
    x, y = lamina.point(s).T
    sigma = 1.0 if arrangement == 'parallel' else -1.0
    rim_1 = np.stack([x, y - delta, 0 * s], axis=-1)
    rim_2 = np.stack([0 * s, delta + sigma * y, x], axis=-1)
    # joggled input (QJ): all points lie in two planes, which makes plain Qhull take ~40 s;
    # the joggle changes the volume by ~3e-13 relative
    return ConvexHull(np.concatenate([rim_1, rim_2]) - centroid, qhull_options='QJ').volume


@pytest.mark.parametrize('body', BODIES, ids=_ids)
def test_ruled_hull_is_closed_outward_and_converges_to_the_convex_hull(body):
    lamina, delta, arrangement = body
    general = ContactSolver(lamina, delta, arrangement)
    reference = _dense_hull_volume(lamina, delta, arrangement, general.centroid)
    errors = []
    for n in (128, 256, 512):
        part = mesh_parts(general, 'solid', n)['hull']
        mesh = trimesh.Trimesh(part.vertices, part.faces, process=False)
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
        # the vertices are ends of rulings: on the rims (disk 1: x3 = 0, disk 2: x1 = 0)
        on_plane = np.minimum(np.abs(part.vertices[:, 2]), np.abs(part.vertices[:, 0]))
        assert on_plane.max() <= ulps(16, general.size)                # rounding
        errors.append(mesh.volume / reference - 1)
    errors = np.array(errors)
    assert np.all(errors < 0)                   # inscribed in the hull
    assert np.all(np.abs(errors) * np.array([128, 256, 512]) ** 2 <= 6)
    # second order: halving the step divides the error by ~4 (measured 3.9–4.1; 2.5 and 3.0
    # for the superellipse n = 100, still approaching it)
    ratios = errors[:-1] / errors[1:]
    assert np.all((ratios > 2.2) & (ratios < 4.5)), ratios


@pytest.mark.parametrize('body', BODIES, ids=_ids)
def test_plates_are_closed_prisms_over_the_outline(body):
    lamina, delta, arrangement = body
    general = ContactSolver(lamina, delta, arrangement)
    thickness = 0.01 * general.size
    for part in mesh_parts(general, 'laminae', 256, thickness).values():
        mesh = trimesh.Trimesh(part.vertices, part.faces, process=False)
        assert mesh.is_watertight and mesh.is_winding_consistent
        # a prism over an inscribed polygon: thickness × (the lamina's area − a little): the
        # chords miss the curve by ≤ 1 − cos(π/256) = 7.5e-5 of the size, measured area
        # deficits 3.5e-5 to 9.7e-5
        area = mesh.volume / thickness
        assert -1.5e-4 <= area / lamina.moments.area - 1 < 0


def test_ellipse_bodies_keep_their_closed_form_meshes():
    # the general path is used only for other bodies: a EllipseBody's plates keep the
    # eccentric-anomaly rim and its hull the closed-form rulings (tests/test_model_mesh.py)
    body = EllipseBody(1.0, 1.0, 0.5)
    assert len(body_mesh(body, 'laminae', 64).vertices) == 2 * (2 * 64 + 2)
    assert len(body_mesh(body, 'solid', 64).vertices) == 2 * 33


def test_mesh_cache_key_distinguishes_shapes(tmp_path):
    # the same a, b, Δ, three shapes: three files; the same shape again: the same file
    bodies = [EllipseBody(1.0, 1.0, 0.5),
              ContactSolver(Superellipse(1.0, 1.0, 4), 0.5),
              ContactSolver(Superellipse(1.0, 1.0, 6), 0.5)]
    for model in ('laminae', 'solid'):
        paths = [cached_stl(body_mesh(body, model, 64), tmp_path) for body in bodies]
        assert len(set(paths)) == 3
        again = cached_stl(body_mesh(ContactSolver(Superellipse(1.0, 1.0, 6), 0.5),
                                     model, 64), tmp_path)
        assert again == paths[-1]


def test_disk_frames_follow_the_centroid_of_an_egg():
    general = ContactSolver(Egg(1.0, 0.8, 0.06), 0.4)
    g = general.centroid[1]
    assert abs(g) > 1e-3                        # the egg's centroid is off its centre
    frame_a, frame_b = disk_frames(general)
    assert np.array_equal(frame_a.translation, [0.0, -0.4 - g, 0.0])
    assert np.array_equal(frame_b.translation, [0.0, 0.4 - g, 0.0])
    # for an ellipse body the frames are exactly the old ones, (0, ∓Δ, 0)
    frame_a, frame_b = disk_frames(EllipseBody(2.0, 1.0, 1.0))
    assert np.array_equal(frame_a.translation, [0.0, -1.0, 0.0])
    assert np.array_equal(frame_b.translation, [0.0, 1.0, 0.0])

"""The drawers (Foxglove /body, RViz markers, the animation) draw the real lamina outline.

References: the laminae's own definitions (the superellipse's implicit equation, the egg's
support function h of laminae/shapes.py) and the placement of the laminae in bodies/contact_solver.py's
docstring, written out here; the lamina's area (lamina.moments: closed forms for the
superellipse) against the shoelace area of what is drawn. The drawers get a
ContactSolver (any lamina) as a body: LaminaBody has the same attributes.
"""

import numpy as np
import pytest
from PIL import Image

from rounding import ulps
from twodisk_ros.model.frames import disk_frames
from twodisk_ros.model.mesh import mesh_parts
from twodisk_ros.model.frames import disk_rims
from twodisk_ros.physics.bodies.outline import DEFAULT_TOLERANCE
from twodisk_ros.physics.bodies.contact_solver import ContactSolver
from twodisk_ros.physics.laminae.shapes import Superellipse
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.plotting.animation import still
from twodisk_ros.runs import Run, RunError

SQUIRCLE = ContactSolver(Superellipse(0.2, 0.15, 6), 0.1)
EGG = ContactSolver(Egg(0.2, 0.16, 0.012), 0.08, 'swapped')


def _superellipse_residual(lamina, x, y):
    """|x/b|ⁿ + |y/a|ⁿ − 1 at lamina points (x across, y along the common axis)."""
    return np.abs(np.abs(x / lamina.b) ** lamina.n + np.abs(y / lamina.a) ** lamina.n - 1)


def _shoelace(x, y):
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _decoded(update):
    """A foxglove SceneUpdate as protobuf decodes its bytes (the schema it carries)."""
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    schema = type(update).get_schema()
    pool = descriptor_pool.DescriptorPool()
    for file in descriptor_pb2.FileDescriptorSet.FromString(schema.data).file:
        pool.Add(file)
    kind = message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))
    return kind.FromString(update.encode())


def test_foxglove_rims_are_the_superellipse_in_the_disk_frames():
    from twodisk_ros.view.scene import body_update
    body = SQUIRCLE
    update = _decoded(body_update(0, 'twodisk_body', body, mesh_parts(body, 'laminae', 64),
                                  disk_frames(body)))
    entities = {e.id: e for e in update.entities}
    lamina = body.lamina
    for rim_id in ('rim_a', 'rim_b'):
        points = np.array([(p.x, p.y, p.z) for p in entities[rim_id].lines[0].points])
        assert np.all(points[:, 2] == 0)
        # disk frames (frames.py): disk 1's lamina point (x, y) is (−y, x), disk 2's (y, −x)
        x, y = (points[:, 1], -points[:, 0]) if rim_id == 'rim_a' else (-points[:, 1],
                                                                         points[:, 0])
        assert _superellipse_residual(lamina, x, y).max() <= 1e-13
        # the drawn polygon holds the lamina's area, less the polygon's error (≤ the stated
        # tolerance × the size per chord: the area deficit is below the perimeter, at most
        # the bounding box's 4(a + b), times that)
        deficit = 1 - _shoelace(points[:, 0], points[:, 1]) / lamina.moments.area
        assert 0 < deficit <= 4 * (lamina.a + lamina.b) * DEFAULT_TOLERANCE * lamina.size \
            / lamina.moments.area
    # the old drawing (an ellipse of semi-axes a, b) would miss the superellipse's corners
    # by ~8 % of the size; the drawn rim reaches them
    corner = np.array([(p.x, p.y) for p in entities['rim_a'].lines[0].points])
    reach = np.max(corner @ np.array([1.0, 1.0]) / np.sqrt(2))
    h = lamina.support(np.array([[1.0, 1.0]]) / np.sqrt(2)).height[0]
    # disk frame (X, Y) = (−y, x): the diagonal X = Y is the lamina's direction (1, −1)/√2,
    # where h equals that of (1, 1)/√2 by symmetry
    assert h - reach <= DEFAULT_TOLERANCE * lamina.size
    assert h - np.hypot(lamina.a, lamina.b) / np.sqrt(2) > 0.05 * lamina.size


def test_marker_fans_fill_the_egg():
    from twodisk_ros.node import messages
    body = EGG
    disk1, disk2 = disk_rims(body)
    specs = messages.body_marker_specs(disk1, disk2, disk1[0], disk2[0], body.size)
    assert [s.id for s in specs] == [0, 1, 2, 3, 4]
    lamina = body.lamina
    sigma = -1.0                                   # the swapped arrangement
    g = body.centroid
    for outline, fan, plane in ((specs[0], specs[3], 2), (specs[1], specs[4], 0)):
        points = np.asarray(outline.points)
        assert np.array_equal(points[0], points[-1]) and np.all(points[:, plane] == 0)
        # back to lamina coordinates (bodies/contact_solver.py's placement) and onto the egg: every
        # vertex is a boundary point (p·n = h(n) along its own outward normal, found as the
        # best of a dense circle of directions, to that circle's resolution)
        if plane == 2:
            lam = np.stack([points[:, 0] + g[0], points[:, 1] + g[1] + body.delta], -1)
        else:
            lam = np.stack([points[:, 2] + g[2], sigma * (points[:, 1] + g[1] - body.delta)],
                           -1)
        phi = np.linspace(0, 2 * np.pi, 4001)
        n = np.stack([np.cos(phi), np.sin(phi)], -1)
        gap = lamina.support(n).height[None, :] - lam @ n.T
        # rounding of the placement, of p·n and of h(n): 16 ulps of the size
        assert gap.min() >= -ulps(16, lamina.size)
        assert gap.min(axis=1).max() <= 1e-5 * lamina.size
        # the fan covers the outline's polygon
        triangles = np.asarray(fan.points).reshape(-1, 3, 3)
        area = 0.5 * np.linalg.norm(np.cross(triangles[:, 1] - triangles[:, 0],
                                             triangles[:, 2] - triangles[:, 0]), axis=1).sum()
        assert area == pytest.approx(_shoelace(lam[:-1, 0], lam[:-1, 1]), rel=1e-12)
        # and the lamina, less the polygon's error: below the perimeter (at most its bounding
        # box's) times the stated error
        x_max, y_min, y_max = lamina.extents
        box = 2 * (2 * x_max + y_max - y_min)
        deficit = 1 - area / lamina.moments.area
        assert 0 < deficit <= box * DEFAULT_TOLERANCE * lamina.size / lamina.moments.area


def _resting_run(body):
    """Two samples of the body at rest at θ = 0 (ground normal n → +Z, A at the origin)."""
    pose = body.geometry(0.0, 1)
    n = pose.ground_normal
    t1 = pose.tangent_a
    rotation = np.stack([t1, np.cross(n, t1), n])          # rows: body → world
    g = -rotation @ pose.contact_a
    return Run(body, np.array([0.0, 1.0]), np.array([g, g]),
               np.zeros((2, 3)), np.array([rotation @ (pose.contact_b - pose.contact_a)] * 2),
               np.array([rotation, rotation]), label=repr(body))


@pytest.mark.parametrize('body', [SQUIRCLE, EGG], ids=['superellipse', 'egg'])
def test_animation_outlines_and_still(body, tmp_path):
    run = _resting_run(body)
    disk1, disk2 = run.outlines(0)
    rim_1, rim_2 = disk_rims(body)
    rotation, g = run.rotation[0], run.position_g[0]
    # a rotation and a shift of the size, rounded (16 ulps)
    np.testing.assert_allclose(disk1, rim_1 @ rotation.T + g, atol=ulps(16, body.size))
    np.testing.assert_allclose(disk2, rim_2 @ rotation.T + g, atol=ulps(16, body.size))
    # resting: nothing below the ground, and both rims touch it (at A and at B)
    for rim in (disk1, disk2):
        assert rim[:, 2].min() >= -DEFAULT_TOLERANCE * body.size
        assert rim[:, 2].min() <= DEFAULT_TOLERANCE * body.size
    for view in ('3d', 'top'):
        path = tmp_path / f'{view}.png'
        still(run, path, at=1.0, view=view, size=(200, 150))
        with Image.open(path) as image:
            assert image.size == (200, 150)
            pixels = np.asarray(image.convert('RGB'), dtype=int)
        # the blue of disk 1 is drawn (palette.A, blended with the background)
        blue = (pixels[..., 2] - pixels[..., 0] > 60)
        assert blue.sum() > 50
    with pytest.raises(RunError) as error:
        still(run, tmp_path / 'frame.gif')
    assert '\n' not in str(error.value) and '.png' in str(error.value)

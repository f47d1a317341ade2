"""The disk frames (twodisk_ros/model/frames.py) against the body's own contact geometry.

References: the contact points A and B of the closed forms (body.phase_geometry), which lie
on the rims by docs/physics.md; scipy's quaternion → matrix conversion; the definitions of
θ and ψ as polar angles. Nothing here is read back from frames.py's own tables.
"""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rounding import ulps
from twodisk_ros.model.frames import check_frame_id, disk_frames
from twodisk_ros.physics import EllipseBody

# (a, b, Δ) in m: Oloid, Two-Circle-Roller, Figures 3 and 4, b > a, thin, small and large Δ
BODIES = [(1.0, 1.0, 0.5), (1.0, 1.0, 1 / math.sqrt(2)), (2.0, 1.0, 1.0),
          (math.sqrt(1.5), 1.0, 1.0), (0.8, 2.0, 0.3), (1.0, 0.05, 0.02), (1.0, 0.7, 0.01),
          (0.5, 0.5, 0.495), (3e-3, 2e-3, 1e-3)]
PHASES = np.linspace(-np.pi, np.pi, 401)


@pytest.mark.parametrize('abd', BODIES, ids=str)
def test_contact_points_lie_on_each_disk_rim_in_its_frame(abd):
    body = EllipseBody(*abd)
    a, b = body.a, body.b
    frame_a, frame_b = disk_frames(body, 'rover')
    geometry = body.phase_geometry(PHASES)
    for frame, points, angle in ((frame_a, geometry.contact_a, geometry.theta),
                                 (frame_b, geometry.contact_b, geometry.psi)):
        # the disk frame's pose, applied by scipy: p_body = R p_disk + t
        rotation = Rotation.from_quat(frame.quaternion)
        local = rotation.inv().apply(points - frame.translation)
        # in the disk's plane, to rounding of the size (16 ulps: a rotated difference of
        # lengths of the size; the closed forms' accuracy, 2e-14 L, is along the rim)
        assert np.max(np.abs(local[:, 2])) <= ulps(16, body.size)
        # on its rim x²/a² + y²/b² = 1 (rim points to 2e-14 of the size → 1e-13 relative)
        assert np.max(np.abs(local[:, 0] ** 2 / a**2 + local[:, 1] ** 2 / b**2 - 1)) <= 1e-13
        # and the contact angle is the polar angle from x towards y (to the 3e-13 rad of ψ)
        polar = np.arctan2(local[:, 1], local[:, 0])
        assert np.max(np.abs(np.angle(np.exp(1j * (polar - angle))))) <= 3e-13


def test_frames_of_the_oloid_exactly():
    # disk 1: centre −Δ e2, x = −e2, y = e1, z = e3; disk 2: centre +Δ e2, x = e2, y = −e3,
    # z = −e1 (docs/physics.md's placement, axes chosen by frames.py's docstring)
    frame_a, frame_b = disk_frames(EllipseBody.oloid(2.0))
    assert frame_a.child_frame_id == 'twodisk_body_disk_a'
    assert frame_b.child_frame_id == 'twodisk_body_disk_b'
    assert frame_a.parent_frame_id == frame_b.parent_frame_id == 'twodisk_body'
    assert frame_a.translation.tolist() == [0.0, -1.0, 0.0]
    assert frame_b.translation.tolist() == [0.0, 1.0, 0.0]
    expected = {id(frame_a): [[0, -1, 0], [1, 0, 0], [0, 0, 1]],     # rows: x, y, z axes
                id(frame_b): [[0, 1, 0], [0, 0, -1], [-1, 0, 0]]}
    for frame in (frame_a, frame_b):
        axes = np.array(expected[id(frame)], dtype=float).T
        assert np.array_equal(frame.axes, axes)
        matrix = Rotation.from_quat(frame.quaternion).as_matrix()
        # rounding of √½ and of its products and sums: 16 ulps of 1
        np.testing.assert_allclose(matrix, axes, rtol=0, atol=ulps(16))
        assert math.isclose(np.linalg.norm(frame.quaternion), 1.0, rel_tol=0,
                            abs_tol=ulps(16))
        assert frame.quaternion[3] > 0
        np.testing.assert_allclose(frame.to_disk(frame.translation + axes[:, 0]), [1, 0, 0],
                                   atol=0)


@pytest.mark.parametrize('name', ['', 'a b', 'tab\there', '/slash', None, 3])
def test_bad_frame_names_are_refused_in_one_line(name):
    with pytest.raises(ValueError) as error:
        check_frame_id(name)
    assert '\n' not in str(error.value) and 'body_frame' in str(error.value)
    with pytest.raises(ValueError):
        disk_frames(EllipseBody.oloid(), name)


def test_model_package_imports_without_ros_or_matplotlib():
    import subprocess
    import sys
    code = ('import sys, twodisk_ros.model.frames, twodisk_ros.model.mesh, '
            'twodisk_ros.model.stl, twodisk_ros.model.urdf; '
            'print(sorted(m for m in ("rclpy", "matplotlib") if m in sys.modules))')
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == '[]'

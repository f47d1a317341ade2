"""A body moved to its centre of mass (LaminaBody.about) is drawn about that point.

The solid hull of a parallel egg has its centre of mass off the laminae's centroid G; the
run description moves the body there (mass.models.centred_on_mass), and the node's pose is
that of the moved origin P. The drawing (rims, disk frames, the hull's rulings) must then
place the laminae at −offset e2 from P. References: the physics' contact geometry (r1 = PA,
r2 = PB, the ground normal n, from the phase tables) and the laminae's placement written out
(centres at ∓Δ e2 from the midpoint O, P = ``body.origin`` from O); drawn with the origin at
G instead, the rims would miss the contacts by the offset's share along the rims, ~1e-3 m.
"""

import numpy as np
import pytest

from twodisk_ros.model.frames import disk_frames
from twodisk_ros.model.frames import disk_rims
from twodisk_ros.physics.bodies.outline import DEFAULT_TOLERANCE
from twodisk_ros.physics.bodies.rulings import hull_rulings
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.physics.bodies.lamina_body import LaminaBody
from twodisk_ros.physics.mass.models import centred_on_mass

LAMINA = Egg(0.1, 0.08, 0.5 * Egg.epsilon_max(0.1, 0.08))      # config/egg.yaml's laminae


@pytest.fixture(scope='module')
def moved():
    body, mass = centred_on_mass('solid', LaminaBody(LAMINA, 0.04), 1.0)
    assert np.array_equal(mass.center_of_mass, np.zeros(3))
    assert abs(body.offset) > 1e-3          # the case this file is about: P is not G
    return body


def test_disk_frames_sit_at_the_centres_seen_from_p(moved):
    origin = moved.origin                   # P from O (m)
    frames = disk_frames(moved)
    for frame, sign in zip(frames, (-1.0, 1.0)):
        np.testing.assert_allclose(frame.translation,
                                   np.array([0.0, sign * moved.delta, 0.0]) - origin,
                                   rtol=0, atol=1e-15)


def test_the_drawn_rims_touch_the_ground_at_the_contact_points(moved):
    """At phases over the cycle, every rim point is on or above the ground plane through A
    and B (n·x ≥ n·r1 less the polygon's error) and a rim vertex lies at each contact to
    within the polygon's chord spacing (the rims are drawn to DEFAULT_TOLERANCE × size)."""
    rim_1, rim_2 = disk_rims(moved)
    geometry = moved.phase_geometry(np.linspace(0.0, 2 * np.pi, 37))
    error = DEFAULT_TOLERANCE * LAMINA.size                     # sagitta of a chord (m)
    spacing = np.sqrt(8 * error * LAMINA.size) * 2              # chord length at that sagitta
    for k in range(len(geometry.phase)):
        n = geometry.ground_normal[k]
        ground = float(n @ geometry.contact_a[k])
        assert float(n @ geometry.contact_b[k]) == pytest.approx(ground, abs=1e-12)
        for rim, contact in ((rim_1, geometry.contact_a[k]), (rim_2, geometry.contact_b[k])):
            heights = rim @ n - ground
            assert heights.min() >= -error
            assert heights.min() <= error
            assert np.linalg.norm(rim - contact, axis=1).min() <= spacing


def test_the_hull_rulings_join_the_contact_points_of_the_moved_body(moved):
    """Each ruling of the drawn hull joins A and B of one resting pose: its ends lie on the
    contact traces of the moved body (r1, r2 from P) at the ruling's own θ. Tolerance 1e-6
    of the size: the θ chart of the tables is ill-conditioned at the turning point θ_max
    (ψ'(θ) → ∞; 2.5e-9 m there), and a drawing about G would be off by |offset| ≈ 2.7e-2 of
    the size."""
    a, b = hull_rulings(moved, 32)
    theta = np.arctan2(a[:, 0], -(a[:, 1] + moved.origin[1] + moved.delta))   # disk 1's angle
    pose = moved.geometry(np.clip(theta, 0.0, moved.theta_max), 1)
    np.testing.assert_allclose(a, pose.contact_a, rtol=0, atol=1e-6 * LAMINA.size)
    np.testing.assert_allclose(b, pose.contact_b, rtol=0, atol=1e-6 * LAMINA.size)

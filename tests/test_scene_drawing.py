"""``twodisk-animate`` draws a scene's sloped ground, and the body on it.

References independent of the drawing code: the slope β read from config/slope.yaml with
yaml (the ground's normal must be (sin β, 0, cos β) in the gravity-aligned frame), the plane
spanned by the drawn ground quad's own corners, and the rims' polygon error (the rims are
drawn to DEFAULT_TOLERANCE × the size). Old code drew no ground and simulated a params file's
slope as the flat ground (the body's contacts at Z = 0, off the sloped plane by X tan β).
"""

import math
import os
from pathlib import Path

import numpy as np
import pytest
import yaml

from batch_recording import record
from twodisk_ros.physics.bodies.outline import DEFAULT_TOLERANCE
from twodisk_ros.plotting.animation import drawn
from twodisk_ros.runs import library_run, recorded_run, settings_from

REPO = Path(__file__).resolve().parents[1]
SLOPE_FILE = REPO / 'config' / 'slope.yaml'
ENV = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID='74',
           MPLBACKEND='Agg')


def _file_slope():
    with open(SLOPE_FILE, encoding='utf-8') as stream:
        return float(yaml.safe_load(stream)['/**']['ros__parameters']['slope'])


def _plane(quad):
    """(unit normal, offset) of the plane through the drawn quad's corners (Z up)."""
    normal = np.cross(quad[2] - quad[0], quad[3] - quad[1])
    normal = normal / np.linalg.norm(normal) * np.sign(normal[2])
    for corner in quad:          # the four corners are coplanar
        assert abs(normal @ (corner - quad[0])) <= 1e-12 * np.ptp(quad[:, :2])
    return normal, float(normal @ quad[0])


def _touches(scene, size):
    """Every drawn rim point on or above the drawn ground, each rim reaching it, and a rim
    vertex at each end of the drawn contact segment (disk 1 at A, disk 2 at B)."""
    normal, offset = _plane(scene.ground_quad)
    error = DEFAULT_TOLERANCE * size                 # sagitta of the rims' chords (m)
    spacing = 2 * math.sqrt(8 * error * size)        # chord length at that sagitta (m)
    x, y, z = (np.asarray(c, dtype=float) for c in scene.segment.get_data_3d())
    ends = np.stack([x, y, z], axis=-1)              # drawn A, B (m)
    assert np.abs(ends @ normal - offset).max() <= 1e-12 * size
    low, high = scene.ground_quad[:, :2].min(axis=0), scene.ground_quad[:, :2].max(axis=0)
    assert np.all((ends[:, :2] >= low) & (ends[:, :2] <= high))   # the ground is under them
    rims = {}
    for polygon, colour in scene.halves:
        rims.setdefault(colour, []).append(polygon)
    assert len(rims) == 2
    for (colour, parts), contact in zip(rims.items(), ends):
        points = np.concatenate(parts)
        heights = points @ normal - offset
        assert heights.min() >= -error, (colour, heights.min())
        assert heights.min() <= error, (colour, heights.min())
        assert np.linalg.norm(points - contact, axis=1).min() <= spacing


@pytest.fixture(scope='module')
def slope_run():
    return library_run(settings_from(SLOPE_FILE), stop=3.0)


def test_the_ground_drawn_is_the_slope_of_the_params_file(slope_run):
    beta = _file_slope()
    assert beta != 0.0
    scene = drawn(slope_run, size=(320, 240))
    normal, offset = _plane(scene.ground_quad)
    np.testing.assert_allclose(normal, [math.sin(beta), 0.0, math.cos(beta)], rtol=0,
                               atol=1e-14)
    assert abs(offset) <= 1e-14                      # through the origin of frame_id
    # walking downhill: G's height along gravity falls by more than the body's size x β / 4
    assert slope_run.position_g[-1, 2] < slope_run.position_g[0, 2] - 0.25 * beta * 0.1


@pytest.mark.parametrize('at', [0.05, 0.7, 1.5, 2.2, 3.0])
def test_the_drawn_rims_touch_the_drawn_slope_at_the_contacts(slope_run, at):
    scene = drawn(slope_run, at=at, start=max(0.0, at - 0.5), size=(320, 240))
    _touches(scene, slope_run.body.lamina.size)


def test_a_steep_slope_across_follow_camera(tmp_path):
    """Across a steep slope (β = 0.25 rad), the camera following G: the quad moves with the
    window and the rims still touch it."""
    run = library_run(settings_from(SLOPE_FILE, slope=0.25, heading0=0.5 * math.pi,
                                    damping=0.0), stop=1.0)
    scene = drawn(run, size=(320, 240), camera='follow')
    normal, _ = _plane(scene.ground_quad)
    np.testing.assert_allclose(normal, [math.sin(0.25), 0.0, math.cos(0.25)], atol=1e-14)
    _touches(scene, run.body.lamina.size)


def test_a_flat_run_draws_no_ground_quad():
    run = library_run(settings_from(REPO / 'config' / 'oloid.yaml'), stop=0.2)
    assert run.slope == 0.0 and drawn(run, size=(160, 120)).ground_quad is None


def test_a_recording_on_the_slope_is_drawn_on_its_slope(tmp_path):
    """A batch recording of config/slope.yaml: the run reads the slope from the recorded
    parameters, and the drawn rims touch the drawn slope at the recorded contacts (the node
    runs in this process, domain 74)."""
    out = record(tmp_path / 'slope.mcap', SLOPE_FILE, domain=int(ENV['ROS_DOMAIN_ID']),
                 duration=0.5)
    run = recorded_run(out)
    assert run.slope == _file_slope()
    _touches(drawn(run, size=(320, 240)), run.body.lamina.size)
    from twodisk_ros.plotting.animate_cli import main
    assert main([str(out), '-o', str(tmp_path / 'slope.png'), '--size', '320x240']) == 0

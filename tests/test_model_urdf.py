"""The URDF (twodisk_ros/model/urdf.py), read by independent parsers.

urdfdom's ``check_urdf`` (the C++ parser RViz's RobotModel uses, from the cmeel-urdfdom
wheel) must accept it; yourdfpy (a second, Python parser) reads the links, joints, inertial
values and meshes back. The references are the closed forms of the mass models written out
here, scipy's quaternion → matrix, the cached STL bytes and the rims' equations.
"""

import hashlib
import math
from pathlib import Path
import shutil
import subprocess
import sys
from urllib.parse import unquote, urlparse
from xml.etree import ElementTree

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
import yourdfpy

from rounding import ulps
from twodisk_ros.model.frames import disk_frames
from twodisk_ros.model.mesh import mesh_parts
from twodisk_ros.model.stl import stl_bytes
from twodisk_ros.model.urdf import body_description, robot_description
from twodisk_ros.physics import EllipseBody, mass_properties
from twodisk_ros.model import palette

# yourdfpy 0.0.60 calls a trimesh method that trimesh 5 deprecates (not ours to fix)
pytestmark = pytest.mark.filterwarnings('ignore:.*Scene.dump.*:DeprecationWarning')
# urdfdom's check_urdf: the venv's (the cmeel-urdfdom wheel's wrapper), else one on PATH
# (liburdfdom-tools in a ROS workspace)
CHECK_URDF = next((p for p in (Path(sys.executable).parent / 'check_urdf',
                               shutil.which('check_urdf')) if p and Path(p).is_file()),
                  'check_urdf')
BODIES = [(1.0, 1.0, 0.5), (2.0, 1.0, 1.0), (0.08, 0.2, 0.03), (1.0, 0.05, 0.02)]
MODELS = ['laminae', 'solid', 'custom']


def _mass(model, abd, mass=1.3):
    moments = (0.4, 0.3, 0.4) if model == 'custom' else None
    return mass_properties(model, *abd, mass, principal_moments=moments)


def _load(text, tmp_path, name='robot.urdf'):
    path = tmp_path / name
    path.write_text(text, encoding='utf-8')
    return path, yourdfpy.URDF.load(str(path), load_meshes=True, load_collision_meshes=True,
                                    build_collision_scene_graph=True)


def _check_urdf(path):
    return subprocess.run([str(CHECK_URDF), str(path)], capture_output=True, text=True,
                          timeout=60)


@pytest.mark.parametrize('model', MODELS)
@pytest.mark.parametrize('abd', BODIES, ids=str)
def test_urdf_read_back_by_urdfdom_and_yourdfpy(abd, model, tmp_path):
    body = EllipseBody(*abd)
    mass = _mass(model, abd)
    text = body_description(body, mass, 'rover', directory=tmp_path / 'cache')
    path, urdf = _load(text, tmp_path)
    checked = _check_urdf(path)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert 'root Link: rover has 2 child(ren)' in checked.stdout
    assert urdf.validate()
    assert urdf.base_link == 'rover'
    assert set(urdf.link_map) == {'rover', 'rover_disk_a', 'rover_disk_b'}
    # inertial: the mass model's values, bit for bit (shortest repr round-trips float64)
    inertial = urdf.link_map['rover'].inertial
    assert inertial.mass == mass.mass
    assert np.array_equal(inertial.inertia, mass.inertia)
    assert np.array_equal(inertial.origin[:3, 3], mass.center_of_mass)
    assert np.array_equal(inertial.origin[:3, :3], np.eye(3))
    # fixed joints whose origins are the disk frames (yourdfpy builds the matrix from rpy)
    for frame in disk_frames(body, 'rover'):
        joint = urdf.joint_map[f'{frame.child_frame_id}_joint']
        assert (joint.type, joint.parent, joint.child) == ('fixed', 'rover',
                                                           frame.child_frame_id)
        np.testing.assert_array_equal(joint.origin[:3, 3], frame.translation)
        # rpy → matrix against quaternion → matrix, each of rounded products of sines and
        # cosines (cos(π/2) in float64: 6e-17): 16 ulps of 1
        np.testing.assert_allclose(joint.origin[:3, :3],
                                   Rotation.from_quat(frame.quaternion).as_matrix(),
                                   rtol=0, atol=ulps(16))
        assert np.allclose(urdf.get_transform(frame.child_frame_id, 'rover'), joint.origin,
                           rtol=0, atol=0)
    # one visual and one collision per mesh part, each the part's STL in the cache
    parts = mesh_parts(body, mass)
    link = urdf.link_map['rover']
    assert [v.name for v in link.visuals] == [c.name for c in link.collisions] == list(parts)
    for visual, collision in zip(link.visuals, link.collisions):
        uri = visual.geometry.mesh.filename
        assert uri == collision.geometry.mesh.filename and uri.startswith('file:///')
        file = Path(unquote(urlparse(uri).path))
        data = file.read_bytes()
        assert data == stl_bytes(parts[visual.name])
        assert file.stem == hashlib.sha256(data).hexdigest()
        colour = {'disk_a': palette.A, 'disk_b': palette.B, 'hull': palette.HULL}[visual.name]
        np.testing.assert_allclose(visual.material.color.rgba, palette.rgb(colour) + (1.0,),
                                   rtol=0, atol=ulps(16))            # a decimal round trip
    # yourdfpy resolved the file:// URIs and loaded the parts' triangles (float32 in STL)
    assert set(urdf.scene.geometry) == set(parts)
    for name, loaded in urdf.scene.geometry.items():
        assert np.array_equal(loaded.triangles, parts[name].triangles.astype(np.float32))


@pytest.mark.parametrize('abd', BODIES, ids=str)
def test_urdf_disk_frames_put_the_contact_points_on_the_rims(abd, tmp_path):
    # the joint origins as the parser reads them, applied to the closed forms' A and B
    body = EllipseBody(*abd)
    _, urdf = _load(robot_description(body, _mass('laminae', abd)), tmp_path)
    geometry = body.phase_geometry(np.linspace(0, 2 * np.pi, 257))
    for child, points in (('twodisk_body_disk_a', geometry.contact_a),
                          ('twodisk_body_disk_b', geometry.contact_b)):
        pose = urdf.get_transform(child, 'twodisk_body')
        local = (points - pose[:3, 3]) @ pose[:3, :3]
        # a rotated difference of lengths of the size: 16 ulps
        assert np.abs(local[:, 2]).max() <= ulps(16, body.size)
        rim = local[:, 0] ** 2 / body.a**2 + local[:, 1] ** 2 / body.b**2 - 1
        assert np.abs(rim).max() <= 1e-12


def test_inertial_block_holds_the_closed_forms(tmp_path):
    # laminae: I11 = I33 = M(2a² + b²)/8 + MΔ², I22 = M b²/4 (docs/physics.md), written out
    a, b, d, m = 0.3, 0.2, 0.1, 2.0
    root = ElementTree.fromstring(robot_description(EllipseBody(a, b, d),
                                                    _mass('laminae', (a, b, d), m)))
    inertia = root.find("link[@name='twodisk_body']/inertial/inertia").attrib
    # the closed forms to rounding (16 ulps; the code may group the terms otherwise)
    assert math.isclose(float(inertia['ixx']), m * (2 * a * a + b * b) / 8 + m * d * d,
                        rel_tol=ulps(16))
    assert math.isclose(float(inertia['iyy']), m * b * b / 4, rel_tol=ulps(16))
    assert float(inertia['izz']) == float(inertia['ixx'])
    assert all(float(inertia[k]) == 0 for k in ('ixy', 'ixz', 'iyz'))
    assert float(root.find('link/inertial/mass').attrib['value']) == m
    # no mesh given: no visual, no collision; the structure urdfdom expects
    assert root.tag == 'robot' and root.find('link/visual') is None
    for joint in root.findall('joint'):
        assert {c.tag for c in joint} == {'parent', 'child', 'origin'}
    assert '-0.0' not in ElementTree.tostring(root, encoding='unicode')


def test_single_uri_and_unknown_part(tmp_path):
    body = EllipseBody.oloid(0.1)
    text = robot_description(body, _mass('solid', (0.1, 0.1, 0.05)), 'b',
                             'file:///tmp/x%20y.stl')
    root = ElementTree.fromstring(text)
    assert [v.get('name') for v in root.findall('link/visual')] == ['body']
    assert root.find('link/visual/geometry/mesh').get('filename') == 'file:///tmp/x%20y.stl'
    with pytest.raises(ValueError, match='unknown part'):
        robot_description(body, _mass('solid', (0.1, 0.1, 0.05)), 'b', {'wheel': 'file:///x'})


def test_check_urdf_is_a_real_check(tmp_path):
    # the reference parser refuses a joint without its child link: it does check
    body = EllipseBody.oloid()
    broken = robot_description(body, _mass('laminae', (1.0, 1.0, 0.5))).replace(
        '<link name="twodisk_body_disk_b" />', '')
    path = tmp_path / 'broken.urdf'
    path.write_text(broken, encoding='utf-8')
    assert _check_urdf(path).returncode != 0


@pytest.mark.parametrize('name', ['', 'two words', '/world'])
def test_bad_body_frame_in_one_line(name):
    with pytest.raises(ValueError) as error:
        robot_description(EllipseBody.oloid(), _mass('laminae', (1.0, 1.0, 0.5)), name)
    assert '\n' not in str(error.value)


def test_a_server_can_name_the_mesh_files_its_own_way(tmp_path):
    body = EllipseBody.oloid(0.1)
    text = body_description(body, _mass('laminae', (0.1, 0.1, 0.05)), directory=tmp_path,
                            uri=lambda path: f'package://twodisk_ros/meshes/{path.name}')
    names = [m.get('filename') for m in ElementTree.fromstring(text).iter('mesh')]
    assert len(names) == 4 and all(n.startswith('package://twodisk_ros/meshes/') for n in names)
    assert {n.rsplit('/', 1)[1] for n in names} == {p.name for p in tmp_path.iterdir()}


@pytest.mark.parametrize('model', ['laminae', 'solid'])
@pytest.mark.parametrize('arrangement', ['parallel', 'swapped'])
def test_urdf_of_a_non_elliptic_body(model, arrangement, tmp_path):
    # an egg (not symmetric along the common axis, so G is off the centres' midpoint): the
    # parsers read its meshes, and its joint origins put the exact contact points A and B of
    # ContactSolver on the egg, mapped into the disk frames as frames.py documents
    from twodisk_ros.physics.bodies.contact_solver import ContactSolver
    from twodisk_ros.physics.laminae.support import Egg
    lamina = Egg(0.2, 0.16, 0.012)
    body = ContactSolver(lamina, 0.08, arrangement)
    # the URDF only carries the mass model's numbers: an ellipse's stand in for the egg's
    mass = _mass(model, (0.2, 0.16, 0.08))
    text = body_description(body, mass, 'rover', directory=tmp_path / 'cache')
    path, urdf = _load(text, tmp_path)
    checked = _check_urdf(path)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    parts = mesh_parts(body, mass)
    assert set(urdf.scene.geometry) == set(parts)
    for name, loaded in urdf.scene.geometry.items():
        assert np.array_equal(loaded.triangles, parts[name].triangles.astype(np.float32))
    sigma = 1.0 if arrangement == 'parallel' else -1.0
    pose = body.geometry(np.linspace(-1, 1, 41) * body.theta_max, 1)
    expected_a = lamina.point(pose.parameter_a)
    for child, points in (('rover_disk_a', pose.contact_a), ('rover_disk_b', pose.contact_b)):
        frame = urdf.get_transform(child, 'rover')
        local = (points - frame[:3, 3]) @ frame[:3, :3]
        assert np.abs(local[:, 2]).max() <= ulps(16, body.size)          # as above
        # frames.py: disk 1's lamina point (x, y) is (−y, x); disk 2's is (σy, −x)
        if child.endswith('_a'):
            x, y = local[:, 1], -local[:, 0]
            # the translation's rounding (16 ulps of the size) and nothing else
            np.testing.assert_allclose(np.stack([x, y], -1), expected_a, rtol=0,
                                       atol=ulps(16, body.size))
        else:
            x, y = -local[:, 1], sigma * local[:, 0]
        # on the egg's boundary: p·n = h(n) for its outward normal n (best of 20 001)
        phi = np.linspace(0, 2 * np.pi, 20001)
        n = np.stack([np.cos(phi), np.sin(phi)], -1)
        gap = lamina.support(n).height[None, :] - np.stack([x, y], -1) @ n.T
        assert gap.min() >= -ulps(16, body.size) and gap.min(axis=1).max() <= 1e-7 * body.size

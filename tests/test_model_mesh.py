"""The body's meshes (twodisk_ros/model/mesh.py, stl.py) against the physics.

Independent references: trimesh (a second library) for closedness, winding, volume and
inertia; the oloid's volume in closed form (complete elliptic integrals, scipy.special); the
laminae's inertia in closed form, thickened here by hand (a thick elliptic plate of mass m
adds m h²/12 about its in-plane axes); the exact area of a polygon inscribed in an ellipse,
(n/2) a b sin(2π/n); the rims' equations of docs/physics.md.

Accuracy claims checked (mesh.py's docstring): vertices on the rims to rounding of the closed
forms (≤ 2e-14 of the size, 2e-13 for extreme shapes); volume and inertia converge at second order in
1/resolution (measured exponents 1.98–2.00), with relative errors ≤ 60/n² for the hull and
≤ 7/n² for the plates (measured maxima 55/n² and 6.6/n² over the bodies below).
"""

import io
import math
import os

import numpy as np
import pytest
import trimesh
from scipy.special import ellipe, ellipk

from rounding import ulps
from twodisk_ros.model.mesh import (DEFAULT_THICKNESS, Mesh, body_mesh, hull_mesh,
                                    laminae_mesh, mesh_parts)
from twodisk_ros.model.stl import cache_directory, cached_stl, stl_bytes
from twodisk_ros.outputs import OutputError
from twodisk_ros.physics import EllipseBody
from twodisk_ros.physics.mass.models import laminae, mass_properties, solid_hull

# Oloid volume / r³ = (2/3)(2E(3/4) + K(3/4)) = 3.0524184684...
OLOID_VOLUME = 2.0 / 3.0 * (2.0 * ellipe(0.75) + ellipk(0.75))
# (a, b, Δ) m: Oloid, Two-Circle-Roller, Figure 3, b > a, thin, small Δ
BODIES = [(1.0, 1.0, 0.5), (1.0, 1.0, 1 / math.sqrt(2)), (2.0, 1.0, 1.0), (0.8, 2.0, 0.3),
          (1.0, 0.05, 0.02), (1.0, 0.7, 0.01)]
EXTREMES = [(1.0, 0.01, 1e-3), (1.0, 100.0, 0.5), (1.0, 1.0, 1 - 1e-6), (2e-3, 1e-3, 5e-4)]


def _trimesh(mesh):
    return trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)


def _rim_residuals(body, points, disk=None):
    """(distance from the disk's plane, distance from its rim in the plane), both / size, and
    which disk (True: disk 1), for points on disk 1 or disk 2. The in-plane distance is
    F/|∇F| of the rim equation F = 0 (first order, exact enough at 1e-13)."""
    a, b, d = body.a, body.b, body.delta
    x1, x2, x3 = points.T
    on_1 = np.abs(x3) <= np.abs(x1) if disk is None else np.full(len(points), disk == 1)
    plane = np.where(on_1, np.abs(x3), np.abs(x1)) / body.size
    across = np.where(on_1, x1, x3)          # along the semi-axis b
    along = np.where(on_1, x2 + d, x2 - d)   # along the semi-axis a, from the centre
    rim = across**2 / b**2 + along**2 / a**2 - 1
    gradient = 2 * np.hypot(across / b**2, along / a**2)
    return plane, np.abs(rim) / gradient / body.size, on_1


@pytest.mark.parametrize('model', ['laminae', 'solid'])
@pytest.mark.parametrize('abd', BODIES + EXTREMES, ids=str)
def test_meshes_are_closed_and_wound_outward(abd, model):
    body = EllipseBody(*abd)
    for part in mesh_parts(body, model, 64).values():
        mesh = _trimesh(part)
        assert mesh.is_watertight and mesh.is_winding_consistent
        assert mesh.volume > 0                       # consistent AND outward
        # each part is convex (a prism over a convex polygon, or a convex hull): every
        # face's outward normal has the whole part behind its plane, to rounding
        centre = part.vertices.mean(axis=0)
        normals = part.normals
        corners = part.triangles
        assert np.all(np.einsum('ij,ij->i', normals, corners.mean(axis=1) - centre) > 0)
        heights = (part.vertices[None, :, :] - corners[:, None, 0]) @ np.eye(3)
        heights = np.einsum('fvk,fk->fv', heights, normals)
        assert heights.max() <= 1e-12 * body.size


@pytest.mark.parametrize('abd', BODIES + EXTREMES, ids=str)
def test_hull_vertices_lie_on_the_rims_and_cover_both(abd):
    body = EllipseBody(*abd)
    mesh = hull_mesh(body, 128)
    plane, rim, on_1 = _rim_residuals(body, mesh.vertices)
    # the closed forms' accuracy (bodies/ellipse.py): lengths to 2e-14 of the size, 2e-13 at extremes;
    # off the disk's plane by rounding only (16 ulps of the size)
    assert plane.max() <= ulps(16)
    assert rim.max() <= (2e-14 if abd in BODIES else 2e-13)
    # the hull keeps every sampled point: n/2 + 1 on each rim (no point inside the hull)
    assert on_1.sum() == 65 and (~on_1).sum() == 65
    # and it reaches both far tips (θ = 0 and ψ = 0), the extreme points along ∓e2
    size = body.a + body.delta
    assert np.isclose(mesh.vertices[:, 1].min(), -size, rtol=ulps(16), atol=0)
    assert np.isclose(mesh.vertices[:, 1].max(), size, rtol=ulps(16), atol=0)


@pytest.mark.parametrize('abd', BODIES, ids=str)
def test_plate_vertices_project_onto_the_rims(abd):
    body = EllipseBody(*abd)
    half = DEFAULT_THICKNESS * body.size / 2
    disk_a, disk_b = mesh_parts(body, 'custom', 64).values()
    for index, part in enumerate((disk_a, disk_b)):
        points = part.vertices.copy()
        normal = 2 if index == 0 else 0                  # disk 1: x3 = 0; disk 2: x1 = 0
        np.testing.assert_allclose(np.abs(points[:, normal]), half, rtol=ulps(16))
        points[:, normal] = 0
        plane, rim, _ = _rim_residuals(body, points[:-2], index + 1)   # last 2: face centres
        # a cos, b sin: rounding only (16 ulps)
        assert plane.max() == 0 and rim.max() <= ulps(16)
    # the volume is that of two prisms over the inscribed 64-gon, exactly
    volume = 2 * 2 * half * 32 * body.a * body.b * math.sin(2 * math.pi / 64)
    assert _trimesh(laminae_mesh(body, 64)).volume == pytest.approx(volume, rel=1e-14)


def _solid_errors(body, resolution, reference):
    mesh = _trimesh(body_mesh(body, 'solid', resolution))
    mesh.density = reference.mass / mesh.volume
    inertia = mesh.moment_inertia
    return (mesh.volume / reference.volume - 1,
            np.abs(inertia - reference.inertia).max() / np.abs(reference.inertia).max())


def test_oloid_hull_volume_converges_to_the_closed_form_at_second_order():
    radius = 0.3
    body = EllipseBody.oloid(radius)
    errors = []
    for n in (64, 128, 256, 512):
        volume = _trimesh(body_mesh(body, 'solid', n)).volume
        errors.append(volume / (OLOID_VOLUME * radius**3) - 1)
    errors = np.array(errors)
    assert np.all(errors < 0)                       # inscribed: the mesh is inside the hull
    assert np.all(np.abs(errors) * np.array([64, 128, 256, 512]) ** 2 <= 60)
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((orders > 1.95) & (orders < 2.05)), orders
    # Richardson: the O(n⁻²) term removed, what is left is far below it
    extrapolated = (4 * errors[-1] - errors[-2]) / 3
    assert abs(extrapolated) <= 1e-2 * abs(errors[-1])     # measured 3.6e-3


@pytest.mark.parametrize('abd', BODIES, ids=str)
def test_hull_volume_and_inertia_match_the_solid_model_within_resolution(abd):
    body = EllipseBody(*abd)
    reference = solid_hull(*abd, 2.5, rtol=1e-12)
    volume, inertia = np.array([_solid_errors(body, n, reference) for n in (128, 256, 512)]).T
    n2 = np.array([128, 256, 512]) ** 2
    assert np.all(np.abs(volume) * n2 <= 60) and np.all(inertia * n2 <= 60)
    for errors in (volume, inertia):
        orders = np.log2(np.abs(errors[:-1] / errors[1:]))
        assert np.all((orders > 1.9) & (orders < 2.1)), orders


@pytest.mark.parametrize('abd', BODIES, ids=str)
def test_plate_inertia_matches_the_laminae_model_thickened(abd):
    body = EllipseBody(*abd)
    mass = 1.7
    thickness = DEFAULT_THICKNESS * body.size
    # two plates of mass M/2, each thickened by h: + (M/2) h²/12 about both in-plane axes;
    # disk 1's in-plane axes are e1, e2, disk 2's are e2, e3
    expected = laminae(*abd, mass).inertia + mass * thickness**2 * np.diag([1, 2, 1]) / 24
    errors, inertias = [], []
    for n in (128, 256, 512):
        mesh = _trimesh(body_mesh(body, 'laminae', n))
        mesh.density = mass / mesh.volume     # the plates' crossing counted twice, as M/2 + M/2
        # 0 by the mesh's symmetry, to the rounding of trimesh's sums (measured ≤ 0.05 ulp)
        np.testing.assert_allclose(mesh.center_mass, 0, atol=ulps(16, body.size))
        inertias.append(mesh.moment_inertia)
        errors.append(np.abs(mesh.moment_inertia - expected).max() / np.abs(expected).max())
    errors = np.array(errors)
    assert np.all(errors * np.array([128, 256, 512]) ** 2 <= 7)
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((orders > 1.95) & (orders < 2.05)), orders
    # Richardson (the O(n⁻²) term removed) leaves the thickened plates' inertia to far below
    # the thickness term, which separates them from the thin-plate model
    extrapolated = (4 * inertias[-1] - inertias[-2]) / 3
    thickness_term = mass * thickness**2 / 12
    assert np.abs(extrapolated - expected).max() <= 1e-4 * thickness_term   # measured 1.2e-5


def test_model_choice_and_defaults():
    body = EllipseBody(2.0, 1.0, 1.0)
    solid = mass_properties('solid', 2.0, 1.0, 1.0, 1.0)
    assert list(mesh_parts(body, solid)) == ['hull']
    assert list(mesh_parts(body, 'laminae')) == ['disk_a', 'disk_b']
    assert len(body_mesh(body, 'custom').vertices) == 2 * (2 * 256 + 2)
    merged = body_mesh(body, 'laminae', 16)
    parts = list(mesh_parts(body, 'laminae', 16).values())
    assert np.array_equal(merged.vertices, np.concatenate([p.vertices for p in parts]))


@pytest.mark.parametrize('kwargs', [dict(resolution=10), dict(resolution=4),
                                    dict(resolution=16.0), dict(resolution=True),
                                    dict(mass_model='lead'), dict(mass_model=None),
                                    dict(thickness=-0.1), dict(thickness=float('nan')),
                                    dict(thickness=5.0), dict(thickness='thin')])
def test_bad_mesh_arguments_are_refused_in_one_line(kwargs):
    with pytest.raises(ValueError) as error:
        body_mesh(EllipseBody.oloid(), **{'mass_model': 'laminae', **kwargs})
    assert '\n' not in str(error.value)
    assert next(iter(kwargs)) in str(error.value)


def test_mesh_validates_its_arrays():
    with pytest.raises(ValueError):
        Mesh(np.zeros((3, 2)), [[0, 1, 2]])
    with pytest.raises(ValueError):
        Mesh(np.zeros((3, 3)), [[0, 1, 3]])


@pytest.mark.parametrize('model', ['laminae', 'solid'])
def test_stl_read_back_by_trimesh_is_the_mesh(model):
    mesh = body_mesh(EllipseBody(0.8, 2.0, 0.3), model, 32)
    data = stl_bytes(mesh)
    assert len(data) == 84 + 50 * len(mesh.faces)
    loaded = trimesh.load(io.BytesIO(data), file_type='stl', process=False)
    # binary STL holds float32: the corners are the mesh's, rounded to float32, exactly
    assert np.array_equal(loaded.triangles, mesh.triangles.astype(np.float32))
    # trimesh's own face normals (from the corners) agree with the stored outward ones
    np.testing.assert_allclose(loaded.face_normals, mesh.normals, atol=1e-6)
    merged = trimesh.load(io.BytesIO(data), file_type='stl')     # vertices merged
    assert merged.is_watertight and merged.is_winding_consistent and merged.volume > 0


def test_cache_is_content_addressed_and_atomic(tmp_path, monkeypatch):
    monkeypatch.setenv('XDG_CACHE_HOME', str(tmp_path / 'xdg'))
    assert cache_directory() == tmp_path / 'xdg' / 'twodisk_ros' / 'meshes'
    oloid = body_mesh(EllipseBody.oloid(), 'solid', 32)
    path = cached_stl(oloid)
    assert path.parent == cache_directory() and path.is_absolute()
    assert path.read_bytes() == stl_bytes(oloid)
    import hashlib
    assert path.stem == hashlib.sha256(path.read_bytes()).hexdigest()
    # the same mesh again: the same file, not rewritten
    inode, mtime = path.stat().st_ino, path.stat().st_mtime_ns
    assert cached_stl(body_mesh(EllipseBody.oloid(), 'solid', 32)) == path
    assert (path.stat().st_ino, path.stat().st_mtime_ns) == (inode, mtime)
    # another body: another file; nothing else (no temporary file) left in the directory
    other = cached_stl(body_mesh(EllipseBody.oloid(1.5), 'solid', 32))
    assert other != path
    assert sorted(os.listdir(path.parent)) == sorted([path.name, other.name])
    # XDG_CACHE_HOME relative or empty: ~/.cache, as the XDG rules say
    monkeypatch.setenv('HOME', str(tmp_path / 'home'))
    for value in ('relative/dir', ''):
        monkeypatch.setenv('XDG_CACHE_HOME', value)
        assert cache_directory() == tmp_path / 'home' / '.cache' / 'twodisk_ros' / 'meshes'


def test_cache_that_cannot_be_written_says_so_in_one_line(tmp_path):
    blocker = tmp_path / 'a_file'
    blocker.write_text('not a directory')
    with pytest.raises(OutputError) as error:
        cached_stl(body_mesh(EllipseBody.oloid(), 'solid', 16), blocker / 'meshes')
    assert '\n' not in str(error.value) and 'XDG_CACHE_HOME' in str(error.value)
    assert blocker.read_text() == 'not a directory'

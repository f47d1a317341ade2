"""Triangle meshes of the two-disk body in the body frame, for viewers and the URDF.

Body frame ``G e1 e2 e3`` as in docs/physics.md (metres). Every mesh is closed (each edge is
shared by exactly two faces) and its faces are wound counter-clockwise seen from outside, so
their right-hand normals point out. Any RollingBody: a EllipseBody (ellipses, closed forms)
or a LaminaBody (any lamina); each gives its rims and hull (``plate_rims``, ``hull_surface``).

``'laminae'`` (and ``'custom'``, whose geometry is the same two disks)
    Each disk as a thin plate: a closed prism over its rim, ``thickness`` thick, centred on
    the disk's plane, with one centre vertex per face. In the disk frames of
    :mod:`~twodisk_ros.model.frames` an ellipse's plate has ``resolution`` rim vertices on
    each face at eccentric anomalies 2πk/resolution, (a cos, b sin, ±thickness/2); any other
    lamina's rim is the polygon of
    :func:`~twodisk_ros.physics.bodies.outline.lamina_outline` whose error is that of a
    regular ``resolution``-gon in a circle, (1 − cos(π/n)) × the lamina's size. The two
    plates cross each other along the common axis (each disk's plane cuts the other disk);
    the mesh keeps them as two closed components, so a volume integral over
    the mesh counts the crossing twice, as the ``laminae`` mass model counts two plates of
    mass M/2 each.
``'solid'``
    The convex hull of the two rims, the body of the ``solid`` mass model. For ellipses its
    vertices are the contact points A (on rim 1) and B (on rim 2) of the closed forms at
    ``resolution`` equal steps of the phase u per cycle: those points are exactly the ends of
    the hull's rulings (docs/physics.md#mass-models), and the rest of each rim lies inside
    the hull. Their convex hull (scipy's Qhull) is the mesh; its edges follow the rulings.
    For any other lamina the rulings come from the exact contact geometry and the mesh is
    the strips between consecutive ones (:mod:`~twodisk_ros.physics.bodies.rulings`); its
    volume converges at second order to that of scipy's ConvexHull of densely sampled rims
    (3.3e-5 low at n = 256 for a Superellipse(1, 1, 6), 5.8e-5 for an Egg(1, 0.8, 0.06),
    tests/test_model_outline.py).

Vertices are on the exact outlines: on the rims, to rounding of the closed forms (≤ 2e-14 of
the size); for the plates, their projections on the disk's plane. A polygon inscribed in a
smooth curve with steps h misses O(h²) of its area, so volume and inertia converge at second
order in 1/resolution n (measured exponents 1.98–2.00, tests/test_model_mesh.py): the hull's
volume and inertia within 55/n² of the ``solid`` model (the Oloid's volume 22/n²: 3.4e-4 at
the default n = 256), the plates' inertia within 6.6/n² of the ``laminae`` model plus the
plates' own thickness term (M h²/24 about e1 and e3, M h²/12 about e2).
"""

from dataclasses import dataclass
import math

import numpy as np

from twodisk_ros.physics.mass.models import MODELS

from .frames import disk_frames

__all__ = ['Mesh', 'body_mesh', 'mesh_parts', 'laminae_mesh', 'hull_mesh', 'merge',
           'DEFAULT_RESOLUTION', 'DEFAULT_THICKNESS']

#: Rim vertices per disk (laminae) and phase steps per cycle (solid hull).
DEFAULT_RESOLUTION = 256
#: Thickness of the laminae's plates, as a fraction of the body's size L (EllipseBody.size).
DEFAULT_THICKNESS = 0.02


@dataclass(frozen=True, eq=False)
class Mesh:
    """A closed triangle mesh.

    Attributes
    ----------
    vertices : numpy.ndarray, shape (n, 3), float64
        Points in the body frame (m).
    faces : numpy.ndarray, shape (m, 3), int64
        Vertex indices, counter-clockwise seen from outside (outward right-hand normals).
    """

    vertices: np.ndarray
    faces: np.ndarray

    def __post_init__(self):
        vertices = np.array(self.vertices, dtype=np.float64)
        faces = np.array(self.faces, dtype=np.int64)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f'vertices must have shape (n, 3), got {vertices.shape}')
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f'faces must have shape (m, 3), got {faces.shape}')
        if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
            raise ValueError(f'faces must index the {len(vertices)} vertices')
        vertices.setflags(write=False)
        faces.setflags(write=False)
        object.__setattr__(self, 'vertices', vertices)
        object.__setattr__(self, 'faces', faces)

    @property
    def triangles(self):
        """The faces' corners, shape (m, 3, 3) (m, body frame)."""
        return self.vertices[self.faces]

    @property
    def normals(self):
        """Unit outward normals of the faces, shape (m, 3) (zero for a degenerate face)."""
        corners = self.triangles
        cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        length = np.linalg.norm(cross, axis=1, keepdims=True)
        return np.divide(cross, length, out=np.zeros_like(cross), where=length > 0)


def _resolution(resolution):
    if isinstance(resolution, (bool, np.bool_)) or not isinstance(resolution,
                                                                  (int, np.integer)) \
            or resolution < 8 or resolution % 4:
        raise ValueError(f'resolution must be an integer multiple of 4, at least 8, got '
                         f'{resolution!r}')
    return int(resolution)


def _model_name(mass_model):
    name = getattr(mass_model, 'model', mass_model)
    if not isinstance(name, str) or name not in MODELS:
        allowed = ', '.join(repr(m) for m in MODELS)
        raise ValueError(f'mass_model must be one of {allowed} or a MassProperties, got '
                         f'{mass_model!r}')
    return name


def merge(meshes):
    """One :class:`Mesh` holding all of ``meshes`` (an iterable of Mesh) as its components."""
    vertices, faces, offset = [], [], 0
    for mesh in meshes:
        vertices.append(mesh.vertices)
        faces.append(mesh.faces + offset)
        offset += len(mesh.vertices)
    return Mesh(np.concatenate(vertices), np.concatenate(faces))


def body_mesh(body, mass_model='laminae', resolution=DEFAULT_RESOLUTION, thickness=None):
    """The mesh that shows ``body`` under a mass model: all of :func:`mesh_parts` in one.

    Parameters
    ----------
    body : EllipseBody or LaminaBody
    mass_model : str or twodisk_ros.physics.mass.models.MassProperties
        ``'solid'`` gives the convex hull (:func:`hull_mesh`); ``'laminae'`` and ``'custom'``
        the two plates (:func:`laminae_mesh`).
    resolution : int
        Multiple of 4, ≥ 8: for ellipses, rim vertices per plate or phase steps per cycle
        for the hull; for any other lamina the sampling whose error is that of a regular
        n-gon (module docstring; the vertex count follows the shape).
    thickness : float, optional
        Plate thickness (m) for the plates; default ``DEFAULT_THICKNESS * body.size``.
        Ignored for the hull.

    Returns
    -------
    Mesh
    """
    return merge(mesh_parts(body, mass_model, resolution, thickness).values())


def mesh_parts(body, mass_model='laminae', resolution=DEFAULT_RESOLUTION, thickness=None):
    """The closed parts of :func:`body_mesh` (same arguments), to colour them apart.

    Returns
    -------
    dict of str to Mesh
        ``{'disk_a': plate of disk 1, 'disk_b': plate of disk 2}`` for ``'laminae'`` and
        ``'custom'``; ``{'hull': the convex hull}`` for ``'solid'``. Body frame (m).
    """
    if _model_name(mass_model) == 'solid':
        return {'hull': hull_mesh(body, resolution)}
    return dict(zip(('disk_a', 'disk_b'), _plates(body, resolution, thickness)))


def laminae_mesh(body, resolution=DEFAULT_RESOLUTION, thickness=None):
    """The two disks as closed prisms over their rims (module docstring), body frame (m)."""
    return merge(_plates(body, resolution, thickness))


def _plates(body, resolution, thickness):
    n = _resolution(resolution)
    if thickness is None:
        thickness = DEFAULT_THICKNESS * body.size
    if isinstance(thickness, (bool, str, bytes)) or not np.isscalar(thickness) \
            or not (math.isfinite(float(thickness)) and 0 < float(thickness) < body.size):
        raise ValueError(f'thickness must be a number of metres in (0, size = {body.size!r}), '
                         f'got {thickness!r}')
    half = 0.5 * float(thickness)
    return tuple(_prism(rim, half, frame)
                 for rim, frame in zip(body.plate_rims(n), disk_frames(body)))


def _prism(rim, half, frame):
    """A closed prism over a counterclockwise polygon ``rim`` (n, 2) of the frame's plane,
    from −half to +half along its z, in the body frame."""
    n = len(rim)
    # local vertices: top rim 0..n−1, bottom rim n..2n−1, top centre 2n, bottom centre 2n+1
    local = np.zeros((2 * n + 2, 3))
    local[:n, :2] = local[n:2 * n, :2] = rim
    local[:n, 2], local[n:2 * n, 2] = half, -half
    local[2 * n:, 2] = half, -half
    k = np.arange(n)
    k1 = (k + 1) % n
    top, bottom = 2 * n, 2 * n + 1
    faces = np.concatenate([
        np.stack([np.full(n, top), k, k1], axis=1),                 # top face, normal +z
        np.stack([np.full(n, bottom), n + k1, n + k], axis=1),      # bottom face, normal −z
        np.stack([n + k, n + k1, k1], axis=1),                      # side, outward
        np.stack([n + k, k1, k], axis=1),
    ])
    return Mesh(local @ frame.axes.T + frame.translation, faces)


def hull_mesh(body, resolution=DEFAULT_RESOLUTION):
    """The convex hull of the two rims (see the module docstring), body frame (m): the
    body's :meth:`~twodisk_ros.physics.bodies.protocol.RollingBody.hull_surface`."""
    return Mesh(*body.hull_surface(_resolution(resolution)))

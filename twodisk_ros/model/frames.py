"""The frames of the two disks, fixed in the body: where /tf_static and the URDF put them.

Parent frame: the body frame ``G e1 e2 e3`` of docs/physics.md, published as ``body_frame``
(default ``twodisk_body``): origin at G, the same orientation as the node's ``pose``
(v_world = R v_body). Lengths in metres, quaternions (x, y, z, w), scalar last as in ROS,
rotating disk frame → body frame (the body-frame components of a disk-frame vector v are
R v), so a ``geometry_msgs/Transform`` with parent ``body_frame`` and child the disk frame
carries ``translation`` and ``quaternion`` as they are.

Each disk frame has its origin at the disk's centre, z normal to the disk's plane, and its
x axis along the common axis pointing away from G, towards the disk's far tip (where
θ = 0, resp. ψ = 0); y completes the right-handed frame. The contact angle of the disk is
the polar angle from x towards y. For ellipses the rim is x²/a² + y²/b² = 1, z = 0, on both
disks, so the contact point is ρ (cos ∠, sin ∠, 0) with ρ = ab/D(∠); for any lamina
(:mod:`~twodisk_ros.physics.bodies.outline`) disk 1's lamina point (x, y) is (−y, x, 0) in its frame
and disk 2's is (σy, −x, 0), σ = ±1 the arrangement:

``{body_frame}_disk_a`` — disk 1, which carries the contact point A (angle θ):
    centre C1 = −Δ e2 − G; x = −e2, y = +e1, z = +e3 (a turn by −90° about e3).
``{body_frame}_disk_b`` — disk 2, which carries the contact point B (angle ψ):
    centre C2 = +Δ e2 − G; x = +e2, y = −e3, z = −e1.

G is the laminae's centroid seen from the midpoint of the centres
(:attr:`ContactSolver.centroid <twodisk_ros.physics.bodies.contact_solver.ContactSolver>`,
along e2): zero for laminae symmetric along the common axis (ellipses, superellipses), not
for an egg in the 'parallel' arrangement. A body moved by
:meth:`LaminaBody.about <twodisk_ros.physics.bodies.lamina_body.LaminaBody.about>` (the solid egg,
centred on its centre of mass) has its origin at P = ``body.origin`` instead, and G above
reads P (the centres at ∓Δ e2 − P). The two rotations are exact (quaternion components
0, ±1/2, ±√½) and the same for every body; only the translations depend on it.
"""

from dataclasses import dataclass
import math

import numpy as np

from twodisk_ros.physics.bodies.outline import DEFAULT_TOLERANCE, body_shape, frame_rims

__all__ = ['DiskFrame', 'disk_frames', 'disk_rims', 'check_frame_id', 'DISK_SUFFIXES']

#: The suffixes of the disk frames' names, after the body frame's: disk 1 (A), disk 2 (B).
DISK_SUFFIXES = ('_disk_a', '_disk_b')

_HALF_SQRT2 = math.sqrt(0.5)
# Columns: the disk frame's x, y, z axes in the body frame (exact integers).
_AXES = (np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
         np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]))
# The same rotations as unit quaternions (x, y, z, w), w > 0.
_QUATERNIONS = ((0.0, 0.0, -_HALF_SQRT2, _HALF_SQRT2), (-0.5, -0.5, 0.5, 0.5))
# Sign of the centre along e2: C1 = −Δ e2, C2 = +Δ e2.
_CENTRE_SIGNS = (-1.0, 1.0)


def check_frame_id(name, what='body_frame'):
    """Return ``name`` if it is a usable tf2 frame id, else raise a one-line ValueError.

    Allowed: a non-empty string without whitespace and without a leading ``/`` (tf2 refuses
    frame ids that start with a slash).
    """
    if not isinstance(name, str) or not name or any(c.isspace() for c in name) \
            or name.startswith('/'):
        raise ValueError(f'{what} must be a non-empty frame name without spaces or a leading '
                         f'"/", got {name!r}')
    return name


@dataclass(frozen=True, eq=False)
class DiskFrame:
    """One disk's frame relative to the body frame (a static transform).

    Attributes
    ----------
    child_frame_id : str
        ``f'{body_frame}_disk_a'`` (disk 1, contact A) or ``f'{body_frame}_disk_b'``
        (disk 2, contact B).
    translation : numpy.ndarray, shape (3,)
        The disk's centre in the body frame (m): (0, ∓Δ − g, 0), g = the body origin's (G's
        or P's) offset from O along e2.
    quaternion : numpy.ndarray, shape (4,)
        (x, y, z, w), unit, w > 0: rotates disk-frame components into body-frame ones.
    parent_frame_id : str
        The body frame's name.
    axes : numpy.ndarray, shape (3, 3)
        The same rotation as a matrix, disk frame → body frame: its columns are the disk's
        x, y, z axes in the body frame (exact entries 0, ±1).
    """

    child_frame_id: str
    translation: np.ndarray
    quaternion: np.ndarray
    parent_frame_id: str
    axes: np.ndarray

    def to_disk(self, points):
        """Body-frame points (m, shape (..., 3)) expressed in this disk's frame (m)."""
        return (np.asarray(points, dtype=float) - self.translation) @ self.axes


def disk_frames(body, body_frame='twodisk_body'):
    """The two disk frames of ``body`` (a EllipseBody), relative to ``body_frame``.

    Parameters
    ----------
    body : EllipseBody, LaminaBody or ContactSolver
        Uses ``body.delta`` (m) and G's offset (:func:`~twodisk_ros.physics.bodies.outline.body_shape`).
    body_frame : str
        The parent frame's name (see :func:`check_frame_id`).

    Returns
    -------
    tuple of DiskFrame
        (disk 1 / contact A, disk 2 / contact B); see the module docstring for the axes.
    """
    check_frame_id(body_frame)
    shape = body_shape(body)
    frames = []
    for suffix, sign, quaternion, axes in zip(DISK_SUFFIXES, _CENTRE_SIGNS, _QUATERNIONS, _AXES):
        centre = np.array([0.0, sign * shape.delta, 0.0]) - shape.centroid
        arrays = [centre, np.array(quaternion), axes.copy()]
        for array in arrays:
            array.setflags(write=False)
        frames.append(DiskFrame(body_frame + suffix, arrays[0], arrays[1], body_frame,
                                arrays[2]))
    return tuple(frames)


def disk_rims(body, tolerance=DEFAULT_TOLERANCE, closed=True):
    """Both rims in the body frame (m, from the body's origin G or P): (rim of disk 1, rim of disk 2), arrays
    (N + 1, 3) with the last point the first (``closed``) or (N, 3).

    Disk 1 lies in x3 = 0, disk 2 in x1 = 0; each starts at its far tip along e2 (−e2 for
    disk 1, +e2 for disk 2) and reaches the near tip at index N/2.
    """
    rims = []
    for frame, rim in zip(disk_frames(body), frame_rims(body, tolerance)):
        local = np.zeros((len(rim), 3))
        local[:, :2] = rim
        points = local @ frame.axes.T + frame.translation
        rims.append(np.vstack([points, points[:1]]) if closed else points)
    return tuple(rims)

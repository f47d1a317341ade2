"""What ``twodisk-view`` shows, as Foxglove messages (``foxglove.messages``; no rclpy).

Every function takes numbers in SI units (m, N, ns) in the frames named by the node's
parameters: the world frame ``frame_id`` (Z up, the ground z = 0), the body frame
``body_frame`` (origin G, v_world = R v_body) and the two disk frames
``{body_frame}_disk_a`` / ``_disk_b`` of :func:`twodisk_ros.model.frames.disk_frames`
(centre of the disk, z normal to its plane, x along the common axis towards its far tip).
Quaternions are (x, y, z, w), rotating child-frame components into parent-frame ones, as in
ROS and in ``foxglove.FrameTransform``. Colours come from
:mod:`twodisk_ros.model.palette` (plain hex strings, no matplotlib): disk 1 and A blue,
disk 2 and B orange, AB green.
"""

import math

import numpy as np
from foxglove.messages import (ArrowPrimitive, Color, FrameTransform, FrameTransforms,
                               LinePrimitive, LinePrimitiveLineType, Point3, Pose, Quaternion,
                               SceneEntity, SceneUpdate, Timestamp, TriangleListPrimitive,
                               Vector3)

from ..physics.bodies.outline import DEFAULT_TOLERANCE, frame_rims
from ..model import palette

__all__ = ['PART_COLOURS', 'Traces', 'body_update', 'color', 'contact_update', 'force_arrows',
           'force_update', 'frame_transforms', 'timestamp', 'trace_update']

#: Line width of the contact segment, the rims and the traces, as a share of the body size.
LINE_WIDTH = 0.01
#: Force arrows as the node's markers draw them: shaft and head diameters, head length (× size).
SHAFT_DIAMETER, HEAD_DIAMETER, HEAD_LENGTH = 0.01, 0.02, 0.03
#: Opacity of the body's mesh (the rims and the contact segment stay opaque).
MESH_ALPHA = 0.55
#: Polygon error of the drawn rims, as a fraction of the lamina's size (physics/bodies/outline.py).
RIM_TOLERANCE = DEFAULT_TOLERANCE


def timestamp(stamp_ns):
    """A ``foxglove`` Timestamp of an integer time in ns (exact: sec and nsec)."""
    sec, nsec = divmod(int(stamp_ns), 1_000_000_000)
    return Timestamp(sec, nsec)


def color(hex_colour, alpha=1.0):
    """A ``foxglove`` Color of a palette entry ``'#rrggbb'`` and an opacity in [0, 1]."""
    r, g, b = palette.rgb(hex_colour)
    return Color(r=r, g=g, b=b, a=float(alpha))


def _point(xyz):
    return Point3(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def _transform(stamp, parent, child, translation, quaternion):
    t, q = translation, quaternion
    return FrameTransform(timestamp=stamp, parent_frame_id=parent, child_frame_id=child,
                          translation=Vector3(x=float(t[0]), y=float(t[1]), z=float(t[2])),
                          rotation=Quaternion(x=float(q[0]), y=float(q[1]), z=float(q[2]),
                                              w=float(q[3])))


def frame_transforms(stamp_ns, frame_id, body_frame, position_g, quaternion, disks=()):
    """World → body (the pose of the sample) and body → each disk frame, one stamp.

    Parameters
    ----------
    stamp_ns : int
        The sample's stamp (ns).
    frame_id, body_frame : str
        Parent (world) and child (body) frame names.
    position_g : array (3,)
        G in the world frame (m): the body frame's translation.
    quaternion : array (4,)
        x, y, z, w, body → world: the body frame's rotation, exactly as sampled.
    disks : sequence of DiskFrame
        The static disk frames (``child_frame_id``, ``translation`` in m, ``quaternion``),
        sent with every sample so that a client joining late has the whole tree at once.
    """
    stamp = timestamp(stamp_ns)
    items = [_transform(stamp, frame_id, body_frame, position_g, quaternion)]
    items += [_transform(stamp, body_frame, d.child_frame_id, d.translation, d.quaternion)
              for d in disks]
    return FrameTransforms(transforms=items)


def _rim(rim):
    """A rim (n, 2) in its disk's frame (m, z = 0) as Foxglove points of a closed loop."""
    return [Point3(x=float(x), y=float(y), z=0.0) for x, y in np.asarray(rim, dtype=float)]


#: Colours of the mesh's parts (:func:`twodisk_ros.model.mesh.mesh_parts`), as in the URDF.
PART_COLOURS = {'disk_a': palette.A, 'disk_b': palette.B, 'hull': palette.HULL}


def _surface(mesh, colour):
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1)
    return TriangleListPrimitive(
        pose=Pose(position=Vector3(), orientation=Quaternion(w=1.0)),
        points=[_point(v) for v in np.asarray(mesh.vertices, dtype=float)],
        color=color(colour, MESH_ALPHA), indices=[int(k) for k in faces])


def body_update(stamp_ns, body_frame, body, parts, disks):
    """The body: its mesh in the body frame and the two rims in the disk frames.

    Each entity is ``frame_locked``, so it follows its frame as the transforms arrive and
    needs sending only once (again when a client subscribes).

    Parameters
    ----------
    body : EllipseBody, LaminaBody or ContactSolver
        For the rims: the real outline of ``body.lamina`` (physics/bodies/outline.py), to a polygon
        error of :data:`RIM_TOLERANCE` of its size.
    parts : dict of str to Mesh
        The body's closed parts (``vertices`` (n, 3) in m, body frame; ``faces`` (m, 3)
        int), as :func:`twodisk_ros.model.mesh.mesh_parts` gives them: the plates
        ``disk_a`` (blue) and ``disk_b`` (orange), or the ``hull`` (grey).
    disks : pair of DiskFrame
        Disk 1 (A, blue) and disk 2 (B, orange).
    """
    stamp = timestamp(stamp_ns)
    surfaces = [_surface(mesh, PART_COLOURS.get(name, palette.HULL))
                for name, mesh in parts.items()]
    entities = [SceneEntity(timestamp=stamp, frame_id=body_frame, id='body', frame_locked=True,
                            triangles=surfaces)]
    width = LINE_WIDTH * body.size
    rims = frame_rims(body, RIM_TOLERANCE)
    for disk, colour, points in zip(disks, (palette.A, palette.B), rims):
        rim = LinePrimitive(type=LinePrimitiveLineType.LineLoop,
                            pose=Pose(position=Vector3(), orientation=Quaternion(w=1.0)),
                            thickness=width, points=_rim(points), color=color(colour))
        entities.append(SceneEntity(timestamp=stamp, frame_id=disk.child_frame_id,
                                    id='rim' + disk.child_frame_id[-2:], frame_locked=True,
                                    lines=[rim]))
    return SceneUpdate(entities=entities)


def contact_update(stamp_ns, frame_id, contact_a, contact_b, size):
    """The contact segment AB (green) in the world frame, A and B in m; ``size`` in m."""
    line = LinePrimitive(type=LinePrimitiveLineType.LineStrip,
                         pose=Pose(position=Vector3(), orientation=Quaternion(w=1.0)),
                         thickness=LINE_WIDTH * size,
                         points=[_point(contact_a), _point(contact_b)], color=color(palette.AB))
    return SceneUpdate(entities=[SceneEntity(timestamp=timestamp(stamp_ns), frame_id=frame_id,
                                             id='contact_segment', lines=[line])])


def _x_to(direction):
    """The unit quaternion (x, y, z, w) turning +x onto the unit vector ``direction``."""
    d = np.asarray(direction, dtype=float)
    w = 1.0 + d[0]
    if w < 1e-12:                       # d = −x: half a turn about z
        return (0.0, 0.0, 1.0, 0.0)
    q = np.array([0.0, -d[2], d[1], w])
    return tuple(q / np.linalg.norm(q))


def force_arrows(points, forces, weight, size):
    """ArrowPrimitives of the ground's forces at A and B (world frame).

    Each arrow starts at its contact point (m) and is ``|F| / (M g) × size`` long, as the
    node's force markers are (the weight M g itself would be one body size); purple
    (:data:`palette.FORCE`), red when the force pulls the body down (F_z < 0,
    :data:`palette.FORCE_PULLING`). A zero force draws nothing.
    """
    scale = size / weight if weight > 0 else 0.0
    arrows = []
    for point, force in zip(points, forces):
        force = np.asarray(force, dtype=float)
        length = scale * float(np.linalg.norm(force))
        if not (math.isfinite(length) and length > 0):
            continue
        head = min(HEAD_LENGTH * size, length)
        q = _x_to(force / np.linalg.norm(force))
        pose = Pose(position=Vector3(x=float(point[0]), y=float(point[1]), z=float(point[2])),
                    orientation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3]))
        arrows.append(ArrowPrimitive(
            pose=pose, shaft_length=length - head, shaft_diameter=SHAFT_DIAMETER * size,
            head_length=head, head_diameter=HEAD_DIAMETER * size,
            color=color(palette.FORCE_PULLING if force[2] < 0 else palette.FORCE)))
    return arrows


def force_update(stamp_ns, frame_id, points, forces, weight, size):
    """The force arrows (:func:`force_arrows`) as one entity of the world frame."""
    return SceneUpdate(entities=[SceneEntity(
        timestamp=timestamp(stamp_ns), frame_id=frame_id, id='contact_forces',
        arrows=force_arrows(points, forces, weight, size))])


class Traces:
    """The last ``length`` positions of A, B and G (world frame, m), like the node's paths."""

    KEYS = ('a', 'b', 'g')

    def __init__(self, length):
        self.length = int(length)
        self.points = {key: np.zeros((0, 3)) for key in self.KEYS}

    def extend(self, a, b, g):
        """Append arrays (n, 3) of A, B and G; keep the last ``length`` of each."""
        for key, new in zip(self.KEYS, (a, b, g)):
            joined = np.concatenate([self.points[key], np.asarray(new, dtype=float)])
            self.points[key] = joined[-self.length:]


def trace_update(stamp_ns, frame_id, traces, size):
    """The traces of A (blue), B (orange) and G (near-black) as line strips (world frame)."""
    stamp = timestamp(stamp_ns)
    width = LINE_WIDTH * size
    entities = []
    for key, colour in zip(Traces.KEYS, (palette.A, palette.B, palette.G)):
        points = traces.points[key]
        line = LinePrimitive(type=LinePrimitiveLineType.LineStrip,
                             pose=Pose(position=Vector3(), orientation=Quaternion(w=1.0)),
                             thickness=width, points=[_point(p) for p in points],
                             color=color(colour))
        entities.append(SceneEntity(timestamp=stamp, frame_id=frame_id, id=f'trace_{key}',
                                    lines=[line]))
    return SceneUpdate(entities=entities)

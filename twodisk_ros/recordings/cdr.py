"""Vectorised CDR encoding of the node's fixed-layout ROS 2 messages, from numpy arrays.

Each function encodes a whole batch of messages at once and returns one ``bytes`` per
message, ready for ``publisher.publish(data)`` and ``mcap.Writer.add_message(data=...)``.
The bytes are what ``rclpy.serialization.serialize_message`` gives for the equivalent message
object (ROS 2 Jazzy, rmw_fastrtps_cpp, Fast-CDR), with two differences that strict readers such
as rosbags need: every alignment padding byte is zero (Fast-CDR leaves whatever the buffer held),
and the message ends after its last field (``serialize_message`` of a JointState with an empty
``effort`` appends 4 bytes of padding past it, which rosbags rejects as a size mismatch).

All messages of a batch share one frame id, hence one length and one layout
(:class:`~twodisk_ros.recordings.cdr_layout.Layout`): a template row holds the constant bytes (header,
string lengths, zero padding), and the numeric columns of an ``(n, L)`` ``uint8`` array are
filled through ``float64``/``int32`` views.  The layouts are derived from the installed
``.msg`` definitions (:func:`~twodisk_ros.recordings.cdr_schema.message_layout`, cached), not written
by hand: each encoder only names its batch constants (frame ids, joint names) and columns.

``serialize`` (:mod:`~twodisk_ros.recordings.cdr_generic`) encodes any other rclpy message object
(MarkerArray, DiagnosticArray, ...) one field at a time, with the same guarantees.

Stamps are integer nanoseconds (``int64``), converted exactly as
``Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)``: floor division, so the
nanoseconds are always in ``[0, 1e9)``; ``sec`` must fit ``int32``.

Only numpy and the standard library are imported, so this module works without rclpy: it reads
the ``.msg`` files from the share directories (``serialize`` duck-types the message object and
its ``rosidl_parser`` field types by class name).
"""

import numpy as np

from .cdr_generic import serialize
from .cdr_layout import ENCAPSULATION, Layout, float_columns, split_rows, stamp_columns
from .cdr_schema import message_layout

__all__ = [
    'ENCAPSULATION',
    'encode_clock',
    'encode_joint_state',
    'encode_path',
    'encode_point_stamped',
    'encode_pose_stamped',
    'encode_tf_message',
    'encode_wrench_stamped',
    'serialize',
    'split_rows',
    'stamp_columns',
    'Layout',
]


POSE_STAMPED = 'geometry_msgs/msg/PoseStamped'
POINT_STAMPED = 'geometry_msgs/msg/PointStamped'
WRENCH_STAMPED = 'geometry_msgs/msg/WrenchStamped'
JOINT_STATE = 'sensor_msgs/msg/JointState'
TF_MESSAGE = 'tf2_msgs/msg/TFMessage'
CLOCK = 'rosgraph_msgs/msg/Clock'


def encode_pose_stamped(stamps_ns, frame_id, positions, quaternions):
    """Encode a batch of ``geometry_msgs/msg/PoseStamped``.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds (since the epoch or simulation start).
    frame_id : str
        Header frame id, the same for the whole batch.
    positions : array_like of float, shape (n, 3)
        Position x, y, z in metres, in ``frame_id``.
    quaternions : array_like of float, shape (n, 4)
        Orientation as x, y, z, w (body → ``frame_id``, the world frame).

    Returns
    -------
    list of bytes
        One CDR message (with encapsulation header) per sample.
    """
    positions = float_columns(positions, 3, 'positions')
    quaternions = float_columns(quaternions, 4, 'quaternions')
    n = len(positions)
    layout = message_layout(POSE_STAMPED, {'header.frame_id': frame_id})
    return split_rows(layout.fill(n, **{'header.stamp': stamp_columns(stamps_ns, n),
                                        'pose.position': positions,
                                        'pose.orientation': quaternions}))


def encode_tf_message(stamps_ns, parent_frame, child_frame, positions, quaternions):
    """Encode a batch of ``tf2_msgs/msg/TFMessage``, each holding one transform.

    Message i is ``TFMessage(transforms=[TransformStamped(header=(stamps_ns[i],
    parent_frame), child_frame_id=child_frame, transform=(positions[i], quaternions[i]))])``:
    the pose of ``child_frame`` in ``parent_frame``, the same numbers as
    :func:`encode_pose_stamped` with ``frame_id=parent_frame``.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds.
    parent_frame : str
        Header frame id (the parent frame), the same for the whole batch.
    child_frame : str
        ``child_frame_id``, the same for the whole batch.
    positions : array_like of float, shape (n, 3)
        Translation x, y, z in metres: the child frame's origin in ``parent_frame``.
    quaternions : array_like of float, shape (n, 4)
        Rotation x, y, z, w (child → parent).

    Returns
    -------
    list of bytes
        One CDR message (with encapsulation header) per sample.
    """
    positions = float_columns(positions, 3, 'positions')
    quaternions = float_columns(quaternions, 4, 'quaternions')
    n = len(positions)
    layout = message_layout(TF_MESSAGE, {'transforms[0].header.frame_id': parent_frame,
                                         'transforms[0].child_frame_id': child_frame},
                            {'transforms': 1})
    return split_rows(layout.fill(n, **{
        'transforms[0].header.stamp': stamp_columns(stamps_ns, n),
        'transforms[0].transform.translation': positions,
        'transforms[0].transform.rotation': quaternions}))


def encode_clock(stamps_ns):
    """Encode a batch of ``rosgraph_msgs/msg/Clock``, one per stamp.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Simulated times, integer nanoseconds.

    Returns
    -------
    list of bytes
        One CDR message (12 bytes: encapsulation, ``int32 sec``, ``uint32 nanosec``) per stamp.
    """
    stamps = stamp_columns(stamps_ns)
    return split_rows(message_layout(CLOCK).fill(len(stamps), clock=stamps))


def encode_point_stamped(stamps_ns, frame_id, points):
    """Encode a batch of ``geometry_msgs/msg/PointStamped``.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds.
    frame_id : str
        Header frame id, the same for the whole batch.
    points : array_like of float, shape (n, 3)
        Point x, y, z in metres, in ``frame_id``.

    Returns
    -------
    list of bytes
        One CDR message per sample.
    """
    points = float_columns(points, 3, 'points')
    n = len(points)
    layout = message_layout(POINT_STAMPED, {'header.frame_id': frame_id})
    return split_rows(layout.fill(n, **{'header.stamp': stamp_columns(stamps_ns, n),
                                        'point': points}))


def encode_wrench_stamped(stamps_ns, frame_id, forces, torques=None):
    """Encode a batch of ``geometry_msgs/msg/WrenchStamped``.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds.
    frame_id : str
        Header frame id (the axes of force and torque), the same for the whole batch.
    forces : array_like of float, shape (n, 3)
        Force (N).
    torques : array_like of float, shape (n, 3), optional
        Torque (N m); zero if omitted.

    Returns
    -------
    list of bytes
        One CDR message (with encapsulation header) per sample.
    """
    forces = float_columns(forces, 3, 'forces')
    n = len(forces)
    torques = np.zeros((n, 3)) if torques is None else float_columns(torques, 3, 'torques')
    layout = message_layout(WRENCH_STAMPED, {'header.frame_id': frame_id})
    return split_rows(layout.fill(n, **{'header.stamp': stamp_columns(stamps_ns, n),
                                        'wrench.force': forces, 'wrench.torque': torques}))


def encode_joint_state(stamps_ns, names, positions, velocities=None, frame_id=''):
    """Encode a batch of ``sensor_msgs/msg/JointState`` with fixed joint names, no effort.

    Parameters
    ----------
    stamps_ns : array_like of int, shape (n,)
        Header stamps, integer nanoseconds.
    names : sequence of str, length k
        Joint names, the same for every message (the node uses ``['theta', 'psi', 'phase']``).
    positions : array_like of float, shape (n, k)
        Joint positions (rad for revolute joints, m for prismatic ones).
    velocities : array_like of float, shape (n, k), optional
        Joint velocities (rad/s or m/s); None gives an empty ``velocity``.
    frame_id : str, default ''
        Header frame id.

    Returns
    -------
    list of bytes
        One CDR message per sample, ending right after the (empty) ``effort`` count.
    """
    names = tuple(names)
    k = len(names)
    positions = float_columns(positions, k, 'positions')
    n = len(positions)
    columns = {'header.stamp': stamp_columns(stamps_ns, n), 'position': positions}
    if velocities is not None:
        columns['velocity'] = float_columns(velocities, k, 'velocities')
        if len(columns['velocity']) != n:
            raise ValueError('positions and velocities must have the same number of rows')
    # effort: empty, and nothing after its count (no alignment for an empty sequence)
    layout = message_layout(JOINT_STATE, {'header.frame_id': frame_id, 'name': names},
                            {'position': k, 'velocity': 0 if velocities is None else k})
    return split_rows(layout.fill(n, **columns))


def encode_path(stamp_ns, frame_id, positions, quaternions=None, stamps_ns=None):
    """Encode one ``nav_msgs/msg/Path`` whose poses all have the header frame id.

    Parameters
    ----------
    stamp_ns : int
        Stamp of the Path header, integer nanoseconds.
    frame_id : str
        Frame id of the Path header and of every pose's header.
    positions : array_like of float, shape (m, 3)
        Pose positions x, y, z in metres, in ``frame_id``; m may be 0.
    quaternions : array_like of float, shape (m, 4) or (4,), optional
        Pose orientations x, y, z, w (body → ``frame_id``); default identity (0, 0, 0, 1).
    stamps_ns : array_like of int, shape (m,), optional
        Per-pose stamps, integer nanoseconds; default ``stamp_ns`` for every pose.

    Returns
    -------
    bytes
        The CDR message.
    """
    positions = float_columns(np.reshape(positions, (-1, 3)), 3, 'positions')
    m = len(positions)
    if quaternions is None:
        quaternions = (0.0, 0.0, 0.0, 1.0)
    quaternions = np.asarray(quaternions, np.float64)
    if quaternions.shape != (4,):
        quaternions = float_columns(quaternions.reshape(-1, 4), 4, 'quaternions')
    quaternions = np.broadcast_to(quaternions, (m, 4))
    stamps = stamp_columns(stamp_ns if stamps_ns is None else stamps_ns, m)
    head = Layout(prefix=ENCAPSULATION)            # the Path's header and the poses' count
    head.field('stamp', '<i4', 2)
    head.string(frame_id)
    head.u32(m)
    parts = [head.fill(1, stamp=stamp_columns(stamp_ns, 1))]
    # Alignment is relative to the payload start: the first pose starts at a multiple of 4, and
    # every pose ends with a float64, so all later poses start at a multiple of 8 and share one
    # layout; the first one may have 4 bytes more padding.
    start = len(head.raw) - len(ENCAPSULATION)
    for rows in (slice(0, 1), slice(1, m)):
        if rows.start >= m:
            break
        pose = message_layout(POSE_STAMPED, {'header.frame_id': frame_id}, start=start)
        parts.append(pose.fill(len(positions[rows]), **{
            'header.stamp': stamps[rows], 'pose.position': positions[rows],
            'pose.orientation': quaternions[rows]}))
        start += len(pose.raw)
    return b''.join(part.tobytes() for part in parts)



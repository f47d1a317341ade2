"""Physics states → ROS 2 messages (SI units, REP-103: x forward, z up, right-handed).

Pure functions: each takes arrays from the physics core and returns message objects.
"""

import math

import numpy as np

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point, PointStamped, Pose, PoseStamped, Quaternion
from nav_msgs.msg import Path
from sensor_msgs.msg import JointState
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

JOINT_NAMES = ['theta', 'psi', 'phase']


def stamp(time_ns):
    """builtin_interfaces/Time from integer nanoseconds."""
    time_ns = int(time_ns)
    return Time(sec=time_ns // 1_000_000_000, nanosec=time_ns % 1_000_000_000)


def header(frame_id, time_ns):
    return Header(stamp=stamp(time_ns), frame_id=frame_id)


def point(xyz):
    return Point(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def pose_stamped(frame_id, time_ns, position, quaternion):
    """The body frame at G: position (m, world) and quaternion (x, y, z, w), body → world."""
    q = Quaternion(x=float(quaternion[0]), y=float(quaternion[1]), z=float(quaternion[2]),
                   w=float(quaternion[3]))
    return PoseStamped(header=header(frame_id, time_ns),
                       pose=Pose(position=point(position), orientation=q))


def point_stamped(frame_id, time_ns, position):
    return PointStamped(header=header(frame_id, time_ns), point=point(position))


def rolling_state(time_ns, positions, velocities):
    """JointState with names theta, psi, phase: positions (rad) and velocities (rad/s)."""
    return JointState(header=header('', time_ns), name=list(JOINT_NAMES),
                      position=[float(x) for x in positions],
                      velocity=[float(x) for x in velocities])


def path_pose(frame_id, time_ns, position):
    """One pose of a Path: a world position (m) with identity orientation."""
    return PoseStamped(header=header(frame_id, time_ns), pose=Pose(position=point(position)))


def path(frame_id, time_ns, poses):
    """nav_msgs/Path through the given poses (from :func:`path_pose`)."""
    return Path(header=header(frame_id, time_ns), poses=list(poses))


def _line_marker(frame_id, time_ns, marker_id, kind, points, rgba, width):
    marker = Marker(header=header(frame_id, time_ns), ns='twodisk', id=marker_id, type=kind,
                    action=Marker.ADD)
    marker.pose.orientation.w = 1.0
    marker.scale.x = float(width)
    marker.color = ColorRGBA(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])
    marker.points = [Point(x=x, y=y, z=z) for x, y, z in np.asarray(points, float).tolist()]
    return marker


def body_markers(frame_id, time_ns, disk1, disk2, contact_a, contact_b, size):
    """Both disk outlines (LINE_STRIP, world points, m) and the contact line AB (LINE_LIST)."""
    width = 0.01 * size
    return MarkerArray(markers=[
        _line_marker(frame_id, time_ns, 0, Marker.LINE_STRIP, disk1, (0.1, 0.4, 0.9, 1.0), width),
        _line_marker(frame_id, time_ns, 1, Marker.LINE_STRIP, disk2, (0.9, 0.4, 0.1, 1.0), width),
        _line_marker(frame_id, time_ns, 2, Marker.LINE_LIST, [contact_a, contact_b],
                     (0.1, 0.7, 0.2, 1.0), width),
    ])


def diagnostics(time_ns, name, level, message, values):
    """DiagnosticArray with one status; ``level`` is :data:`OK`, :data:`WARN` or :data:`ERROR`
    and ``values`` a list of (key, value) pairs."""
    status = DiagnosticStatus(level=bytes([level]), name=name, message=message,
                              hardware_id='twodisk_ros',
                              values=[KeyValue(key=k, value=_text(v)) for k, v in values])
    return DiagnosticArray(header=header('', time_ns), status=[status])


def _text(value):
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else str(value)
    if isinstance(value, np.floating):
        return repr(float(value))
    return str(value)


#: diagnostic levels as integers (DiagnosticStatus stores them as one byte)
OK, WARN, ERROR = (ord(level) for level in (DiagnosticStatus.OK, DiagnosticStatus.WARN,
                                            DiagnosticStatus.ERROR))
#: marker ids of the two force arrows (the body's markers use the ids below them)
FORCE_ARROW_IDS = (100, 101)


def force_arrows(frame_id, time_ns, points, forces, weight, size):
    """ARROW markers of the ground's forces on the body at A and B (world frame).

    Each arrow starts at its contact point and is ``force / (M g) × size`` long, so the
    weight M g itself would be one body size; red when the force pulls (N < 0).
    """
    scale = size / weight if weight > 0 else 0.0
    markers = []
    for marker_id, point_xyz, force in zip(FORCE_ARROW_IDS, points, forces):
        start = np.asarray(point_xyz, dtype=float)
        marker = Marker(header=header(frame_id, time_ns), ns='twodisk_forces', id=marker_id,
                        type=Marker.ARROW, action=Marker.ADD)
        marker.pose.orientation.w = 1.0
        marker.points = [point(start), point(start + scale * np.asarray(force, dtype=float))]
        marker.scale.x, marker.scale.y, marker.scale.z = 0.01 * size, 0.02 * size, 0.03 * size
        pulling = force[2] < 0
        marker.color = ColorRGBA(r=0.9 if pulling else 0.2, g=0.1 if pulling else 0.6, b=0.1,
                                 a=1.0)
        markers.append(marker)
    return markers

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

from ..recordings.cdr_markers import MarkerSpec
from ..model import palette

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


def marker(frame_id, time_ns, spec):
    """A ``visualization_msgs/Marker`` from a :class:`~twodisk_ros.recordings.cdr_markers.MarkerSpec`."""
    result = Marker(header=header(frame_id, time_ns), ns=spec.ns, id=spec.id, type=spec.type,
                    action=spec.action)
    result.pose.orientation.w = 1.0
    result.scale.x, result.scale.y, result.scale.z = (float(x) for x in spec.scale)
    result.color = ColorRGBA(r=float(spec.color[0]), g=float(spec.color[1]),
                             b=float(spec.color[2]), a=float(spec.color[3]))
    result.points = [Point(x=x, y=y, z=z)
                     for x, y, z in np.asarray(spec.points, float).reshape(-1, 3).tolist()]
    return result


#: Marker ids of :func:`body_markers` (namespace ``twodisk``).
MARKER_IDS = {'outline_1': 0, 'outline_2': 1, 'contact_line': 2, 'disk_1': 3, 'disk_2': 4,
              'hull': 5, 'ground': 6}
#: disk 1 and disk 2 (r, g, b): the package's one palette (model/palette.py)
DISK_COLORS = (palette.rgb(palette.A), palette.rgb(palette.B))


def _closed(outline):
    """The outline with its last point equal to the first (appended if it is not there)."""
    outline = np.asarray(outline, dtype=float)
    extent = float(np.ptp(outline, axis=0).max()) if len(outline) else 0.0
    if len(outline) > 1 and np.linalg.norm(outline[-1] - outline[0]) <= 1e-9 * extent:
        return outline
    return np.vstack([outline, outline[:1]])


def _fan(outline):
    """Triangles (centre, p_k, p_k+1) filling a convex closed outline: a (3k, 3) array.

    The centre is the mean of the outline's points (the duplicate last point dropped).
    """
    outline = _closed(outline)
    count = len(outline) - 1
    if count < 2:                     # no area to fill (an empty or one-point outline)
        return np.zeros((0, 3))
    centre = outline[:-1].mean(axis=0)
    triangles = np.empty((count, 3, 3))
    triangles[:, 0] = centre
    triangles[:, 1] = outline[:-1]
    triangles[:, 2] = outline[1:]
    return triangles.reshape(-1, 3)


def _strip(rim_1, rim_2):
    """Triangles of the ruled surface between matching points of two closed curves."""
    p, q = np.asarray(rim_1, dtype=float), np.asarray(rim_2, dtype=float)
    quads = np.stack([p[:-1], p[1:], q[1:], p[:-1], q[1:], q[:-1]], axis=1)
    return quads.reshape(-1, 3)


def body_marker_specs(disk1, disk2, contact_a, contact_b, size, *, filled=True, alpha=0.6,
                      hull=None):
    """The body as :class:`MarkerSpec` s (world points, m), namespace ``twodisk``.

    Ids :data:`MARKER_IDS`. 0, 1: the disk outlines (LINE_STRIP); 2: the contact line AB
    (LINE_LIST); 3, 4 (if ``filled``): each disk as a filled surface, a fan of triangles from
    its centre over its outline (TRIANGLE_LIST, disk 1 blue, disk 2 orange, opacity
    ``alpha``); 5 (if ``hull`` is given): the convex hull as a TRIANGLE_LIST strip between
    ``hull = (rim_1, rim_2)``, matching points of the two rims (arrays (n + 1, 3), closed),
    e.g. the end points A and B of the rulings over one cycle
    (:meth:`~twodisk_ros.run.simulation.Simulation.hull_rims`). ``disk1``, ``disk2``: closed
    outlines, arrays (n + 1, 3) with the last point the first.
    """
    width = 0.01 * size
    (r1, g1, b1), (r2, g2, b2) = DISK_COLORS
    line = (width, 0.0, 0.0)
    specs = [
        MarkerSpec('twodisk', 0, Marker.LINE_STRIP, Marker.ADD, line, (r1, g1, b1, 1.0), disk1),
        MarkerSpec('twodisk', 1, Marker.LINE_STRIP, Marker.ADD, line, (r2, g2, b2, 1.0), disk2),
        MarkerSpec('twodisk', 2, Marker.LINE_LIST, Marker.ADD, line,
                   palette.rgb(palette.AB) + (1.0,), [contact_a, contact_b]),
    ]
    surfaces = []
    if filled:
        surfaces += [(3, _fan(disk1), (r1, g1, b1, alpha)), (4, _fan(disk2), (r2, g2, b2, alpha))]
    if hull is not None:
        surfaces.append((5, _strip(*hull), palette.rgb(palette.HULL) + (0.35,)))
    for marker_id, triangles, rgba in surfaces:
        specs.append(MarkerSpec('twodisk', marker_id, Marker.TRIANGLE_LIST, Marker.ADD,
                                (1.0, 1.0, 1.0), rgba, triangles))
    return specs


def body_markers(frame_id, time_ns, disk1, disk2, contact_a, contact_b, size, **options):
    """The body as a ``MarkerArray`` (:func:`body_marker_specs`, same arguments)."""
    return MarkerArray(markers=[marker(frame_id, time_ns, spec) for spec in body_marker_specs(
        disk1, disk2, contact_a, contact_b, size, **options)])


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


def force_arrow_specs(points, forces, weight, size):
    """ARROW :class:`MarkerSpec` s of the ground's forces on the body at A and B (world frame).

    Each arrow starts at its contact point and is ``force / (M g) × size`` long, so the
    weight M g itself would be one body size; purple (:data:`palette.FORCE`), red when the
    force pulls (N < 0, :data:`palette.FORCE_PULLING`).
    """
    scale = size / weight if weight > 0 else 0.0
    specs = []
    for marker_id, point_xyz, force in zip(FORCE_ARROW_IDS, points, forces):
        start = np.asarray(point_xyz, dtype=float)
        pulling = force[2] < 0
        specs.append(MarkerSpec(
            'twodisk_forces', marker_id, Marker.ARROW, Marker.ADD,
            (0.01 * size, 0.02 * size, 0.03 * size),
            palette.rgb(palette.FORCE_PULLING if pulling else palette.FORCE) + (1.0,),
            [start, start + scale * np.asarray(force, dtype=float)]))
    return specs


def force_arrows(frame_id, time_ns, points, forces, weight, size):
    """The force arrows as ``Marker`` s (:func:`force_arrow_specs`)."""
    return [marker(frame_id, time_ns, spec)
            for spec in force_arrow_specs(points, forces, weight, size)]


def ground_spec(point, slope, size, extent=8.0):
    """The sloped ground as a TRIANGLE_LIST :class:`MarkerSpec` (id 6, namespace ``twodisk``).

    A square of side ``extent × size`` (m) in the plane through the origin with normal
    (sin β, 0, cos β) (``frame_id``, gravity-aligned), centred at the foot of ``point`` (G)
    on it, edges along straight downhill (cos β, 0, −sin β) and across (0, 1, 0); grey, 30 %
    opaque.
    """
    normal = np.array([math.sin(slope), 0.0, math.cos(slope)])
    downhill = np.array([math.cos(slope), 0.0, -math.sin(slope)])
    across = np.array([0.0, 1.0, 0.0])
    point = np.asarray(point, dtype=float)
    centre = point - float(np.dot(point, normal)) * normal
    half = 0.5 * extent * size
    corners = [centre + half * (i * downhill + j * across)
               for i, j in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    triangles = [corners[0], corners[1], corners[2], corners[0], corners[2], corners[3]]
    return MarkerSpec('twodisk', MARKER_IDS['ground'], Marker.TRIANGLE_LIST, Marker.ADD,
                      (1.0, 1.0, 1.0), (0.5, 0.5, 0.5, 0.3), triangles)

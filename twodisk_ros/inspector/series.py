"""The recorded messages as time series, and the samples that pose, contacts and state share.

Topics are matched by the last component of their name (so a namespace is allowed):
``pose`` (PoseStamped: G and the body → world orientation), ``contact_a`` and ``contact_b``
(PointStamped), ``rolling_state`` (JointState ``theta``, ``psi``, ``phase``: positions and
rates), ``diagnostics`` (DiagnosticArray, key ``energy``) and, optional (recordings made
before the contact forces lack them), ``wrench_a`` and ``wrench_b`` (WrenchStamped: the
ground's force on the body at A and at B, world axes, N; applied at the contact point of the
same stamp, so the torque is 0).
"""

from dataclasses import dataclass
import math

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ['JOINT_NAMES', 'METADATA_NAME', 'SAMPLED', 'STAMP_TOLERANCE', 'Samples', 'Series',
           'TOPIC_TYPES', 'WRENCHES', 'extract_series', 'join_samples', 'select_topics',
           'topic_role', 'values_at']

#: The topics read, by the last component of their name, and the types they must have.
TOPIC_TYPES = {
    'pose': 'geometry_msgs/msg/PoseStamped',
    'contact_a': 'geometry_msgs/msg/PointStamped',
    'contact_b': 'geometry_msgs/msg/PointStamped',
    'rolling_state': 'sensor_msgs/msg/JointState',
    'diagnostics': 'diagnostic_msgs/msg/DiagnosticArray',
    'wrench_a': 'geometry_msgs/msg/WrenchStamped',
    'wrench_b': 'geometry_msgs/msg/WrenchStamped',
}
#: Optional topics published with the samples: the contact forces at A and at B.
WRENCHES = ('wrench_a', 'wrench_b')
#: Topics published together at every step, at ``rate`` Hz; all are required (the
#: diagnostics are only reported and plotted).
SAMPLED = ('pose', 'contact_a', 'contact_b', 'rolling_state')
METADATA_NAME = 'twodisk_ros'
JOINT_NAMES = ('theta', 'psi', 'phase')
STAMP_TOLERANCE = 0.01        # relative deviation of a stamp interval from 1/rate
_MAX_NS = np.iinfo(np.int64).max    # MCAP times are uint64; the series hold int64


@dataclass
class Series:
    """Messages of one topic: stamps (int ns) and named value arrays."""

    topic: str
    stamp_ns: np.ndarray
    log_ns: np.ndarray
    publish_ns: np.ndarray
    values: dict

    def __len__(self):
        return len(self.stamp_ns)


def topic_role(topic):
    """The last component of a topic name: ``'/ns/pose'`` → ``'pose'``."""
    return topic.rstrip('/').rsplit('/', 1)[-1]


def select_topics(topics, problems):
    """Map each role of :data:`TOPIC_TYPES` to a recorded topic of the right type."""
    chosen = {}
    for role, type_name in TOPIC_TYPES.items():
        named = [name for name in topics if topic_role(name) == role]
        typed = [name for name in named if topics[name].type_name == type_name]
        for name in named:
            if name not in typed:
                problems.append(f'topic {name} has type {topics[name].type_name}, '
                                f'expected {type_name}')
        if not typed:
            continue
        typed.sort(key=lambda name: (-topics[name].message_count, name))
        if len(typed) > 1:
            problems.append(f'{len(typed)} {role} topics ({", ".join(typed)}); '
                            f'using {typed[0]}')
        chosen[role] = typed[0]
    return chosen


def _stamp(header):
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _xyz(point):
    return (float(point.x), float(point.y), float(point.z))


def _pose_values(msg):
    q = msg.pose.orientation
    return {'position': _xyz(msg.pose.position),
            'quaternion': (float(q.x), float(q.y), float(q.z), float(q.w))}


def _point_values(msg):
    return {'point': _xyz(msg.point)}


def _wrench_values(msg):
    return {'force': _xyz(msg.wrench.force), 'torque': _xyz(msg.wrench.torque)}


def _joint_values(msg):
    names = list(msg.name)
    index = [names.index(name) for name in JOINT_NAMES]
    position = [float(msg.position[k]) for k in index]
    velocity = list(msg.velocity)
    rate = ([float(velocity[k]) for k in index] if len(velocity) == len(names)
            else [math.nan] * 3)
    return {'position': position, 'velocity': rate}


def _number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def _diagnostic_values(msg):
    found = {}
    for status in msg.status:
        for pair in status.values:
            if pair.key in ('energy', 'energy_drift') and pair.key not in found:
                found[pair.key] = _number(pair.value)
    return {'energy': found.get('energy', math.nan),
            'energy_drift': found.get('energy_drift', math.nan)}


_EXTRACT = {
    'pose': _pose_values,
    'contact_a': _point_values,
    'contact_b': _point_values,
    'rolling_state': _joint_values,
    'diagnostics': _diagnostic_values,
    'wrench_a': _wrench_values,
    'wrench_b': _wrench_values,
}


def extract_series(recording, chosen, problems):
    """Collect the chosen topics' messages into :class:`Series`."""
    roles = {topic: role for role, topic in chosen.items()}
    rows = {role: ([], [], [], []) for role in chosen}
    bad, late = {}, {}
    for message in recording.messages:
        role = roles.get(message.topic)
        if role is None:
            continue
        if max(message.log_time_ns, message.publish_time_ns) > _MAX_NS:
            late[message.topic] = late.get(message.topic, 0) + 1
            continue
        try:
            values = _EXTRACT[role](message.msg)
            stamp = _stamp(message.msg.header)
        except (AttributeError, TypeError, ValueError, IndexError):
            bad[message.topic] = bad.get(message.topic, 0) + 1
            continue
        stamps, logs, publishes, value_rows = rows[role]
        stamps.append(stamp)
        logs.append(message.log_time_ns)
        publishes.append(message.publish_time_ns)
        value_rows.append(values)
    for topic, count in bad.items():
        problems.append(f'{count} messages of {topic} lack the expected fields')
    for topic, count in late.items():
        problems.append(f'{count} messages of {topic} have log or publish times beyond '
                        f'2^63 ns (ignored)')
    series = {}
    for role, (stamps, logs, publishes, value_rows) in rows.items():
        keys = value_rows[0].keys() if value_rows else ()
        series[role] = Series(
            chosen[role], np.array(stamps, dtype=np.int64), np.array(logs, dtype=np.int64),
            np.array(publishes, dtype=np.int64),
            {key: np.array([row[key] for row in value_rows], dtype=float) for key in keys})
    return series


@dataclass
class Samples:
    """Pose, contacts and rolling state at the stamps they share."""

    stamp_ns: np.ndarray
    t: np.ndarray               # s from the first stamp of the recording
    position_g: np.ndarray
    rotation: Rotation
    contact_a: np.ndarray
    contact_b: np.ndarray
    angles: np.ndarray          # θ, ψ, u
    rates: np.ndarray           # θ̇, ψ̇, u̇


def _first_of_each(stamps):
    """Indices of the first message of every distinct stamp, sorted by stamp."""
    _, index = np.unique(stamps, return_index=True)
    return index


def join_samples(series, t0_ns):
    """Samples at the stamps present in pose, both contacts and rolling state."""
    if any(role not in series or len(series[role]) == 0 for role in SAMPLED):
        return None
    firsts = {role: _first_of_each(series[role].stamp_ns) for role in SAMPLED}
    common = series['pose'].stamp_ns[firsts['pose']]
    for role in SAMPLED[1:]:
        common = np.intersect1d(common, series[role].stamp_ns[firsts[role]],
                                assume_unique=True)
    if common.size == 0:
        return None
    picked = {}
    for role in SAMPLED:
        stamps = series[role].stamp_ns[firsts[role]]
        picked[role] = firsts[role][np.searchsorted(stamps, common)]
    pose = series['pose'].values
    quaternion = pose['quaternion'][picked['pose']]
    state = series['rolling_state'].values
    return Samples(
        stamp_ns=common, t=(common - t0_ns) * 1e-9,
        position_g=pose['position'][picked['pose']],
        rotation=Rotation.from_quat(quaternion),
        contact_a=series['contact_a'].values['point'][picked['contact_a']],
        contact_b=series['contact_b'].values['point'][picked['contact_b']],
        angles=state['position'][picked['rolling_state']],
        rates=state['velocity'][picked['rolling_state']])


def values_at(series, key, stamps):
    """The values ``key`` of the first message of ``series`` at each of ``stamps`` (int ns).

    Returns
    -------
    values : numpy.ndarray
        NaN where no message carries the stamp.
    found : numpy.ndarray of bool
    """
    stamps = np.asarray(stamps, dtype=np.int64)
    data = series.values.get(key) if series is not None else None
    if data is None or len(series) == 0:
        return np.full((stamps.size, 3), np.nan), np.zeros(stamps.size, dtype=bool)
    firsts = _first_of_each(series.stamp_ns)
    own = series.stamp_ns[firsts]
    where = np.clip(np.searchsorted(own, stamps), 0, own.size - 1)
    found = own[where] == stamps
    values = np.where(found.reshape((-1,) + (1,) * (data.ndim - 1)),
                      data[firsts[where]], np.nan)
    return values, found

"""The ``tf`` check of ``twodisk-inspect``: the body frame on /tf is the pose, bit for bit.

The node broadcasts the body frame on ``/tf`` (``tf2_msgs/msg/TFMessage``) with every pose
sample: a transform whose parent is the ``frame_id`` parameter, whose child is the
``body_frame`` parameter (default ``twodisk_body``, at G, the orientation of ``pose``), with
the pose's stamp, translation = the pose's position (m) and rotation = its orientation
(x, y, z, w).

Both parameters may change at run time, so the frames expected are those in force at each
stamp, not the last recorded parameters:

- the parent at stamp s is the ``header.frame_id`` of the pose at s (the pose and its
  transform are encoded from the same settings); for a transform at a stamp without a pose,
  that of the latest pose before it, or the metadata's ``frame_id`` (default ``world``);
- the body frame at s is the parent of the disk frames in the latest ``/tf_static`` message
  stamped at or before s (the node sends /tf_static at the first sample and again at the
  first sample after ``body_frame`` or ``delta`` changes, stamped with that sample's stamp:
  :mod:`twodisk_ros.node.frames_publisher`); before the first /tf_static, or in a recording
  without one, the metadata's ``body_frame`` (default ``twodisk_body``).

``tf``
    Counted, tolerance 0: transforms of the body frame whose parent is not the one expected;
    transforms at a stamp that has no pose; transforms whose translation or rotation differs
    from the pose of their stamp in any bit (float64, so -0.0 ≠ 0.0 and NaNs compare by their
    bits); and pose stamps that no transform of the body frame at that stamp carries (a /tf
    that keeps the old child after a rename misses every later stamp). In a truncated file
    the pose stamps after the last transform recovered are not counted (the cut may fall
    between a pose and its transform).

A recording without a ``tf`` topic (made before the node broadcast /tf) has no such check:
the summary says it is not applicable, and the verdict does not depend on it.
"""

import numpy as np

from .results import Check, json_ready
from .series import topic_role, values_at

__all__ = ['DEFAULT_BODY_FRAME', 'TF_TITLE', 'TF_TYPE', 'is_tf_topic', 'reads_topic',
           'tf_check']

TF_TYPE = 'tf2_msgs/msg/TFMessage'
DEFAULT_BODY_FRAME = 'twodisk_body'
DEFAULT_FRAME_ID = 'world'       # the node's default frame_id
TF_TITLE = 'transform of body_frame on /tf = pose, bit for bit, at every pose stamp'
NOT_RECORDED = ('no /tf topic: a recording made before the node broadcast /tf; the tf check '
                'is not applicable')
_SHOWN = 3       # stamps named per kind of discrepancy


def is_tf_topic(topic):
    """Whether a topic is read by this check (last name component ``tf``: ``/tf``, ``/ns/tf``)."""
    return topic_role(topic) == 'tf'


def reads_topic(topic):
    """Whether this check needs the topic decoded: /tf and /tf_static (any namespace)."""
    return topic_role(topic) in ('tf', 'tf_static')


def _stamp_ns(stamp):
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


class _Steps:
    """A frame name as a step function of the stamp: the latest value at or before it."""

    def __init__(self, stamps, names, default):
        order = np.argsort(np.asarray(stamps, dtype=np.int64), kind='stable')
        self.stamps = np.asarray(stamps, dtype=np.int64)[order]
        self.names = [names[i] for i in order]
        self.default = default

    def at(self, stamps):
        index = np.searchsorted(self.stamps, np.asarray(stamps, dtype=np.int64), 'right') - 1
        return [self.names[i] if i >= 0 else self.default for i in index]

    def distinct(self, first):
        """The names in stamp order without repeats, ``first`` (the one before any) first."""
        names = [first]
        for name in self.names:
            if name != names[-1]:
                names.append(name)
        return names


def _pose_frames(recording, topic, default):
    """The ``header.frame_id`` of the first pose message at each stamp, as :class:`_Steps`."""
    seen = {}
    for message in recording.messages:
        if message.topic == topic:
            try:
                seen.setdefault(_stamp_ns(message.msg.header.stamp),
                                str(message.msg.header.frame_id))
            except (AttributeError, TypeError, ValueError):
                continue       # counted by the inputs check
    return _Steps(list(seen), list(seen.values()), default)


def _body_frames(recording, default):
    """The body frame of each /tf_static message (its transforms' parent) by their stamp.

    Returns the :class:`_Steps` and the number of /tf_static messages without that form.
    """
    topics = {name for name, info in recording.topics.items()
              if topic_role(name) == 'tf_static' and info.type_name == TF_TYPE}
    stamps, names, malformed = [], [], 0
    for message in recording.messages:
        if message.topic not in topics or isinstance(message.msg,
                                                      (bytes, bytearray, memoryview)):
            continue
        try:
            first = message.msg.transforms[0].header
            stamps.append(_stamp_ns(first.stamp))
            names.append(str(first.frame_id))
        except (AttributeError, TypeError, ValueError, IndexError):
            malformed += 1
    return _Steps(stamps, names, default), malformed


def _not_evaluated(reason):
    return Check('tf', TF_TITLE, False, None, 0, 'transforms', [f'not evaluated: {reason}'])


def _choose(recording):
    """The /tf topic read, or a reason why there is none of type TFMessage."""
    named = [name for name in recording.topics if is_tf_topic(name)]
    typed = [name for name in named if recording.topics[name].type_name == TF_TYPE]
    if not typed:
        return None, (f'topic {named[0]} has type {recording.topics[named[0]].type_name}, '
                      f'expected {TF_TYPE}')
    typed.sort(key=lambda name: (-recording.topics[name].message_count, name))
    return typed[0], None


def _transforms(recording, topic):
    """(stamps, parents, children, values, malformed) of the transforms on ``topic``.

    ``values``: (n, 7) float64 translations (m) and rotations (x, y, z, w).
    """
    stamps, parents, children, rows, malformed = [], [], [], [], 0
    for message in recording.messages:
        if message.topic != topic or isinstance(message.msg, (bytes, bytearray, memoryview)):
            continue          # undecodable messages are problems of the inputs check
        try:
            for t in message.msg.transforms:
                tr, rot = t.transform.translation, t.transform.rotation
                rows.append((float(tr.x), float(tr.y), float(tr.z), float(rot.x),
                             float(rot.y), float(rot.z), float(rot.w)))
                stamps.append(_stamp_ns(t.header.stamp))
                parents.append(t.header.frame_id)
                children.append(t.child_frame_id)
        except (AttributeError, TypeError, ValueError):
            malformed += 1
    values = np.array(rows, dtype=np.float64).reshape(-1, 7)
    return np.array(stamps, dtype=np.int64), parents, children, values, malformed


def _seconds(stamps, t0_ns):
    return ', '.join(f'{(int(s) - t0_ns) * 1e-9:.9g} s' for s in stamps[:_SHOWN]) + (
        f' and {len(stamps) - _SHOWN} more' if len(stamps) > _SHOWN else '')


def tf_check(recording, series, parameters, t0_ns=0):
    """The ``tf`` check of a recording, and a JSON-ready summary.

    Parameters
    ----------
    recording : twodisk_ros.recordings.Recording
        Read with /tf and /tf_static decoded (:func:`reads_topic`).
    series : dict of str to Series
        The pose series (role ``'pose'``): stamps, ``position``, ``quaternion``.
    parameters : dict of str to str
        The recorded parameters (``frame_id``, ``body_frame``: the frames where the pose
        messages and /tf_static do not say).
    t0_ns : int
        Stamp that times in the details are counted from (ns).

    Returns
    -------
    checks : list of Check
        Empty for a recording without a /tf topic.
    summary : dict
        ``recorded``, and ``topic``, ``parent``, ``child`` (the frames at the last pose
        stamp), ``parents``, ``children`` (every one in force, in order), ``transforms`` and
        the counts of each discrepancy; or ``note`` (why the check is not applicable).
    """
    if not any(is_tf_topic(name) for name in recording.topics):
        return [], {'recorded': False, 'note': NOT_RECORDED}
    topic, reason = _choose(recording)
    pose = series.get('pose')
    summary = {'recorded': True, 'topic': topic}
    if topic is None or pose is None or not len(pose):
        summary.update(parent=parameters.get('frame_id', DEFAULT_FRAME_ID),
                       child=parameters.get('body_frame', DEFAULT_BODY_FRAME))
        return [_not_evaluated(reason or 'no pose samples')], json_ready(summary)
    parent_at = _pose_frames(recording, pose.topic,
                             parameters.get('frame_id', DEFAULT_FRAME_ID))
    child_at, malformed = _body_frames(recording,
                                       parameters.get('body_frame', DEFAULT_BODY_FRAME))
    all_stamps, all_parents, children, all_values, bad = _transforms(recording, topic)
    malformed += bad
    body = np.array([c == e for c, e in zip(children, child_at.at(all_stamps))], dtype=bool)
    stamps, values = all_stamps[body], all_values[body]
    parents = [p for p, b in zip(all_parents, body) if b]
    wrong_parent = np.array([p != e for p, e in zip(parents, parent_at.at(stamps))],
                            dtype=bool)
    position, found = values_at(pose, 'position', stamps)
    quaternion, _ = values_at(pose, 'quaternion', stamps)
    expected = np.concatenate([position.reshape(-1, 3), quaternion.reshape(-1, 4)], axis=1)
    differs = found & np.any(values.view(np.uint64) != expected.view(np.uint64), axis=1)
    pose_stamps = np.unique(pose.stamp_ns)
    missing = np.setdiff1d(pose_stamps, stamps)
    (parent,), (child,) = parent_at.at(pose_stamps[-1:]), child_at.at(pose_stamps[-1:])
    (first_parent,), (first_child,) = parent_at.at(pose_stamps[:1]), child_at.at(
        pose_stamps[:1])
    parents_used = parent_at.distinct(first_parent)
    children_used = child_at.distinct(first_child)
    summary.update(parent=parent, child=child, parents=parents_used, children=children_used)
    excused = 0
    if recording.truncated and missing.size:
        tail = missing > (stamps.max() if stamps.size else np.iinfo(np.int64).min)
        excused, missing = int(np.count_nonzero(tail)), missing[~tail]
    counts = {'wrong_parent': int(np.count_nonzero(wrong_parent)),
              'without_pose': int(np.count_nonzero(~found)),
              'different': int(np.count_nonzero(differs)),
              'missing': int(missing.size), 'malformed': malformed}
    summary.update(transforms=int(stamps.size), pose_stamps=int(pose_stamps.size),
                   excused_tail=excused, **counts)
    detail = [f'{stamps.size} transforms {" then ".join(parents_used)} → '
              f'{" then ".join(children_used)} on {topic} against {pose_stamps.size} pose '
              f'stamps on {pose.topic}']
    phrases = (
        ('wrong_parent', stamps[wrong_parent],
         'with a parent other than the frame_id of the pose at their stamp'),
        ('without_pose', stamps[~found], 'at stamps without a pose'),
        ('different', stamps[differs], 'differ from the pose in some bit'),
        ('missing', missing, 'pose stamps without a transform of the body frame at that '
                             f'stamp ({" then ".join(map(repr, children_used))})'))
    for name, where, phrase in phrases:
        if counts[name]:
            detail.append(f'{counts[name]} {"" if name == "missing" else "transforms "}'
                          f'{phrase}: t = {_seconds(where, t0_ns)}')
    if malformed:
        detail.append(f'{malformed} /tf or /tf_static messages lack the TFMessage fields')
    if excused:
        detail.append(f'{excused} pose stamps after the last transform of the truncated file '
                      f'not counted')
    value = sum(counts.values())
    check = Check('tf', TF_TITLE, value == 0, value, 0, 'transforms', detail)
    return [check], json_ready(summary)

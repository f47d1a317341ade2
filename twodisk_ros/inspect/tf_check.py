"""The ``tf`` check of ``twodisk-inspect``: the body frame on /tf is the pose, bit for bit.

The node broadcasts the body frame on ``/tf`` (``tf2_msgs/msg/TFMessage``) with every pose
sample: a transform whose parent is the ``frame_id`` parameter, whose child is the
``body_frame`` parameter (default ``twodisk_body``, at G, the orientation of ``pose``), with
the pose's stamp, translation = the pose's position (m) and rotation = its orientation
(x, y, z, w). Both parameters are read from the recording's ``twodisk_ros`` metadata.

``tf``
    Counted, tolerance 0: transforms of ``body_frame`` whose parent is not ``frame_id``;
    transforms at a stamp that has no pose; transforms whose translation or rotation differs
    from the pose of their stamp in any bit (float64, so -0.0 ≠ 0.0 and NaNs compare by their
    bits); and pose stamps that no transform of ``body_frame`` carries. In a truncated file the
    pose stamps after the last transform recovered are not counted (the cut may fall between
    a pose and its transform).

A recording without a ``tf`` topic (made before the node broadcast /tf) has no such check:
the summary says it is not applicable, and the verdict does not depend on it.
"""

import numpy as np

from .results import Check, json_ready
from .series import topic_role, values_at

__all__ = ['DEFAULT_BODY_FRAME', 'TF_TITLE', 'TF_TYPE', 'is_tf_topic', 'tf_check']

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


def _transforms(recording, topic, child):
    """(stamps, parents, translations, rotations, malformed) of the transforms of ``child``."""
    stamps, parents, rows, malformed = [], [], [], 0
    for message in recording.messages:
        if message.topic != topic or isinstance(message.msg, (bytes, bytearray, memoryview)):
            continue          # undecodable messages are problems of the inputs check
        try:
            for t in message.msg.transforms:
                if t.child_frame_id != child:
                    continue
                tr, rot = t.transform.translation, t.transform.rotation
                rows.append((float(tr.x), float(tr.y), float(tr.z), float(rot.x),
                             float(rot.y), float(rot.z), float(rot.w)))
                stamps.append(int(t.header.stamp.sec) * 1_000_000_000
                              + int(t.header.stamp.nanosec))
                parents.append(t.header.frame_id)
        except (AttributeError, TypeError, ValueError):
            malformed += 1
    values = np.array(rows, dtype=np.float64).reshape(-1, 7)
    return np.array(stamps, dtype=np.int64), parents, values, malformed


def _seconds(stamps, t0_ns):
    return ', '.join(f'{(int(s) - t0_ns) * 1e-9:.9g} s' for s in stamps[:_SHOWN]) + (
        f' and {len(stamps) - _SHOWN} more' if len(stamps) > _SHOWN else '')


def tf_check(recording, series, parameters, t0_ns=0):
    """The ``tf`` check of a recording, and a JSON-ready summary.

    Parameters
    ----------
    recording : twodisk_ros.io.Recording
        Read with /tf decoded (:func:`is_tf_topic`).
    series : dict of str to Series
        The pose series (role ``'pose'``): stamps, ``position``, ``quaternion``.
    parameters : dict of str to str
        The recorded parameters (``frame_id``, ``body_frame``).
    t0_ns : int
        Stamp that times in the details are counted from (ns).

    Returns
    -------
    checks : list of Check
        Empty for a recording without a /tf topic.
    summary : dict
        ``recorded``, and ``topic``, ``parent``, ``child``, ``transforms`` and the counts of
        each discrepancy; or ``note`` (why the check is not applicable).
    """
    if not any(is_tf_topic(name) for name in recording.topics):
        return [], {'recorded': False, 'note': NOT_RECORDED}
    parent = parameters.get('frame_id', DEFAULT_FRAME_ID)
    child = parameters.get('body_frame', DEFAULT_BODY_FRAME)
    topic, reason = _choose(recording)
    summary = {'recorded': True, 'topic': topic, 'parent': parent, 'child': child}
    pose = series.get('pose')
    if topic is None or pose is None or not len(pose):
        return [_not_evaluated(reason or 'no pose samples')], json_ready(summary)
    stamps, parents, values, malformed = _transforms(recording, topic, child)
    wrong_parent = np.array([p != parent for p in parents], dtype=bool)
    position, found = values_at(pose, 'position', stamps)
    quaternion, _ = values_at(pose, 'quaternion', stamps)
    expected = np.concatenate([position.reshape(-1, 3), quaternion.reshape(-1, 4)], axis=1)
    differs = found & np.any(values.view(np.uint64) != expected.view(np.uint64), axis=1)
    pose_stamps = np.unique(pose.stamp_ns)
    missing = np.setdiff1d(pose_stamps, stamps)
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
    detail = [f'{stamps.size} transforms {parent} → {child} on {topic} against '
              f'{pose_stamps.size} pose stamps on {pose.topic}']
    phrases = (
        ('wrong_parent', stamps[wrong_parent], f'with a parent other than {parent!r}'),
        ('without_pose', stamps[~found], 'at stamps without a pose'),
        ('different', stamps[differs], 'differ from the pose in some bit'),
        ('missing', missing, f'pose stamps without a transform of {child!r}'))
    for name, where, phrase in phrases:
        if counts[name]:
            detail.append(f'{counts[name]} {"" if name == "missing" else "transforms "}'
                          f'{phrase}: t = {_seconds(where, t0_ns)}')
    if malformed:
        detail.append(f'{malformed} /tf messages lack the TFMessage fields')
    if excused:
        detail.append(f'{excused} pose stamps after the last transform of the truncated file '
                      f'not counted')
    value = sum(counts.values())
    check = Check('tf', TF_TITLE, value == 0, value, 0, 'transforms', detail)
    return [check], json_ready(summary)

"""The ``tf`` check of ``twodisk-inspect``: /tf carries the pose samples bit for bit.

Recordings are those of ``test_inspect`` (simulated physics, written as the node does) with a
/tf topic added: one TFMessage per pose, built here with rclpy's own message classes and
serializer (independent of the package's encoders; the node's path, ``cdr.encode_tf_message``,
is checked once too). Injected faults, each alone, must FAIL the check and only it: one ulp
off in a translation or a rotation, a stamp left out, a wrong parent, -q for q, the
``body_frame`` of the metadata not the child on /tf. A recording without /tf still PASSes,
the check reported as not applicable; a cut recording with /tf is INCOMPLETE, not FAIL.
"""

import os

os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', '41')

import importlib  # noqa: E402
import json  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

tf2_msgs = pytest.importorskip('tf2_msgs.msg')

from geometry_msgs.msg import (Quaternion, Transform, TransformStamped,  # noqa: E402
                               Vector3)
from builtin_interfaces.msg import Time  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile  # noqa: E402
from rclpy.serialization import deserialize_message  # noqa: E402
from std_msgs.msg import Header  # noqa: E402

from test_inspect import OLOID, run_main, simulate_run, write_run  # noqa: E402
from twodisk_ros.inspector import inspect_recording  # noqa: E402
from twodisk_ros.recordings import McapRecorder, cdr, read_recording  # noqa: E402

pytestmark = pytest.mark.ros
TFMessage = tf2_msgs.TFMessage
#: test_inspect's oloid run, 1.5 s instead of 3 s (151 samples at 100 Hz): every claim here
#: is about single samples or about all of them, none about the length of the run
RUN = dict(OLOID, duration='1.5')
SAMPLES = 151
PARAMS = dict(RUN, body_frame='twodisk_body')
K = 137          # the sample each fault is injected at


@pytest.fixture(scope='module')
def old_file(tmp_path_factory):
    """A recording as the node wrote it before /tf (no body_frame in its metadata either)."""
    return write_run(tmp_path_factory.mktemp('old') / 'old.mcap', simulate_run(RUN), RUN)


def _class(type_name):
    package, _, name = type_name.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


def _static(body_frame, stamp):
    """The node's /tf_static at ``stamp`` (ns): the disk frames, parent ``body_frame``."""
    sec, nanosec = divmod(int(stamp), 10**9)
    return TFMessage(transforms=[TransformStamped(
        header=Header(stamp=Time(sec=sec, nanosec=nanosec), frame_id=body_frame),
        child_frame_id=f'{body_frame}{suffix}', transform=Transform(
            translation=Vector3(x=sign * 0.5), rotation=Quaternion(w=1.0)))
        for suffix, sign in (('_disk_a', -1.0), ('_disk_b', 1.0))])


def with_tf(old, path, *, params=PARAMS, edit=None, drop=(), parent='world',
            child='twodisk_body', encoder=False, frames=None, statics=None):
    """``old`` rewritten with a /tf message after each pose, the pose's numbers in it.

    ``edit(i, values)`` may change the 7 values (x, y, z, qx, qy, qz, qw) of sample i;
    samples in ``drop`` get no transform. ``frames(i)`` gives (the pose's frame_id, the /tf
    parent, the /tf child) of sample i instead of ('world', ``parent``, ``child``);
    ``statics`` maps sample indices to the body frame of a /tf_static message written, as
    the node writes it, at that sample's stamp before its messages.
    """
    raw = read_recording(old, decode=lambda topic: False)
    poses = [m.msg for m in read_recording(old).messages if m.topic.endswith('/pose')]
    # 64 KiB chunks as write_run: a cut keeps whole chunks (rclpy leaves padding bytes
    # uninitialised, so compressed sizes, and where a cut falls, vary from run to run)
    with McapRecorder(path, metadata=params, chunk_size=64 * 1024) as rec:
        for name, info in raw.topics.items():
            rec.add_topic(name, _class(info.type_name))
        rec.add_topic('/tf', TFMessage, QoSProfile(depth=100))
        if statics:
            rec.add_topic('/tf_static', TFMessage, QoSProfile(
                depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
        i = 0
        for message in raw.messages:
            if not message.topic.endswith('/pose'):
                rec.write_serialized(message.topic, message.msg, message.log_time_ns)
                continue
            pose = poses[i]
            if statics and i in statics:
                rec.write('/tf_static', _static(statics[i], message.log_time_ns),
                          message.log_time_ns)
            if frames is None:
                rec.write_serialized(message.topic, message.msg, message.log_time_ns)
            else:
                msg = deserialize_message(message.msg, _class(raw.topics[message.topic]
                                                               .type_name))
                msg.header.frame_id, parent, child = frames(i)
                rec.write(message.topic, msg, message.log_time_ns)
            p, q = pose.pose.position, pose.pose.orientation
            values = [p.x, p.y, p.z, q.x, q.y, q.z, q.w]
            if edit is not None:
                values = edit(i, values)
            stamp = pose.header.stamp.sec * 10**9 + pose.header.stamp.nanosec
            if i not in drop:
                if encoder:
                    rec.write_serialized('/tf', cdr.encode_tf_message(
                        [stamp], parent, child, [values[:3]], [values[3:]])[0], stamp)
                else:
                    rec.write('/tf', TFMessage(transforms=[TransformStamped(
                        header=Header(stamp=Time(sec=pose.header.stamp.sec,
                                                 nanosec=pose.header.stamp.nanosec),
                                      frame_id=parent),
                        child_frame_id=child, transform=Transform(
                            translation=Vector3(x=values[0], y=values[1], z=values[2]),
                            rotation=Quaternion(x=values[3], y=values[4], z=values[5],
                                                w=values[6])))]), stamp)
            i += 1
    return path


def verdict(path):
    inspection = inspect_recording(path)
    checks = {check.name: check for check in inspection.checks}
    return inspection, checks


def test_recording_without_tf_passes_with_the_check_not_applicable(capsys, old_file):
    inspection, checks = verdict(old_file)
    assert inspection.verdict == 'PASS' and 'tf' not in checks
    assert inspection.summary['tf'] == {'recorded': False, 'note': inspection.summary['tf'][
        'note']} and 'not applicable' in inspection.summary['tf']['note']
    status, out, _ = run_main(capsys, old_file)
    assert status == 0 and 'result: PASS' in out
    assert 'tf: not recorded, check not applicable' in out


@pytest.mark.parametrize('encoder', [False, True], ids=['rclpy', 'cdr.encode_tf_message'])
def test_exact_tf_passes(capsys, tmp_path, old_file, encoder):
    path = with_tf(old_file, tmp_path / 'tf.mcap', encoder=encoder)
    inspection, checks = verdict(path)
    assert inspection.verdict == 'PASS', [c for c in inspection.checks if not c.passed]
    assert checks['tf'].passed and checks['tf'].value == 0
    samples = inspection.summary['samples']
    assert inspection.summary['tf']['transforms'] == samples == SAMPLES
    status, out, _ = run_main(capsys, path, '--json')
    document = json.loads(out)
    assert status == 0 and document['summary']['tf']['different'] == 0
    assert [c['status'] for c in document['checks'] if c['name'] == 'tf'] == ['PASS']


def _ulp(index, direction=np.inf):
    def edit(i, values):
        if i == K:
            values = list(values)
            values[index] = float(np.nextafter(values[index], direction))
        return values
    return edit


def _opposite_quaternion(i, values):
    return values[:3] + [-v for v in values[3:]] if i == K else values


@pytest.mark.parametrize('fault, kwargs, counted, value', [
    ('translation x one ulp up', {'edit': _ulp(0)}, 'different', 1),
    ('translation z one ulp down', {'edit': _ulp(2, -np.inf)}, 'different', 1),
    ('rotation w one ulp down', {'edit': _ulp(6, -np.inf)}, 'different', 1),
    ('a stamp missing', {'drop': {K}}, 'missing', 1),
    ('parent not frame_id', {'parent': 'map'}, 'wrong_parent', SAMPLES),
    ('child not the metadata body_frame', {'params': dict(PARAMS, body_frame='base_link')},
     'missing', SAMPLES),
])
def test_fault_fails_the_tf_check_only(tmp_path, old_file, fault, kwargs, counted, value):
    path = with_tf(old_file, tmp_path / 'bad.mcap', **kwargs)
    inspection, checks = verdict(path)
    assert inspection.verdict == 'FAIL', fault
    assert [c.name for c in inspection.checks if not c.passed] == ['tf'], fault
    summary = inspection.summary['tf']
    assert summary[counted] == checks['tf'].value == value, (fault, summary)
    if 'drop' in kwargs or 'edit' in kwargs:
        assert f't = {K / 100:.9g} s' in ' '.join(checks['tf'].detail), checks['tf'].detail


def test_same_rotation_other_quaternion_fails(tmp_path, old_file):
    """Bit for bit, not up to the rotation: -q is the same rotation as q, not the pose's numbers."""
    inspection, checks = verdict(with_tf(old_file, tmp_path / 'q.mcap',
                                         edit=_opposite_quaternion))
    assert not checks['tf'].passed and inspection.summary['tf']['different'] == 1


def test_custom_body_frame_from_metadata_passes(tmp_path, old_file):
    path = with_tf(old_file, tmp_path / 'base.mcap', child='base_link',
                   params=dict(PARAMS, body_frame='base_link'))
    inspection, checks = verdict(path)
    assert checks['tf'].passed and inspection.verdict == 'PASS'
    assert inspection.summary['tf']['child'] == 'base_link'


def test_cut_recording_with_tf_is_incomplete_not_fail(tmp_path, old_file):
    path = with_tf(old_file, tmp_path / 'full.mcap')
    data = path.read_bytes()
    cut = tmp_path / 'cut.mcap'
    for fraction in (0.35, 0.7):
        cut.write_bytes(data[:int(len(data) * fraction)])
        inspection, checks = verdict(cut)
        assert inspection.verdict == 'INCOMPLETE', [c for c in inspection.checks
                                                    if not c.passed]
        assert checks['tf'].passed


# -- frame_id and body_frame changed at run time (the node accepts both) ---------------------
CHANGE = 75      # the first sample after the change: /tf_static is sent again at its stamp
RENAMED = dict(PARAMS, frame_id='odom', body_frame='oloid')   # the metadata: the last values


def _renamed(i):
    return ('world', 'world', 'twodisk_body') if i < CHANGE else ('odom', 'odom', 'oloid')


def test_frames_changed_at_run_time_pass(capsys, tmp_path, old_file):
    """The parent is each pose's own frame_id, the child the body frame of the latest
    /tf_static: a rename of both at sample 75 PASSes (the metadata only holds the last)."""
    path = with_tf(old_file, tmp_path / 'renamed.mcap', params=RENAMED, frames=_renamed,
                   statics={0: 'twodisk_body', CHANGE: 'oloid'})
    inspection, checks = verdict(path)
    assert inspection.verdict == 'PASS', [c for c in inspection.checks if not c.passed]
    summary = inspection.summary['tf']
    assert checks['tf'].value == 0 and summary['transforms'] == SAMPLES
    assert (summary['parents'], summary['children']) == (['world', 'odom'],
                                                         ['twodisk_body', 'oloid'])
    assert (summary['parent'], summary['child']) == ('odom', 'oloid')
    status, out, _ = run_main(capsys, path)
    assert status == 0 and 'world then odom → twodisk_body then oloid' in out


@pytest.mark.parametrize('fault, frames, counted', [
    ('/tf keeps the old child', lambda i: _renamed(i)[:2] + ('twodisk_body',), 'missing'),
    ('/tf keeps the old parent', lambda i: _renamed(i)[:1] + ('world',) + _renamed(i)[2:],
     'wrong_parent'),
])
def test_old_frame_after_the_change_fails(tmp_path, old_file, fault, frames, counted):
    path = with_tf(old_file, tmp_path / 'stale.mcap', params=RENAMED, frames=frames,
                   statics={0: 'twodisk_body', CHANGE: 'oloid'})
    inspection, checks = verdict(path)
    assert inspection.verdict == 'FAIL', fault
    assert [c.name for c in inspection.checks if not c.passed] == ['tf'], fault
    # every sample from the change on (151 - 75), and only those
    assert inspection.summary['tf'][counted] == checks['tf'].value == SAMPLES - CHANGE, fault
    assert f't = {CHANGE / 100:.9g} s' in ' '.join(checks['tf'].detail), checks['tf'].detail

"""The body in ROS tools: /tf, /tf_static and robot_description from a ``roller`` process.

The node runs as a process; this test process is the second process that subscribes, as
RViz or a tf2 listener would. Transforms are checked bit for bit against ``pose`` (the same
arrays) and, independently, against the physics: each recorded contact point, carried
through /tf and /tf_static into its disk's frame, lies on that disk's rim
x²/a² + y²/b² = 1, z = 0. Subprocess nodes use ROS domain 32; discovery is localhost-only.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

from pathlib import Path  # noqa: E402
import signal  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import xml.etree.ElementTree as ElementTree  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import rclpy  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile  # noqa: E402
from rcl_interfaces.srv import SetParameters  # noqa: E402

from geometry_msgs.msg import PointStamped, PoseStamped  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402

from roller_here import run_roller_main  # noqa: E402
from rounding import ulps  # noqa: E402

# yourdfpy 0.0.60 calls a trimesh method that trimesh 5 deprecates (not ours to fix)
pytestmark = [pytest.mark.ros,
              pytest.mark.filterwarnings('ignore:.*Scene.dump.*:DeprecationWarning')]

REPO = Path(__file__).resolve().parents[1]
DOMAIN = 32
RATE = 50.0
PERIOD_NS = 20_000_000
#: an elliptic body, so that a swapped x and y of a disk frame shows on the rim
BODY = {'a': 0.1, 'b': 0.07, 'delta': 0.05}
#: tf2_ros's StaticListenerQoS: what a late-joining tf2 listener asks for
LATCHED = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)
STARTED = 30.0        # s: a node answers within this on a loaded 2-core machine


def node_env():
    return dict(os.environ, PYTHONPATH=str(REPO), ROS_DOMAIN_ID=str(DOMAIN),
                ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')


def body_params(**extra):
    values = dict(BODY, **extra)
    return [arg for name, value in values.items() for arg in ('-p', f'{name}:={value}')]


def start_roller(*params):
    return subprocess.Popen(
        [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
         'config/oloid.yaml', *params], cwd=REPO, env=node_env(), stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE, text=True)


def stop(process, sig=signal.SIGINT, timeout=20.0):
    """Send ``sig`` (None: wait for the end), then the exit code and stderr; killed by PID if
    it does not end."""
    try:
        if process.poll() is None and sig is not None:
            process.send_signal(sig)
        _, err = process.communicate(timeout=timeout)
        return process.returncode, err
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()


@pytest.fixture
def client():
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=DOMAIN)
    node = rclpy.create_node('frames_test_client', context=ctx)
    executor = SingleThreadedExecutor(context=ctx)
    executor.add_node(node)
    try:
        yield node, executor
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=ctx)


def spin_until(executor, predicate, timeout=STARTED):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.02)
        if predicate():
            return True
    return False


def stamp_ns(header):
    return header.stamp.sec * 1_000_000_000 + header.stamp.nanosec


def rotation(q):
    """Rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def xyz(v):
    return np.array([v.x, v.y, v.z])


def xyzw(q):
    return np.array([q.x, q.y, q.z, q.w])


def assert_tf_is_pose(tf, pose, parent='world', child='twodisk_body'):
    """One /tf message holds the pose's transform, bit for bit."""
    (t,) = tf.transforms
    assert (t.header.frame_id, t.child_frame_id) == (parent, child)
    assert stamp_ns(t.header) == stamp_ns(pose.header)
    tr, p = t.transform, pose.pose
    assert [tr.translation.x, tr.translation.y, tr.translation.z] == [
        p.position.x, p.position.y, p.position.z]
    assert list(xyzw(tr.rotation)) == list(xyzw(p.orientation))


def static_frames(message):
    """{child: (parent, translation, rotation matrix disk → body)} of a /tf_static message."""
    return {t.child_frame_id: (t.header.frame_id, xyz(t.transform.translation),
                               rotation(xyzw(t.transform.rotation)))
            for t in message.transforms}


def assert_contacts_on_rims(tfs, contacts_a, contacts_b, states, static,
                            body_frame='twodisk_body'):
    """Each contact, carried world → body (/tf) → disk (/tf_static), is on its disk's rim, at
    the polar angle (from x towards y) that rolling_state gives: theta on disk a, psi on b."""
    a, b = BODY['a'], BODY['b']
    checked = 0
    for stamp, tf in tfs.items():
        if not all(stamp in topic for topic in (contacts_a, contacts_b, states)):
            continue
        (t,) = tf.transforms
        g, r = xyz(t.transform.translation), rotation(xyzw(t.transform.rotation))
        angles = states[stamp].position[:2]
        for contact, suffix, angle in ((contacts_a[stamp], '_disk_a', angles[0]),
                                       (contacts_b[stamp], '_disk_b', angles[1])):
            parent, centre, axes = static[body_frame + suffix]
            assert parent == body_frame
            local = axes.T @ (r.T @ (xyz(contact.point) - g) - centre)
            # 1e-12 m: the closed forms' positions are exact to ~1e-16 of the size (0.1 m)
            assert abs(local[2]) < 1e-12, (suffix, local)
            assert abs((local[0] / a) ** 2 + (local[1] / b) ** 2 - 1) < 1e-12, (suffix, local)
            # the contact angle is the polar angle from x towards y (1e-9 rad: θ, ψ come
            # from the phase by complex steps, the points from the closed forms)
            polar = np.arctan2(local[1], local[0])
            assert abs(np.angle(np.exp(1j * (polar - angle)))) < 1e-9, (suffix, polar, angle)
        checked += 1
    assert checked >= 10
    return checked


# -- one process: /tf at rate, latched topics to late joiners, changes at run time ----------

def test_tf_latched_topics_and_changes_resend_what_they_alter_and_nothing_else(client):
    """One ``roller`` process (its start and discovery are the slow part), checked in two
    stages: first /tf against pose and the physics, /tf_static and robot_description reaching
    late joiners; then parameter changes re-send only what they alter."""
    node, executor = client
    got = {'pose': [], '/tf': [], 'contact_a': [], 'contact_b': [], 'rolling_state': []}
    subscriptions = [node.create_subscription(kind, topic, got[topic].append, 1000)
                     for topic, kind in (('pose', PoseStamped), ('/tf', TFMessage),
                                         ('contact_a', PointStamped),
                                         ('contact_b', PointStamped),
                                         ('rolling_state', JointState))]
    process = start_roller('-p', f'rate:={RATE}', *body_params())
    try:
        assert spin_until(executor, lambda: len(got['/tf']) >= 40), 'no /tf'
        # late joiners: the node published both before these subscriptions existed
        statics, descriptions = [], []
        node.create_subscription(TFMessage, '/tf_static', statics.append, LATCHED)
        node.create_subscription(String, 'robot_description', descriptions.append, LATCHED)
        assert spin_until(executor, lambda: statics and descriptions), 'no latched message'
        assert spin_until(executor, lambda: len(got['/tf']) >= 60)
        first = {topic: list(messages) for topic, messages in got.items()}   # the first body
        _check_tf_and_latched(first, statics, descriptions)
        for subscription in subscriptions[2:]:      # the contacts and states: not needed now
            node.destroy_subscription(subscription)
        _check_changes(executor, node, got['pose'], got['/tf'], statics, descriptions)
    finally:
        code, err = stop(process)
    assert code == 0 and 'Traceback' not in err, err


def _check_tf_and_latched(got, statics, descriptions):
    poses = {stamp_ns(m.header): m for m in got['pose']}
    tfs = {stamp_ns(m.transforms[0].header): m for m in got['/tf']}
    # /tf at rate: consecutive stamps one period apart (reliable, keep last 100)
    assert np.all(np.diff(sorted(tfs)) == PERIOD_NS)
    common = sorted(set(poses) & set(tfs))
    assert len(common) >= 40
    for stamp in common:
        assert_tf_is_pose(tfs[stamp], poses[stamp])
    # /tf_static: one message, both disks, once (nothing changed)
    assert len(statics) == 1
    static = static_frames(statics[0])
    assert set(static) == {'twodisk_body_disk_a', 'twodisk_body_disk_b'}
    assert_contacts_on_rims(tfs, {stamp_ns(m.header): m for m in got['contact_a']},
                            {stamp_ns(m.header): m for m in got['contact_b']},
                            {stamp_ns(m.header): m for m in got['rolling_state']}, static)
    # robot_description: a URDF whose links are the body and its two disks
    (description,) = descriptions
    assert_urdf(description.data, 'twodisk_body', static)


def call(executor, client, parameter):
    request = SetParameters.Request(parameters=[parameter.to_parameter_msg()])
    future = client.call_async(request)
    assert spin_until(executor, future.done), 'service call timed out'
    (result,) = future.result().results
    return result


def _check_changes(executor, node, poses, tfs, statics, descriptions):
    """Changes at run time re-send what they alter and nothing else (``statics`` and
    ``descriptions`` hold the one latched message each so far)."""
    setter = node.create_client(SetParameters, '/roller/set_parameters')
    assert setter.wait_for_service(timeout_sec=STARTED)

    # friction alters neither: after 10 more samples, nothing was re-sent
    assert call(executor, setter, Parameter('friction', value=0.8)).successful
    count = len(poses)
    assert spin_until(executor, lambda: len(poses) >= count + 10)
    assert (len(statics), len(descriptions)) == (1, 1)

    # delta moves the disk centres (±delta e2) and changes the URDF
    assert call(executor, setter, Parameter('delta', value=0.06)).successful
    assert spin_until(executor, lambda: len(statics) == 2 and len(descriptions) == 2)
    static = static_frames(statics[-1])
    np.testing.assert_array_equal(static['twodisk_body_disk_a'][1], [0.0, -0.06, 0.0])
    np.testing.assert_array_equal(static['twodisk_body_disk_b'][1], [0.0, 0.06, 0.0])
    assert descriptions[-1].data != descriptions[0].data

    # body_frame renames the child on /tf, the static parents and the URDF's links
    assert call(executor, setter, Parameter('body_frame', value='oloid')).successful
    assert spin_until(executor, lambda: len(statics) == 3 and len(descriptions) == 3)
    assert set(static_frames(statics[-1])) == {'oloid_disk_a', 'oloid_disk_b'}
    assert_urdf(descriptions[-1].data, 'oloid', static_frames(statics[-1]))
    # (/tf sent before the change may still be queued here: from the first renamed one on)
    tfs.clear()
    children = lambda: [m.transforms[0].child_frame_id for m in tfs]  # noqa: E731

    def renamed():
        return 'oloid' in children() and len(tfs) - children().index('oloid') >= 5
    assert spin_until(executor, renamed)
    assert set(children()[children().index('oloid'):]) == {'oloid'}

    # refused at run time, one line each: a bad body_frame, following /clock
    for parameter, words in ((Parameter('body_frame', value='world'), 'frame_id'),
                             (Parameter('body_frame', value='a b'), 'spaces'),
                             (Parameter('use_sim_time', value=True), 'use_sim_time')):
        result = call(executor, setter, parameter)
        assert not result.successful and words in result.reason, result.reason
        assert '\n' not in result.reason
    count = len(poses)
    assert spin_until(executor, lambda: len(poses) >= count + 10)   # still running
    assert len(statics) == 3


def assert_urdf(text, body_frame, static=None, mass=1.0):
    """The URDF as yourdfpy reads it: the body link with the run's mass and its meshes on
    disk; the disk links on fixed joints placed as the /tf_static transforms (if given)."""
    import io
    from urllib.parse import unquote, urlparse
    import yourdfpy
    robot = yourdfpy.URDF.load(io.StringIO(text), build_scene_graph=False,
                               load_meshes=False).robot
    links = {link.name: link for link in robot.links}
    assert set(links) == {body_frame, body_frame + '_disk_a', body_frame + '_disk_b'}
    assert links[body_frame].inertial.mass == mass
    meshes = [Path(unquote(urlparse(visual.geometry.mesh.filename).path))
              for visual in links[body_frame].visuals]
    assert meshes and all(path.is_file() for path in meshes)
    # in the suite's temporary cache (conftest), never the user's ~/.cache
    cache = Path(os.environ['XDG_CACHE_HOME']).resolve()
    assert all(path.resolve().is_relative_to(cache) for path in meshes), meshes
    assert not cache.is_relative_to(Path.home().resolve() / '.cache')
    joints = {j.child: j for j in robot.joints}
    for suffix in ('_disk_a', '_disk_b'):
        joint = joints[body_frame + suffix]
        assert (joint.type, joint.parent) == ('fixed', body_frame)
        if static is not None:
            parent, translation, axes = static[body_frame + suffix]
            np.testing.assert_array_equal(joint.origin[:3, 3], translation)
            # rpy → matrix in float64: the 0/±1 entries to rounding (16 ulps of 1)
            np.testing.assert_allclose(joint.origin[:3, :3], axes, rtol=0, atol=ulps(16))
    return robot


# -- bad input -------------------------------------------------------------------------------



@pytest.mark.parametrize('arguments, words', [
    (["body_frame:=''"], 'body_frame must be a non-empty frame name'),
    (["body_frame:='two words'"], 'without spaces'),
    (['body_frame:=/twodisk_body'], 'leading "/"'),
    (['body_frame:=world'], 'body_frame must differ from frame_id'),
    (['frame_id:=map', 'body_frame:=map'], "include frame_id 'map'"),
    (['frame_id:=body_disk_b', 'body_frame:=body'], "include frame_id 'body_disk_b'"),
    (['body_frame:=12'], 'body_frame is a string'),
    (['use_sim_time:=true'], 'use_sim_time must be false for roller'),
    (['frame_id:=/world'], 'frame_id must be a non-empty frame name'),
], ids=['empty', 'space', 'slash', 'frame_id', 'both', 'disk-frame', 'integer', 'sim-time',
        'frame_id-slash'])
def test_bad_frames_or_sim_time_exit_2_with_one_line(arguments, words, monkeypatch, capfd):
    """Through the entry function in this process (tests/roller_here.py): body_frame:=12 is
    refused by the argument check (before rclpy), use_sim_time:=true by the node (after
    rclpy.init); refusals at both places as real processes are in test_node_reliability.py."""
    params = [arg for argument in arguments for arg in ('-p', argument)]
    args = ('-p', 'realtime:=false', '-p', 'duration:=0.1', *params)
    code, err = run_roller_main(('--params-file', 'config/oloid.yaml', *args),
                                monkeypatch, capfd, domain=DOMAIN, cwd=REPO)
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith('roller: ') and words in lines[0], err


# -- the recording -----------------------------------------------------------------------------

def test_recording_holds_tf_tf_static_and_robot_description(tmp_path, monkeypatch, capfd):
    """As rosbag2 records them: /tf per sample, /tf_static and robot_description once,
    transient local in their offered QoS; read by rosbags and by mcap-ros2-support. The
    node's batch run through its entry function in this process (the claim is the file)."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    from twodisk_ros.recordings import read_recording
    target = tmp_path / 'frames.mcap'
    code, err = run_roller_main(('--params-file', 'config/oloid.yaml', '-p', 'realtime:=false',
                                 '-p', 'duration:=2.0', '-p', 'rate:=100.0',
                                 '-p', 'frame_id:=odom', '-p', 'body_frame:=oloid',
                                 '-p', f'record:={target}', *body_params()),
                                monkeypatch, capfd, domain=DOMAIN, cwd=REPO)
    assert code == 0 and 'Traceback' not in err, err
    store = get_typestore(Stores.ROS2_JAZZY)
    got = {}
    with AnyReader([target], default_typestore=store) as reader:
        qos = {c.topic: c.ext.offered_qos_profiles for c in reader.connections}
        for connection, log_time, data in reader.messages():
            message = reader.deserialize(data, connection.msgtype)
            got.setdefault(connection.topic, []).append((log_time, message))
    assert len(got['/pose']) == len(got['/tf']) == 201
    for (log_pose, pose), (log_tf, tf) in zip(got['/pose'], got['/tf']):
        assert log_pose == log_tf
        assert_tf_is_pose(tf, pose, parent='odom', child='oloid')
    for topic in ('/tf_static', '/robot_description'):
        (profile,) = qos[topic]
        assert profile.durability.name == 'TRANSIENT_LOCAL' and profile.depth == 1, topic
        assert len(got[topic]) == 1, topic
        assert got[topic][0][0] == got['/pose'][0][0]      # sent with the first sample
    assert qos['/tf'][0].durability.name == 'VOLATILE' and qos['/tf'][0].depth == 100
    (_, static), = got['/tf_static']
    assert {t.child_frame_id: t.header.frame_id for t in static.transforms} == {
        'oloid_disk_a': 'oloid', 'oloid_disk_b': 'oloid'}
    (_, description), = got['/robot_description']
    assert_urdf(description.data, 'oloid', static_frames(static))
    # mcap-ros2-support, and the parameters in the metadata
    recording = read_recording(target, decode=lambda topic: topic in (
        '/tf', '/tf_static', '/robot_description'))
    assert not recording.undecodable
    tfs = [m.msg for m in recording.messages if m.topic == '/tf']
    assert [t.transforms[0].transform.translation.x for t in tfs] == [
        pose.pose.position.x for _, pose in got['/pose']]
    assert recording.metadata['twodisk_ros']['body_frame'] == 'oloid'
    assert '/clock' not in qos                               # published, not recorded


def test_an_unwritable_mesh_cache_leaves_a_urdf_without_meshes(tmp_path, monkeypatch, capfd):
    """The motion does not need the meshes: a warning, and the URDF keeps links and joints.
    Through the entry function in this process (the cache directory is read from the
    environment at each build)."""
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore
    blocker = tmp_path / 'a_file'
    blocker.write_text('not a directory')
    target = tmp_path / 'no_meshes.mcap'
    monkeypatch.setenv('XDG_CACHE_HOME', str(blocker / 'cache'))
    code, err = run_roller_main(('-p', 'realtime:=false', '-p', 'duration:=0.1',
                                 '-p', f'record:={target}'), monkeypatch, capfd,
                                domain=DOMAIN, cwd=REPO)
    assert code == 0, err
    warnings = [line for line in err.splitlines() if '[WARN]' in line]
    assert len(warnings) == 1 and 'robot_description without meshes' in warnings[0], err
    assert 'XDG_CACHE_HOME' in warnings[0]
    with AnyReader([target], default_typestore=get_typestore(Stores.ROS2_JAZZY)) as reader:
        (connection,) = [c for c in reader.connections if c.topic == '/robot_description']
        ((_, _, data),) = list(reader.messages(connections=[connection]))
        text = reader.deserialize(data, connection.msgtype).data
    robot = ElementTree.fromstring(text)
    assert robot.find('.//mesh') is None
    assert {link.get('name') for link in robot.findall('link')} == {
        'twodisk_body', 'twodisk_body_disk_a', 'twodisk_body_disk_b'}

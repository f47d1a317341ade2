"""``twodisk-view``: a Foxglove WebSocket server of the rolling body, without ROS.

The servers run as the command in a process of their own, with rclpy made unimportable (the
whole path of the command must run without ROS), on a free port (``--port 0``, the port read
from its first line), and are read with the headless client of ``foxglove_client`` (``websockets``
and ``google.protobuf``, nothing of twodisk_ros or foxglove-sdk). The values received are
compared with the physics library called independently at the same times, or with the
recording read by ``mcap_ros2``. The server is killed by its PID in a finally. A server
answers several claims: the live oloid those of the channels, the values, the subprotocols
and SIGINT; a solid body at one sample per 20 s those of the hull, the static content and
SIGTERM. Bad input is refused by ``main`` called in this process (one line, exit 2), and once
by the command's own process.

The roller node (for the recording) runs in this process with ROS_DOMAIN_ID 46, loopback
discovery only.
"""

import contextlib
import io
import math
from pathlib import Path
import signal
import socket
import subprocess
import sys

import numpy as np
import pytest
import yaml

from batch_recording import record
from foxglove_client import SUBPROTOCOL, collect, refused, stamp_ns
from view_process import ENV, RUNNER, View, wait_for_handlers
from twodisk_ros.model.mesh import mesh_parts
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.mass.models import mass_properties
from twodisk_ros.physics.motion.simulate import simulate
from twodisk_ros.model import palette

REPO = Path(__file__).resolve().parents[1]
OLOID = REPO / 'config' / 'oloid.yaml'
TOPICS = ('/tf', '/body', '/contact_segment', '/contact_forces', '/traces', '/parameters')
#: "Floating precision": the same samples of the same motion, computed twice, agree to
#: rounding: positions to this share of the body size, quaternions and directions to this.
ROUNDING = 1e-12

def _oloid_parameters():
    return yaml.safe_load(OLOID.read_text())['/**']['ros__parameters']


def _library(p, t):
    """Poses, contacts and ground forces of the parameters ``p`` at times ``t`` (s): the
    physics library, called here independently of the command."""
    body = EllipseBody(p['a'], p['b'], p['delta'])
    mass = mass_properties(p['mass_model'], p['a'], p['b'], p['delta'], p['mass'])
    dynamics = RollingDynamics(body, mass, p['gravity'])
    motion = simulate(dynamics, t, mode=p['mode'], theta0=p['theta0'], branch=p['branch'],
                      omega0=p['omega0'], method=p['method'], tolerance=p['tolerance'])
    state = dynamics.cycle.state(motion.phase)
    forces = ContactForceModel(dynamics).dynamic(motion.phase, motion.phase_rate)
    return body, state, forces, mass.mass * p['gravity']


def _rotation(q):
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def _vector(v):
    return np.array([v.x, v.y, v.z])


def _quaternion(q):
    return np.array([q.x, q.y, q.z, q.w])


def _colour(c):
    return (c.r, c.g, c.b)


def _live_enough(received):
    return (received.count('/tf') >= 40 and all(received.count(t) for t in TOPICS)
            and len(received.messages['/traces'][-1][1].entities[0].lines[0].points) >= 2)


def _port_is_free(port):
    """True if nobody listens on ``port`` any more: it can be bound and listened on."""
    with socket.socket() as again:
        again.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)   # as servers do
        try:
            again.bind(('127.0.0.1', port))
            again.listen()
        except OSError:
            return False
    return True


@pytest.fixture(scope='module')
def live():
    """A live oloid (config/oloid.yaml): the subprotocols it refuses and accepts, what a
    client received from it, and its stop by SIGINT."""
    view = View('--params-file', OLOID, '--port', 0)
    try:
        port = view.wait_serving()
        handshakes = {'foxglove.websocket.v1': refused(port, 'foxglove.websocket.v1'),
                      SUBPROTOCOL: refused(port, SUBPROTOCOL)}
        received = collect(port, TOPICS, _live_enough, request_parameters=True)
        status, stderr = view.stop(signal.SIGINT)
        view.handshakes, view.freed = handshakes, _port_is_free(port)
        yield received, status, stderr, view
    finally:
        view.kill()


@pytest.fixture(scope='module')
def sparse_solid():
    """A solid oloid at one sample per 20 s: a first client subscribes to /tf until the
    first sample, a second one then to /body and /parameters; stopped by SIGTERM."""
    view = View('--params-file', OLOID, '--mass-model', 'solid', '--rate', 0.05, '--port', 0)
    try:
        port = view.wait_serving()
        first = collect(port, ['/tf'], lambda r: r.count('/tf'))   # a sample was just shown
        received = collect(port, ['/body', '/parameters'],
                           lambda r: r.count('/body') and r.count('/parameters'), timeout=10.0)
        status, stderr = view.stop(signal.SIGTERM)
        view.freed = _port_is_free(port)
        yield first, received, status, stderr, view
    finally:
        view.kill()


def test_live_server_info_and_every_channel(live):
    received, status, stderr, view = live
    assert status == 0, stderr
    assert received.server_info['name'] == 'twodisk-view'
    assert {'time', 'parameters'} <= set(received.server_info['capabilities'])
    assert set(received.channels) == set(TOPICS)
    schemas = {t: c['schemaName'] for t, c in received.channels.items()}
    assert schemas['/tf'] == 'foxglove.FrameTransforms'
    assert all(schemas[t] == 'foxglove.SceneUpdate' for t in TOPICS[1:5])
    assert received.channels['/parameters']['encoding'] == 'json'
    assert all(received.count(t) > 0 for t in TOPICS), {t: received.count(t) for t in TOPICS}
    assert 'stopped after' in ''.join(view.stdout)


def test_live_transforms_equal_the_library_poses(live):
    """Each world → body transform is the library's pose at the sample's time, the disk
    frames put the disk rims on the body's outlines, and the stamps are the node's."""
    received, *_ = live
    p = _oloid_parameters()
    run = received.messages['/parameters'][0][1]['run']
    start, rate = run['start_stamp_ns'], run['rate']
    assert rate == p['rate'] and run['frame_id'] == p['frame_id']
    transforms = [m.transforms for _, m in received.messages['/tf']]
    stamps = np.array([stamp_ns(tf[0].timestamp) for tf in transforms])
    ticks = np.round((stamps - start) * rate / 1e9).astype(np.int64)
    assert np.array_equal(stamps, start + np.round(ticks * (1e9 / rate)).astype(np.int64))
    assert np.all(np.diff(ticks) >= 1)
    assert [log for log, _ in received.messages['/tf']] == list(stamps)
    body, state, _, _ = _library(p, ticks / rate)
    size = body.size
    for k, tf in enumerate(transforms):
        world = tf[0]
        assert (world.parent_frame_id, world.child_frame_id) == ('world', 'twodisk_body')
        assert np.max(np.abs(_vector(world.translation) - state.position_g[k])) \
            <= ROUNDING * size
        assert np.max(np.abs(_rotation(_quaternion(world.rotation)) - state.rotation[k])) \
            <= ROUNDING
        assert abs(np.linalg.norm(_quaternion(world.rotation)) - 1) <= ROUNDING
        disks = {d.child_frame_id: d for d in tf[1:]}
        assert set(disks) == {'twodisk_body_disk_a', 'twodisk_body_disk_b'}
        assert all(d.parent_frame_id == 'twodisk_body' for d in tf[1:])
    # the rims x²/a² + y²/b² = 1, z = 0 of the disk frames lie on the body's disks:
    # disk 1 in the plane e3 = 0 around (0, −Δ, 0), disk 2 in e1 = 0 around (0, Δ, 0)
    s = np.linspace(0, 2 * math.pi, 17)
    rim = np.stack([p['a'] * np.cos(s), p['b'] * np.sin(s), 0 * s], -1)
    a, b, d = p['a'], p['b'], p['delta']
    for name, (normal, along_a, centre) in {'twodisk_body_disk_a': (2, 0, -d),
                                             'twodisk_body_disk_b': (0, 2, d)}.items():
        frame = disks[name]
        points = rim @ _rotation(_quaternion(frame.rotation)).T + _vector(frame.translation)
        assert np.max(np.abs(points[:, normal])) <= ROUNDING * size
        assert np.max(np.abs(((points[:, 1] - centre) / a) ** 2
                             + (points[:, along_a] / b) ** 2 - 1)) <= ROUNDING
    # the server's time is the stamp of the sample just shown: a sample's stamp, and once
    # subscribed (from the first /tf received on) the stamp of a /tf received
    times = np.array(received.times)
    time_ticks = np.round((times - start) * rate / 1e9).astype(np.int64)
    assert len(times) and np.array_equal(
        times, start + np.round(time_ticks * (1e9 / rate)).astype(np.int64))
    inside = times[(times >= stamps[0]) & (times <= stamps[-1])]
    assert len(inside) and set(inside) <= set(stamps)


def test_live_scene_contacts_forces_and_traces(live):
    """The contact segment, the force arrows and the traces are the library's contacts and
    ground forces at their stamps; the colours are the palette's."""
    received, *_ = live
    p = _oloid_parameters()
    run = received.messages['/parameters'][0][1]['run']
    start, rate = run['start_stamp_ns'], run['rate']

    def tick(entity):
        return round((stamp_ns(entity.timestamp) - start) * rate / 1e9)

    segments = [m.entities[0] for _, m in received.messages['/contact_segment']]
    arrows = [m.entities[0] for _, m in received.messages['/contact_forces']]
    traces = [m.entities for _, m in received.messages['/traces']]
    ticks = sorted({tick(e) for e in segments + arrows} | {tick(t[0]) for t in traces})
    body, state, forces, weight = _library(p, np.array(ticks) / rate)
    at = {k: i for i, k in enumerate(ticks)}
    size = body.size
    for segment in segments:
        i = at[tick(segment)]
        line = segment.lines[0]
        ends = np.array([_vector(q) for q in line.points])
        assert np.max(np.abs(ends - [state.contact_a[i], state.contact_b[i]])) <= ROUNDING * size
        assert _colour(line.color) == pytest.approx(palette.rgb(palette.AB), abs=1e-7)
    for entity in arrows:
        i = at[tick(entity)]
        assert len(entity.arrows) == 2
        for arrow, point, force in zip(entity.arrows, (state.contact_a[i], state.contact_b[i]),
                                       (forces.force_a[i], forces.force_b[i])):
            start_point = _vector(arrow.pose.position)
            direction = _rotation(_quaternion(arrow.pose.orientation))[:, 0]
            length = arrow.shaft_length + arrow.head_length
            assert np.max(np.abs(start_point - point)) <= ROUNDING * size
            expected = force * size / weight
            assert np.max(np.abs(direction * length - expected)) <= ROUNDING * size
    for entities in traces:
        i = at[tick(entities[0])]
        ends = {e.id: _vector(e.lines[0].points[-1]) for e in entities}
        colours = {e.id: _colour(e.lines[0].color) for e in entities}
        assert np.max(np.abs(ends['trace_a'] - state.contact_a[i])) <= ROUNDING * size
        assert np.max(np.abs(ends['trace_b'] - state.contact_b[i])) <= ROUNDING * size
        assert np.max(np.abs(ends['trace_g'] - state.position_g[i])) <= ROUNDING * size
        assert colours['trace_a'] == pytest.approx(palette.rgb(palette.A), abs=1e-7)
        assert colours['trace_b'] == pytest.approx(palette.rgb(palette.B), abs=1e-7)


def _check_body(update, p, parts):
    """The /body update: the mesh's parts as mesh_parts gives them, coloured as the URDF's,
    in the body frame; the rims on x²/a² + y²/b² = 1 in the disk frames, blue and orange."""
    entities = {e.id: e for e in update.entities}
    mesh = entities['body']
    assert mesh.frame_id == 'twodisk_body' and mesh.frame_locked
    assert len(mesh.triangles) == len(parts)
    colours = {'disk_a': palette.A, 'disk_b': palette.B, 'hull': palette.HULL}
    for triangles, (name, part) in zip(mesh.triangles, parts.items()):
        vertices = np.array([_vector(q) for q in triangles.points])
        assert np.array_equal(vertices, part.vertices), name
        assert np.array_equal(np.array(triangles.indices).reshape(-1, 3), part.faces), name
        assert _colour(triangles.color) == pytest.approx(palette.rgb(colours[name]), abs=1e-7)
    for rim_id, frame, colour in (('rim_a', 'twodisk_body_disk_a', palette.A),
                                  ('rim_b', 'twodisk_body_disk_b', palette.B)):
        rim = entities[rim_id]
        assert rim.frame_id == frame and rim.frame_locked
        points = np.array([_vector(q) for q in rim.lines[0].points])
        assert np.max(np.abs((points[:, 0] / p['a']) ** 2 + (points[:, 1] / p['b']) ** 2 - 1)) \
            <= ROUNDING
        assert _colour(rim.lines[0].color) == pytest.approx(palette.rgb(colour), abs=1e-7)


def test_live_body_mesh_and_parameters(live):
    received, *_ = live
    p = _oloid_parameters()
    parts = mesh_parts(EllipseBody(p['a'], p['b'], p['delta']), p['mass_model'])
    assert set(parts) == {'disk_a', 'disk_b'}
    _check_body(received.messages['/body'][0][1], p, parts)
    shown = received.messages['/parameters'][0][1]['parameters']
    for name, value in p.items():
        assert shown[name] == value, name
    assert received.parameters, 'no answer to getParameters'
    served = {q['name']: q['value'] for q in received.parameters[0]['parameters']}
    assert served['a'] == p['a'] and served['mass_model'] == p['mass_model']


def test_solid_body_is_the_grey_hull(sparse_solid):
    _, received, status, stderr, _ = sparse_solid
    assert status == 0, stderr
    p = dict(_oloid_parameters(), mass_model='solid')
    parts = mesh_parts(EllipseBody(p['a'], p['b'], p['delta']), 'solid')
    assert set(parts) == {'hull'}
    _check_body(received.messages['/body'][0][1], p, parts)


def test_old_subprotocol_is_refused_and_the_sdk_one_accepted(live):
    *_, view = live
    assert view.handshakes['foxglove.websocket.v1'] == 400
    assert view.handshakes[SUBPROTOCOL] is None


def _recording(tmp_path, duration=2.0):
    return record(tmp_path / 'run.mcap', OLOID, domain=int(ENV['ROS_DOMAIN_ID']),
                  duration=duration)


def _recorded_poses(path):
    """{stamp ns: (G, q)} of /pose, read with mcap_ros2 (not the package's reader)."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    poses = {}
    with open(path, 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _, channel, _, msg in reader.iter_decoded_messages(topics=['/pose']):
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            p, q = msg.pose.position, msg.pose.orientation
            poses[stamp] = (np.array([p.x, p.y, p.z]), np.array([q.x, q.y, q.z, q.w]))
    return poses


def test_replay_transforms_equal_the_recording(tmp_path):
    """Replayed transforms carry the recorded poses and stamps, bit for bit, every sample
    from the client's subscription on to the end of the recording."""
    recording = _recording(tmp_path, duration=1.0)
    poses = _recorded_poses(recording)
    last = max(poses)

    def enough(received):
        return (received.count('/parameters') and received.count('/contact_forces')
                and any(log == last for log, _ in received.messages.get('/tf', ())))
    view = View(recording, '--port', 0, '--speed', 0.5)
    try:
        port = view.wait_serving()
        received = collect(port, TOPICS, enough)
        view.wait_line('the run ended after')
        status, stderr = view.stop()
    finally:
        view.kill()
    assert status == 0, stderr
    stamps = []
    for log_time, message in received.messages['/tf']:
        world = message.transforms[0]
        stamp = stamp_ns(world.timestamp)
        assert stamp == log_time and stamp in poses
        position, quaternion = poses[stamp]
        assert np.array_equal(_vector(world.translation), position)
        assert np.array_equal(_quaternion(world.rotation), quaternion)
        stamps.append(stamp)
    recorded = sorted(poses)
    assert len(stamps) >= 10 and stamps == recorded[recorded.index(stamps[0]):]
    run = received.messages['/parameters'][0][1]['run']
    assert run['start_stamp_ns'] == recorded[0] and str(recording) in run['source']
    assert f'the run ended after {len(recorded)} samples' in ''.join(view.stdout)


def _one_line(status, stderr):
    assert status == 2, (status, stderr)
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('twodisk-view: '), stderr
    assert 'Traceback' not in stderr
    return lines[0]


def _one_line_refusal_by_the_process(*args):
    """The command's own process (rclpy unimportable; RUNNER exits 9 if rclpy or matplotlib
    were imported)."""
    result = subprocess.run([sys.executable, '-c', RUNNER, *map(str, args)], cwd=REPO, env=ENV,
                            capture_output=True, text=True, timeout=120)
    return _one_line(result.returncode, result.stderr)


@contextlib.contextmanager
def _own_signal_handlers():
    """main installs its SIGINT/SIGTERM handlers: pytest's are put back afterwards."""
    saved = {number: signal.getsignal(number) for number in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for number, handler in saved.items():
            signal.signal(number, handler)


def _one_line_refusal(*args):
    """``main`` called in this process: its exit status and stderr (nothing on stdout)."""
    from twodisk_ros.view.cli import main
    out, err = io.StringIO(), io.StringIO()
    with _own_signal_handlers(), contextlib.redirect_stdout(out), \
            contextlib.redirect_stderr(err):
        status = main([str(arg) for arg in args])
    assert out.getvalue() == '', out.getvalue()
    return _one_line(status, err.getvalue())


def test_bad_input_is_one_line_and_exit_2(tmp_path):
    missing = tmp_path / 'missing.mcap'
    assert 'missing.mcap' in _one_line_refusal_by_the_process(missing)
    assert 'missing.mcap' in _one_line_refusal(missing)
    text = tmp_path / 'text.mcap'
    text.write_text('not a recording\n')
    assert 'not an MCAP file' in _one_line_refusal(text)
    assert 'delta/a' in _one_line_refusal('--delta', 0.2, '--port', 0)
    bad_file = tmp_path / 'bad.yaml'
    bad_file.write_text('/**:\n  ros__parameters:\n    a: [1\n')
    assert 'bad.yaml' in _one_line_refusal('--params-file', bad_file, '--port', 0)
    assert 'loopback' in _one_line_refusal('--host', '192.0.2.1')
    assert '--speed' in _one_line_refusal('--speed', 0)
    assert '--port' in _one_line_refusal('--port', 70000)
    assert 'rate' in _one_line_refusal('--rate', 5000.0, '--port', 0)
    assert 'applies to simulated runs' in _one_line_refusal(text, '--a', 0.2)


def test_a_port_in_use_is_refused():
    with socket.socket() as taken:
        taken.bind(('127.0.0.1', 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert 'in use' in _one_line_refusal('--port', port)


@pytest.mark.parametrize('number', [signal.SIGINT, signal.SIGTERM])
def test_signal_stops_the_server_and_frees_the_port(number, request):
    """SIGINT stopped the live oloid after >= 40 samples on /tf, SIGTERM the sparse solid
    one (idle between its samples) after its first: exit 0, the last line said, the port
    free (bound again by the fixture once the process had exited)."""
    if number == signal.SIGINT:
        received, status, stderr, view = request.getfixturevalue('live')
    else:
        received, _, status, stderr, view = request.getfixturevalue('sparse_solid')
    assert received.count('/tf') >= 1
    assert status == 0, stderr
    assert 'stopped after' in ''.join(view.stdout)
    assert view.freed


def test_signal_before_serving_exits_0():
    """A signal during start-up (the costliest body's tables: 2-4 s) ends the command at
    once, exit 0, without serving."""
    view = View('--port', 0, '--a', 0.1, '--b', 0.001, '--delta', 0.0001, '--theta0', 0.0)
    try:
        wait_for_handlers(view.process.pid)
        status, stderr = view.stop(signal.SIGTERM)
        assert status == 0, stderr
        assert not any('serving' in line for line in view.stdout)
    finally:
        view.kill()


def test_help_states_the_protocol_and_the_viewers(tmp_path):
    result = subprocess.run([sys.executable, '-m', 'twodisk_ros.view', '--help'], cwd=tmp_path,
                            env=ENV, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0
    text = ' '.join(result.stdout.split())
    assert 'foxglove.sdk.v1' in text and 'Lichtblick 1.22.0' in text
    assert 'foxglove.websocket.v1' in text and list(tmp_path.iterdir()) == []


def test_static_content_reaches_a_client_between_sparse_samples(sparse_solid):
    """With 20 s between samples, a client that subscribes just after a sample gets the body
    and the parameters at once, not at the next sample (it waits 10 s at most)."""
    first, received, status, stderr, _ = sparse_solid
    assert first.count('/tf') == 1
    assert status == 0, stderr
    assert received.count('/body') and received.count('/parameters')
    assert received.messages['/parameters'][0][1]['run']['rate'] == 0.05

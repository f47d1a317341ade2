"""twodisk-explore without a browser: its motion is the node's, its refusals are the node's,
its command line refuses bad input in one line (exit 2), its lesson is one offline file.

References: the node's Simulation sampled directly (the page must not re-implement physics),
the node's own checks (RollerSettings.checked) for the reasons, the equilibria of the
stability module against the extrema of z_G along the cycle's poses (two methods), the MCAP
recording read by rosbags (an independent reader).
"""

import math
import os
import re
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from twodisk_ros.explore.motion import CYCLE_POINTS, LiveMotion, RecordedMotion
from twodisk_ros.run.simulation import Simulation
from twodisk_ros.runs import settings_from

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / 'config'
ENV = dict(os.environ, PYTHONPATH=str(REPO))


def _explore(*args, cwd=None, timeout=120):
    return subprocess.run([sys.executable, '-m', 'twodisk_ros.explore', *map(str, args)],
                          capture_output=True, text=True, env=ENV, cwd=cwd, timeout=timeout)


@pytest.fixture(scope='module')
def oloid():
    return settings_from(str(CONFIG / 'oloid.yaml'), realtime=True)


def test_frames_are_the_nodes_samples_bit_for_bit(oloid):
    """The page's frames are Simulation.sample at the same times (no physics of its own)."""
    motion = LiveMotion(oloid)
    frames = [motion.advance(0.05, 5) for _ in range(4)]
    t = np.concatenate([f.t for f in frames])
    assert np.all(np.diff(t) > 0) and t[0] == 0.0 and math.isclose(t[-1], 0.2, rel_tol=1e-12)
    reference = Simulation(oloid).sample(t, forces=True)
    got = {key: np.concatenate([getattr(f, key) for f in frames])
           for key in ('position_g', 'quaternion', 'contact_a', 'contact_b', 'normal_a',
                       'mu_required')}
    assert np.array_equal(got['position_g'], reference.position_g)
    assert np.array_equal(got['quaternion'], reference.quaternion)
    assert np.array_equal(got['contact_a'], reference.contact_a)
    assert np.array_equal(got['contact_b'], reference.contact_b)
    assert np.array_equal(got['normal_a'], reference.forces.normal_a)
    assert np.array_equal(got['mu_required'], reference.forces.mu_required)


def test_an_accepted_change_restarts_the_run_of_the_new_settings(oloid):
    motion = LiveMotion(oloid)
    motion.advance(0.3, 3)
    assert motion.change('theta0', 0.5) is None
    assert motion.t == 0.0 and motion.settings.theta0 == 0.5 and motion.restarts == 1
    frame = motion.advance(0.1, 2)
    reference = Simulation(oloid.with_values(theta0=0.5).checked()).sample(frame.t)
    assert np.array_equal(frame.position_g, reference.position_g)
    # a new body: a, b, delta of the two-circle roller
    assert motion.change('delta', 0.07) is None
    assert motion.body.delta == 0.07


@pytest.mark.parametrize('name, value', [('delta', 0.3), ('theta0', 3.0), ('b', 20.0),
                                         ('drive', 'fly'), ('damping', 1e5)])
def test_a_refused_value_gives_the_nodes_reason_and_the_motion_goes_on(oloid, name, value):
    motion = LiveMotion(oloid)
    before = motion.advance(0.1, 2)
    with pytest.raises(ValueError) as node:
        oloid.with_values(**{name: value}).checked()
    reason = motion.change(name, value)
    assert reason == ' '.join(str(node.value).split())
    assert motion.settings == oloid and motion.restarts == 0
    after = motion.advance(0.1, 2)
    assert after.t[0] > before.t[-1]


def test_a_drive_and_its_command_restart_a_driven_run(oloid):
    """drive speed with a command: the speed follows it (first-order lag, the node's scene)."""
    motion = LiveMotion(oloid)
    assert motion.change('drive', 'speed') is None
    assert motion.change('command', 6.0) is None
    frame = motion.advance(1.0, 10)
    reference = Simulation(oloid.with_values(drive='speed').checked(), drive='speed',
                           command=6.0).sample(frame.t)
    assert np.array_equal(frame.position_g, reference.position_g)


def test_the_cycle_curve_has_its_minima_at_the_stable_equilibria(oloid):
    """z_G along the cycle's poses (the page's curve) against the equilibria of the
    stability module: equal heights (to the 1e-9 m of docs/physics.md's pose accuracy) and a
    stable one lower than the curve on both sides, an unstable one higher (a second method)."""
    motion = LiveMotion(settings_from(realtime=True))     # a = b = 0.1 m, delta = 0.05 m
    u, z = motion.cycle()
    marks = motion.equilibria()
    kinds = [kind for *_, kind in marks]
    assert len(marks) >= 4 and 'stable' in kinds and 'unstable' in kinds
    poses = motion.simulation.dynamics.cycle.poses
    for phase, height, kind in marks:
        stable = kind == 'stable'
        near = np.asarray(poses(np.array([phase - 0.05, phase, phase + 0.05])).position_g)[:, 2]
        assert abs(near[1] - height) < 1e-9
        assert (near[[0, 2]] > height).all() if stable else (near[[0, 2]] < height).all()
    k = np.searchsorted(u, [m[0] for m in marks])
    assert np.all(np.abs(np.interp([m[0] for m in marks], u, z) - [m[1] for m in marks])
                  < (z.max() - z.min()) * (2 * math.pi / (len(u) - 1)) ** 2), k


@pytest.fixture(scope='module')
def served():
    """A viser server on a free loopback port (no browser)."""
    from twodisk_ros.explore.cli import _server, stop_server
    server = _server('127.0.0.1', 0)
    yield server
    stop_server(server)


def test_the_page_says_the_nodes_words_when_the_model_stops_holding(oloid, served):
    """friction 0.02: the oloid slips at once; the status line quotes the node's
    ValidityReport of the same run (its Simulation sampled at the page's times)."""
    from twodisk_ros.explore.page import Explorer
    settings = oloid.with_values(friction=0.02).checked()
    explorer = Explorer(served, LiveMotion(settings))
    frames = [explorer.step(0.05) for _ in range(4)]
    node = Simulation(settings)
    node.sample(np.concatenate([f.t for f in frames]), forces=True)
    assert node.invalid is not None and 'slip' in node.invalid.reason
    assert f'outside the rolling model:** {node.invalid.reason}' in explorer.status.content
    assert explorer.change('friction', 0.5) is None
    explorer.step(0.05)
    assert 'outside' not in explorer.status.content


@pytest.mark.parametrize('slope', [0.0, 0.3, -0.45])
def test_the_ground_is_the_nodes_plane(oloid, served, slope):
    """The drawn ground's normal (its rotation applied to z) is the node's ground normal
    (sin slope, 0, cos slope), and the shift keeps G's foot on it at the origin."""
    from twodisk_ros.explore.page import Explorer
    from twodisk_ros.run.scene_simulation import ground_normal
    explorer = Explorer(served, LiveMotion(oloid.with_values(slope=slope).checked()))
    frame = explorer.step(0.1)
    w, x, y, z = explorer.scene.ground.wxyz
    normal = np.array([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)])
    assert np.allclose(normal, ground_normal(slope), rtol=0, atol=4e-16)
    g = frame.position_g[-1]
    foot = g + explorer.scene.shift(g)
    assert abs(foot @ ground_normal(slope) - g @ ground_normal(slope)) < 1e-15
    assert np.allclose(foot, (g @ ground_normal(slope)) * ground_normal(slope), atol=1e-15)


def test_serves_prints_its_url_and_stops_on_sigterm():
    import signal
    import urllib.request
    process = subprocess.Popen([sys.executable, '-m', 'twodisk_ros.explore', '-p',
                                'omega0:=2.0'], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=ENV)
    try:
        line = process.stdout.readline()
        url = re.match(r'twodisk-explore: serving (http://127\.0\.0\.1:\d+/) ', line).group(1)
        with urllib.request.urlopen(url, timeout=20) as page:
            assert page.status == 200 and b'<html' in page.read(2000).lower()
    finally:
        process.send_signal(signal.SIGTERM)
        out, err = process.communicate(timeout=30)
    assert process.returncode == 0, err


def test_the_solid_body_is_drawn_as_its_hull(oloid, served):
    """mass_model solid: one grey hull mesh, closed, its volume the solid model's own
    (docs/physics.md: the hull mesh's volume within 55 / n^2 of the model at n rulings)."""
    from twodisk_ros.explore.page import Explorer
    from twodisk_ros.explore.scene3d import MESH_RESOLUTION
    explorer = Explorer(served, LiveMotion(oloid))
    assert sorted(explorer.scene.parts) == ['disk_a', 'disk_b']
    assert explorer.change('mass_model', 'solid') is None
    explorer.step(0.05)
    (name, hull), = explorer.scene.parts.items()
    assert name == 'hull' and len(explorer.scene.meshes) == 1
    v = np.asarray(hull.vertices)[np.asarray(hull.faces)]
    volume = np.einsum('ij,ij->i', v[:, 0], np.cross(v[:, 1], v[:, 2])).sum() / 6
    expected = _oloid_volume(explorer.motion.settings.a)
    assert abs(volume / expected - 1) < 55 / MESH_RESOLUTION ** 2, (volume, expected)


def _oloid_volume(r):
    """The Oloid's volume for circles of radius r (Dirnböck and Stachel 1997): 3.0524184 r^3."""
    return 3.0524184684 * r ** 3


def test_a_new_body_updates_the_plots_in_place(oloid, served):
    """delta 0.05 → 0.06 m: the same plot handle gets the new body's z_G along its cycle
    (the poses of a RunDescription of the new settings, built apart from the page) and one
    mark per equilibrium."""
    from twodisk_ros.explore.page import Explorer
    from twodisk_ros.run.description import RunDescription
    explorer = Explorer(served, LiveMotion(oloid.with_values(delta=0.05).checked()))
    plot = explorer.cycle_plot
    assert explorer.change('delta', 0.06) is None
    assert explorer.cycle_plot is plot
    # playing, the change draws the new motion's first frame with the new scene: t = 0 of the
    # new settings' run (its Simulation sampled apart from the page)
    first = explorer.shown
    assert first is not None and first.t[0] == 0.0 and explorer.restart_shown is not None
    reference = Simulation(oloid.with_values(delta=0.06).checked()).sample(first.t)
    assert np.array_equal(first.position_g, reference.position_g)
    u, z = plot.data[0], plot.data[1]
    grid = np.linspace(0.0, 2 * math.pi, CYCLE_POINTS)
    poses = RunDescription(oloid.with_values(delta=0.06).checked()).dynamics.cycle.poses
    assert np.array_equal(z[np.isin(u, grid)], np.asarray(poses(grid).position_g)[:, 2])
    marks = np.concatenate([np.isfinite(series) for series in plot.data[2:5]])
    assert marks.sum() == len(explorer.motion.equilibria())


def test_speed_pause_and_reset(oloid, served):
    """x10: 0.1 s of the show is 1 s of the run; paused, nothing advances; reset: t = 0."""
    from twodisk_ros.explore.page import Explorer
    explorer = Explorer(served, LiveMotion(oloid))
    explorer.set_speed(10.0)
    frame = explorer.step(0.1)
    assert frame.t[-1] == pytest.approx(1.0, rel=1e-12) and len(frame) == 1 + 50
    explorer.toggle()
    assert explorer.step(0.1) is None and explorer.motion.t == pytest.approx(1.0, rel=1e-12)
    explorer.toggle()
    explorer.reset()
    assert explorer.motion.t == 0.0 and explorer.step(0.1).t[0] == 0.0


def _distance_to_polyline(points, line):
    """Distance (m) of each point (n, 3) to a polyline (k, 3): the least over its segments."""
    a, b = line[:-1], line[1:]
    d = b - a
    rel = points[:, None, :] - a[None]
    s = np.clip(np.einsum('nkj,kj->nk', rel, d) / np.einsum('kj,kj->k', d, d), 0.0, 1.0)
    return np.linalg.norm(rel - s[..., None] * d[None], axis=2).min(axis=1)


def test_a_simplified_trace_keeps_the_points_a_circle_needs():
    """Points every theta on a circle of radius R: a chord spanning k steps passes
    R (cos psi - cos(k theta / 2)) from the farthest point between (psi = 0 for k even,
    theta / 2 for k odd), so the walk keeps every k-th point for the largest such k within
    the tolerance; a straight line keeps its two ends, and its turning point if it goes back."""
    from twodisk_ros.explore.scene3d import simplified
    radius, theta, tolerance = 0.3, 2 * math.pi / 400, 1e-4
    angles = theta * np.arange(150)
    circle = radius * np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], 1)
    def sagitta(k):
        return radius * (math.cos(0.0 if k % 2 == 0 else theta / 2) - math.cos(k * theta / 2))
    k = max(k for k in range(2, 150) if sagitta(k) <= tolerance)
    expected = list(range(0, 150, k))
    expected += [149] if expected[-1] != 149 else []
    assert simplified(circle, tolerance).tolist() == expected
    assert _distance_to_polyline(circle, circle[expected]).max() <= tolerance
    line = np.outer(np.linspace(0.0, 1.0, 50), [0.3, -0.2, 0.1])
    assert simplified(line, tolerance).tolist() == [0, 49]
    # out and back along the line: the turning point is kept (every point lies on the line,
    # but the tip lies beyond the chord from the first point to the last)
    cusp = np.concatenate([line, line[-2::-1]])
    assert simplified(cusp, tolerance).tolist() == [0, 49, 98]


def _centre_line(mesh, lift):
    """The centre line (starts and ends of its segments, (k, 3) each) of a strip of
    scene3d.ribbon: the midpoints of the pairs of vertices across each of its two crossed
    rectangles (they must agree to float32 rounding), less its lift."""
    v = np.asarray(mesh.vertices, dtype=float).reshape(-1, 8, 3)
    mid = 0.5 * (v[:, 0::2] + v[:, 1::2])                   # (k, 4, 3)
    assert np.abs(mid[:, 0] - mid[:, 1]).max() <= 1e-6
    assert np.abs(mid[:, 2] - mid[:, 3]).max() <= 1e-6
    return mid[:, 0] - lift, mid[:, 2] - lift


def test_the_drawn_traces_pass_within_their_tolerance_of_every_sample(oloid, served,
                                                                      monkeypatch):
    """2 s of the oloid: the strips of the finished traces have fewer points than samples,
    and every sample of A, B and G (the frames' own) lies within TRACE_TOLERANCE x size of
    the centre line drawn (sent as float32: 1e-6 m of rounding allowed), two rectangles
    TRACE_WIDTH x size wide across it at +-45 deg to the ground; the current chunk's lines
    go on from the finished one's last point to the last sample. Chunks of 32 points in
    groups of 2, so that 2 s of 100 samples a second make several groups."""
    from twodisk_ros.explore import scene3d
    from twodisk_ros.explore.scene3d import TRACE_TOLERANCE, TRACE_WIDTH, Scene3D
    monkeypatch.setattr(scene3d, 'TRACE_GROUP', 2)
    monkeypatch.setattr(scene3d, 'TRACE_CHUNK', 32)
    motion = LiveMotion(oloid)
    scene = Scene3D(served, motion)
    frames = [motion.advance(0.1, 10) for _ in range(20)]
    for frame in frames:
        scene.show(frame)
    traces = scene.traces
    groups = sorted(part[1] for part in traces.handles if part != 'now')
    assert len(traces.nodes) >= 3 and groups == list(range(len(groups))) and len(groups) >= 2
    for k, key in enumerate(('contact_a', 'contact_b', 'position_g')):
        samples = np.concatenate([getattr(f, key) for f in frames])
        lines = [_centre_line(traces.handles['done', g][k], traces.lift) for g in groups]
        starts, ends = (np.concatenate(part) for part in zip(*lines))
        assert np.abs(ends[:-1] - starts[1:]).max() <= 1e-6              # one chain
        drawn = np.concatenate([starts, ends[-1:]])
        covered = samples[:sum(node[1] for node in traces.nodes) + 1]
        assert len(drawn) < 0.7 * len(covered)
        tolerance = TRACE_TOLERANCE * scene.size + 1e-6
        assert _distance_to_polyline(covered, drawn).max() <= tolerance
        v = np.concatenate([np.asarray(traces.handles['done', g][k].vertices, dtype=float)
                            for g in groups]).reshape(-1, 8, 3)
        across = v[:, [1, 3]] - v[:, [0, 2]]                # (k, 2, 3): the two rectangles
        assert np.allclose(np.linalg.norm(across, axis=2), TRACE_WIDTH * scene.size, atol=1e-6)
        # at +-45 deg to the ground, across the segment's course on the ground (cosines:
        # float32 vertices near 0.3 m give 3e-8 m differences over a width of 2e-3 m)
        up = across @ traces.normal / (TRACE_WIDTH * scene.size)
        assert np.allclose(np.sort(up, axis=1), [-math.sqrt(0.5), math.sqrt(0.5)], atol=1e-4)
        course = (ends - starts) - np.outer((ends - starts) @ traces.normal, traces.normal)
        course /= np.linalg.norm(course, axis=1, keepdims=True)
        assert np.abs(np.einsum('kjc,kc->kj', across, course)).max() <= 1e-4 * TRACE_WIDTH \
            * scene.size
        last = ends[-1]
        if 'now' in traces.handles:                   # the current chunk's lines
            now = np.asarray(traces.handles['now'][k].points, dtype=float) - traces.lift
            assert np.abs(now[0, 0] - last).max() <= 1e-6
            assert np.abs(now[1:, 0] - now[:-1, 1]).max() <= 1e-6          # one chain
            last = now[-1, 1]
        assert np.abs(last - samples[-1]).max() <= 1e-6


def test_a_trace_keeps_its_length_and_drops_whole_groups(served):
    """A trace of 14 chunks of a helix, length 300 points: the finished chunks kept hold at
    least 300 points and fewer than 300 + TRACE_GROUP x TRACE_CHUNK (the oldest group goes
    once the others hold 300), the groups kept are the newest ones, each with its meshes,
    and a dropped group's meshes are removed from the scene."""
    from twodisk_ros.explore.scene3d import TRACE_CHUNK, TRACE_GROUP, Traces
    traces = Traces(served.scene, 1.0, 300)
    angle = 0.05 * np.arange(14 * TRACE_CHUNK)
    helix = np.stack([np.cos(angle), np.sin(angle), 0.01 * angle], axis=1)
    first = None
    for start in range(0, len(helix), 32):
        traces.extend(*(helix[start:start + 32],) * 3)
        traces.publish()
        if first is None and ('done', 0) in traces.handles:
            first = traces.handles['done', 0]
    kept = sum(node[1] for node in traces.nodes)
    assert 300 <= kept < 300 + TRACE_GROUP * TRACE_CHUNK
    groups = sorted({node[2] for node in traces.nodes})
    assert groups == list(range(groups[-1] - len(groups) + 1, groups[-1] + 1))
    assert sorted(part[1] for part in traces.handles if part != 'now') == groups
    assert groups[0] > 0 and first[0].name not in served.scene._handle_from_node_name
    traces.clear()


def test_a_replay_in_the_page_has_its_controls_disabled(recording, served):
    from twodisk_ros.explore.page import Explorer
    explorer = Explorer(served, RecordedMotion(recording))
    frame = explorer.step(0.5)
    assert len(frame) >= 2 and all(h.disabled for h in explorer.controls.values())
    assert 'replay of' in explorer.status.content
    while explorer.motion.restarts == 0:                # to the end, and again from 0
        frame = explorer.step(0.5)
    assert frame.t[0] == 0.0 and len(explorer.scene.traces.nodes) == 0
    assert explorer.change('a', 0.2).startswith('a is recorded in')


def test_help_has_no_side_effects(tmp_path):
    result = _explore('--help', cwd=tmp_path)
    assert result.returncode == 0 and '--export' in result.stdout and not result.stderr
    assert list(tmp_path.iterdir()) == []


class _Result:
    def __init__(self, code, stderr):
        self.returncode, self.stderr = code, stderr


def _main(*args, capsys):
    """twodisk-explore's main in this process (its signal handlers put back after)."""
    import signal
    from twodisk_ros.explore.cli import main
    handlers = {n: signal.getsignal(n) for n in (signal.SIGINT, signal.SIGTERM)}
    try:
        code = main([str(a) for a in args])
    finally:
        for number, handler in handlers.items():
            signal.signal(number, handler)
    return _Result(code, capsys.readouterr().err)


def _refused(result, pattern):
    assert result.returncode == 2, result
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('twodisk-explore: '), result.stderr
    assert re.search(pattern, lines[0]), lines[0]


def test_a_port_in_use_is_one_line_and_exit_2():
    taken = socket.socket()
    taken.bind(('127.0.0.1', 0))
    taken.listen()
    try:
        _refused(_explore('--port', taken.getsockname()[1]), r'port is in use')
    finally:
        taken.close()


def test_bad_input_is_one_line_and_exit_2(tmp_path, oloid, capsys, recording):
    def explore(*args):
        return _main(*args, capsys=capsys)
    _refused(explore(tmp_path / 'missing.mcap'), r'missing\.mcap')
    junk = tmp_path / 'junk.mcap'
    junk.write_bytes(b'\x89MCAP0\r\n' + os.urandom(200))
    _refused(explore(junk), r'junk\.mcap')
    damaged = tmp_path / 'damaged.mcap'
    damaged.write_bytes(Path(recording).read_bytes()[:3000])
    _refused(explore(damaged), r'damaged\.mcap')
    exists = tmp_path / 'lesson.html'
    exists.write_text('mine')
    _refused(explore('--export', exists), r'exists: pass --overwrite')
    assert exists.read_text() == 'mine'
    _refused(explore('-p', 'delta:=0.3'), re.escape(_reason(oloid, delta=0.3)))
    _refused(explore('-p', 'delta:=1'), r'delta is a double: write 1\.0, not 1')
    _refused(explore('-p', 'colour:=1.0'), r"no parameter 'colour'")
    _refused(explore('--host', '8.8.8.8'), r'not a loopback address')
    _refused(explore('--speed', '20'), r'--speed must be in \[0\.1, 10\]')
    _refused(explore('--params-file', CONFIG / 'oloid.yaml', tmp_path / 'x.mcap'),
             r'--params-file applies to simulated runs')


def _reason(settings, **values):
    with pytest.raises(ValueError) as error:
        settings.with_values(**values).checked()
    return ' '.join(str(error.value).split())


@pytest.fixture(scope='module')
def recording(tmp_path_factory):
    from batch_recording import record
    path = tmp_path_factory.mktemp('explore') / 'oloid.mcap'
    return record(path, CONFIG / 'oloid.yaml', duration=2.0, rate=50.0)


def test_a_replay_shows_the_recorded_poses(recording):
    """Every recorded pose is shown in order (rosbags reads the file independently)."""
    from rosbags.highlevel import AnyReader
    with AnyReader([Path(recording)]) as reader:
        connections = [c for c in reader.connections if c.topic.rsplit('/', 1)[-1] == 'pose']
        recorded = np.array([[m.pose.position.x, m.pose.position.y, m.pose.position.z]
                             for c, _, raw in reader.messages(connections=connections)
                             for m in [reader.deserialize(raw, c.msgtype)]])
    motion = RecordedMotion(recording)
    shown = []
    while not shown or motion.t < motion.duration:
        shown.append(motion.advance(0.1).position_g)
    shown = np.concatenate(shown)
    _, first = np.unique(shown, axis=0, return_index=True)
    assert np.array_equal(shown[np.sort(first)], recorded)
    assert motion.change('a', 0.2).startswith('a is recorded in')


def test_a_replay_has_the_phase_of_the_recorded_run(recording, oloid, served):
    """The replay's phase u (for the marker on the z_G plot), found from the recorded
    attitudes alone, is the phase of the node's own run of the same settings (its
    Simulation sampled at the recorded stamps) to the matching grid's step 2 pi / PHASE_GRID;
    the page's z_G plot marks the last frame's phase."""
    from twodisk_ros.explore.motion import PHASE_GRID
    from twodisk_ros.explore.page import Explorer
    motion = RecordedMotion(recording)
    frame = motion.advance(1.5)
    node = Simulation(motion.settings).sample(frame.t).phase
    error = np.angle(np.exp(1j * (frame.phase - np.asarray(node))))   # modulo 2 pi
    assert len(frame) >= 50 and np.max(np.abs(error)) <= 0.5 * 2 * math.pi / PHASE_GRID + 1e-9
    explorer = Explorer(served, RecordedMotion(recording))
    shown = explorer.step(0.5)
    now = explorer.cycle_plot.data[-1]
    (k,) = np.flatnonzero(np.isfinite(now))
    grid = explorer.cycle_plot.data[0]
    assert k == np.argmin(abs(grid - shown.phase[-1] % (2 * math.pi)))


def _lesson_moves(html):
    import json
    return json.loads(re.search(r'moves = (\{.*?\});', html).group(1))


@pytest.fixture(scope='module')
def lesson(tmp_path_factory):
    """2 s of config/oloid.yaml exported by the command: (result, path)."""
    out = tmp_path_factory.mktemp('lesson') / 'lesson.html'
    return _explore('--params-file', CONFIG / 'oloid.yaml', '--export', out, '--seconds', 2), out


def test_a_lesson_has_its_plots_and_their_markers_follow_the_run(lesson, oloid):
    """2 s of the oloid: the lesson's panel has the three plots; frame k's translation of the
    phase marker is, along u, the scale of the axis times the phase of the node's run at the
    frame's time (its Simulation sampled apart; to the 0.01 pt the moves are rounded to), and
    up the z_G axis that of the run's own z_G (flat ground: z_G(u) of the cycle, to 1 % of
    the curve's span); the time lines move with t, not up or down."""
    from twodisk_ros.explore.cli import EXPORT_FPS
    result, path = lesson
    assert result.returncode == 0, result.stderr
    html = path.read_text(encoding='utf-8')
    for title in ('id="lesson-plots"', 'z_G over the cycle', 'normal forces',
                  'friction needed and available'):
        assert title in html
    moves = _lesson_moves(html)
    t = np.arange(1, int(round(2 * EXPORT_FPS)) + 1) / EXPORT_FPS
    run = Simulation(oloid).sample(t)
    u = np.asarray(run.phase) % (2 * math.pi)
    z = np.asarray(run.position_g)[:, 2]
    phase = np.array(moves['lesson-phase'])
    assert phase.shape == (len(t), 2)
    k = np.argmax(abs(u - u[0]))
    scale = phase[k, 0] / (u[k] - u[0])
    assert scale > 0 and np.max(abs(phase[:, 0] - scale * (u - u[0]))) <= 0.01 + 1e-9
    span = z.max() - z.min()
    scale_z = -phase[np.argmax(abs(z - z[0])), 1] / (z[np.argmax(abs(z - z[0]))] - z[0])
    assert np.max(abs(-phase[:, 1] - scale_z * (z - z[0]))) <= 0.01 * scale_z * span + 0.01
    for key in ('lesson-time-1', 'lesson-time-2'):
        line = np.array(moves[key])
        step = line[-1, 0] / (t[-1] - t[0])
        assert np.all(line[:, 1] == 0) and np.max(abs(line[:, 0] - step * (t - t[0]))) <= 0.01


def test_export_is_one_offline_file_and_of_a_recording_too(tmp_path, recording, lesson):
    result, out = lesson
    assert result.returncode == 0, result.stderr
    html = out.read_text(encoding='utf-8')
    assert len(html) < 3e6
    # nothing is loaded from elsewhere: no script, link or image with a URL
    assert not re.search(r'''(src|href)\s*=\s*["']?(https?:)?//''', html)
    replay = tmp_path / 'replay.html'
    result = _explore(recording, '--export', replay)
    assert result.returncode == 0, result.stderr
    assert replay.stat().st_size > 0.5e6

"""Fault injection on the ``roller`` process: signals at random moments, a full disk, bad input.

Every recording left behind is checked with the inspector; no missing sample is tolerated.
Subprocess nodes use ROS domain 85, in-process nodes 86; discovery is localhost-only.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

import math  # noqa: E402
from pathlib import Path  # noqa: E402
import random  # noqa: E402
import resource  # noqa: E402
import signal  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

from hypothesis import given, HealthCheck, settings, strategies as st  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from twodisk_ros.inspector import inspect_recording  # noqa: E402
from twodisk_ros.recordings import read_recording  # noqa: E402

from roller_here import run_roller_main  # noqa: E402

pytestmark = pytest.mark.ros

REPO = Path(__file__).resolve().parents[1]
SAMPLED = ('/pose', '/contact_a', '/contact_b', '/rolling_state')


def node_env():
    return dict(os.environ, PYTHONPATH=str(REPO), ROS_DOMAIN_ID='85',
                ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')


def roller(*params, **kwargs):
    return subprocess.Popen(
        [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
         'config/oloid.yaml', *params], cwd=REPO, env=node_env(), stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True, **kwargs)


def finish(process, timeout=30.0):
    try:
        out, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        process.kill()
        out, err = process.communicate()
        pytest.fail(f'the node hung: {err[-2000:]}')
    return process.returncode, out, err


#: Samples the checks need to evaluate every central difference: the 5-point stencils leave
#: n - 4 rows, and energy_balance needs 3 of them (inspect/resolution.py).
EVALUATED_FROM = 7


def assert_complete(path, detail):
    """A finished, indexed recording, every topic on the same sample, that passes every check.
    A signal soon after the first sample leaves fewer samples than the finite differences
    need: then the FD checks (and only they) say they were not evaluated, and why."""
    recording = read_recording(path, decode=lambda topic: False)
    assert not recording.truncated, detail
    counts = {t: recording.topics[t].message_count for t in SAMPLED}
    assert len(set(counts.values())) == 1 and min(counts.values()) >= 1, (detail, counts)
    inspection = inspect_recording(path)
    failed = [f'{c.name}: {c.detail}' for c in inspection.checks if not c.passed]
    if min(counts.values()) >= EVALUATED_FROM:
        assert inspection.passed, (detail, failed)
    else:
        assert all(not c.passed and c.value is None and (
            'central differences' in c.detail[0]) for c in inspection.checks
            if not c.passed), (detail, counts, failed)


# -- signals ---------------------------------------------------------------------------------

PATTERNS = ('SIGINT', 'SIGTERM', 'SIGINT+SIGTERM')
#: Mid-run (seed 1) every pattern in both modes: the run is where the modes differ (the
#: batch loop, the executor). At start-up (seed 0) every pattern once, the modes taking
#: turns: the start-up is the same code in both (imports, tables, the node; the mode is
#: read when the run begins). (A seed 2 drew a second mid-run moment of the same window: in
#: batch the signal lands while the node computes and writes its first 2000-sample block
#: whatever the moment, so both recordings held the same 2000 samples.)
SIGNAL_CASES = ([(mode, pattern, 1) for mode in ('realtime', 'batch') for pattern in PATTERNS]
                + [(mode, pattern, 0) for mode, pattern in zip(
                    ('realtime', 'batch', 'realtime'), PATTERNS)])


def _until_recording(process, target, timeout=30.0):
    """Return once ``target`` exists (the recorder gives the file its name with its first
    message on disk: the run is recording) or the process has ended."""
    deadline = time.monotonic() + timeout
    while not target.exists() and process.poll() is None:
        assert time.monotonic() < deadline, 'the node never started recording'
        time.sleep(0.002)


def _until_handled(process, timeout=30.0):
    """Return once the process catches SIGTERM (/proc/PID/status SigCgt): the entry point's
    handlers are in, so a signal is the node's to handle. Before that the interpreter is
    still starting (a SIGINT there interrupts Python's own site import, not our code)."""
    deadline = time.monotonic() + timeout
    while process.poll() is None:
        with open(f'/proc/{process.pid}/status', encoding='ascii') as status:
            caught = next(int(line.split()[1], 16) for line in status
                          if line.startswith('SigCgt:'))
        if caught & (1 << (signal.SIGTERM - 1)):
            return
        assert time.monotonic() < deadline, 'the node never installed its signal handlers'
        time.sleep(0.002)


@pytest.mark.parametrize('mode, pattern, seed', SIGNAL_CASES,
                         ids=[f'{m}-{p}-{s}' for m, p, s in SIGNAL_CASES])
def test_signal_at_a_random_moment_leaves_a_complete_recording(tmp_path, mode, pattern, seed):
    """Start-up, mid-chunk, during close: exit 0, no traceback, a recording that passes.

    Seed 0 a moment in the first second after the entry point's signal handlers are in
    (start-up, or for a fast start the first samples); seed 1 a moment after the recording got its name (mid-run): in
    real time (200 Hz, running until stopped) within 0.5 s of it, in batch (15 s at 1 kHz,
    about a second of work) within 0.2 s of it, in a chunk, so the batch is signalled while
    it runs instead of mostly after its end. Waiting for the file instead of sleeping a
    random 0-3 s covers start-up and the run in both modes without idle seconds."""
    rng = random.Random(f'{mode}{pattern}{seed}')
    target = tmp_path / 'run.mcap'
    params = (['-p', 'rate:=200.0'] if mode == 'realtime'
              else ['-p', 'realtime:=false', '-p', 'rate:=1000.0', '-p', 'duration:=15.0'])
    process = roller(*params, '-p', f'record:={target}')
    if seed > 0:
        _until_recording(process, target)
        delay = rng.uniform(0.0, 0.5 if mode == 'realtime' else 0.2)
    else:
        _until_handled(process)
        delay = rng.uniform(0.0, 1.0)
    time.sleep(delay)
    try:
        for name in pattern.split('+'):
            process.send_signal(getattr(signal, name))
            time.sleep(0.001)
    except ProcessLookupError:
        pass                                  # a batch run may have ended already
    code, _, err = finish(process)
    detail = f'{mode} {pattern} after {delay:.3f} s: {err[-1500:]}'
    assert code == 0, detail
    assert 'Traceback' not in err, detail
    if not target.exists():                   # stopped during start-up: nothing recorded
        assert 'no recording written' in err, detail
        return
    assert_complete(target, detail)


HAMMER = [(signal.SIGTERM, 0.3), (signal.SIGTERM, 1.2), (signal.SIGTERM, 1.6),
          (signal.SIGTERM, 2.0), (signal.SIGINT, 1.4), (signal.SIGINT, 1.8)]


@pytest.mark.parametrize('sig, delay', HAMMER, ids=[f'{s.name}-{d}s' for s, d in HAMMER])
def test_a_signal_every_few_milliseconds_until_the_process_ends(tmp_path, sig, delay):
    """From ``delay`` on, a signal every 5 ms: start-up, run, close and shutdown alike."""
    target = tmp_path / 'hammered.mcap'
    process = roller('-p', 'realtime:=false', '-p', 'rate:=1000.0', '-p', 'duration:=3.0',
                     '-p', f'record:={target}')
    time.sleep(delay)
    while process.poll() is None:
        try:
            process.send_signal(sig)
        except ProcessLookupError:
            break
        time.sleep(0.005)
    code, _, err = finish(process)
    assert code == 0 and 'Traceback' not in err, err
    if target.exists():
        assert_complete(target, err)
    else:
        assert 'no recording written' in err, err


def test_existing_record_file_is_refused_unless_overwrite(tmp_path, monkeypatch, capfd):
    """The refusal as a real process; the run that overwrites through the entry function in
    this process."""
    target = tmp_path / 'kept.mcap'
    target.write_bytes(b'precious')
    code, _, err = finish(roller('-p', f'record:={target}', '-p', 'realtime:=false',
                                 '-p', 'duration:=0.1'))
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert 'exists' in err and 'overwrite:=true' in err
    assert target.read_bytes() == b'precious'
    code, err = run_roller_main(('--params-file', 'config/oloid.yaml', '-p', f'record:={target}',
                                 '-p', 'realtime:=false', '-p', 'duration:=0.1',
                                 '-p', 'overwrite:=true'), monkeypatch, capfd, domain=86,
                                cwd=REPO)
    assert code == 0, err
    assert_complete(target, err)


# -- a full disk -----------------------------------------------------------------------------

def _file_size_limit(limit):
    def apply():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


def test_disk_full_is_one_line_and_keeps_what_was_written(tmp_path):
    """Writing past a file-size limit (EFBIG, as ENOSPC): exit 3, one line, data readable."""
    target = tmp_path / 'full.mcap'
    process = roller('-p', 'realtime:=false', '-p', 'rate:=1000.0', '-p', 'duration:=30.0',
                     '-p', f'record:={target}', preexec_fn=_file_size_limit(600_000))
    code, _, err = finish(process, timeout=60.0)
    lines = [line for line in err.strip().splitlines() if not line.startswith('[INFO] ')]
    assert code == 3, err
    # one error line; the only other line is the node's start line (INFO, rclpy's logger)
    assert len(lines) == 1 and str(target) in lines[0] and 'Traceback' not in err, err
    assert len(err.strip().splitlines()) == 2 and 'recording to' in err, err
    recording = read_recording(target, decode=lambda topic: topic == '/pose')
    assert recording.truncated and len(recording.messages) > 1000
    stamps = [m.log_time_ns for m in recording.messages if m.topic == '/pose']
    assert np.all(np.diff(stamps) == 1_000_000)   # what was kept is contiguous
    inspection = inspect_recording(target)        # a partial report, no exception
    assert inspection.summary['truncated']


# -- bad input at start-up -------------------------------------------------------------------

BAD_START_VALUES = [
    ('a:=', 'no value'),
    ('frame_id:=', 'no value'),
    ('omega0:=1e300', 'omega0'),
    ('omega0:=.nan', 'omega0'),
    ('delta:=1e-17', 'delta'),
    ('delta:=0.0999999999', 'delta/a'),
    ('b:=0.0001', 'b'),
    ('rate:=50', 'decimal point'),
    ('theta0:=3.0', 'theta_max'),
    ('mass_model:=granite', 'mass_model'),
    ('gravity:=-1.0', 'gravity'),
    ('tolerance:=0.0', 'tolerance'),
    ('frame_id:=has space', 'frame_id'),
]
#: Run as real processes: one refused by the argument check (before rclpy), one by the node
#: (after rclpy.init); the others run the same entry function in this process (domain 86).
IN_A_PROCESS = ('rate:=50', 'theta0:=3.0')


@pytest.mark.parametrize('argument, words', BAD_START_VALUES)
def test_bad_start_values_exit_2_with_one_line(argument, words, monkeypatch, capfd):
    params = ('-p', argument, '-p', 'realtime:=false', '-p', 'duration:=0.1')
    if argument in IN_A_PROCESS:
        code, _, err = finish(roller(*params), timeout=60.0)
    else:
        code, err = run_roller_main(('--params-file', 'config/oloid.yaml', *params),
                                    monkeypatch, capfd, domain=86, cwd=REPO)
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith('roller: ') and words in lines[0], err


def test_unreadable_params_file_and_unknown_names(tmp_path, monkeypatch, capfd):
    """The broken file as a real process; the missing one and the run with unknown names
    through the entry function in this process."""
    broken = tmp_path / 'broken.yaml'
    broken.write_text('/**:\n  ros__parameters: [unclosed\n')
    for path in (broken, tmp_path / 'missing.yaml'):
        if path is broken:
            process = subprocess.Popen(
                [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
                 str(path)], cwd=REPO, env=node_env(), stdout=subprocess.PIPE,
                stderr=subprocess.PIPE, text=True)
            code, _, err = finish(process)
        else:
            code, err = run_roller_main(('--params-file', path), monkeypatch, capfd,
                                        domain=86, cwd=REPO)
        assert code == 2 and len(err.strip().splitlines()) == 1 and str(path) in err, err
    code, err = run_roller_main(('--params-file', 'config/oloid.yaml', '-p', 'no_such_param:=1.0',
                                 '-p', 'omgea0:=2.0', '-p', 'realtime:=false',
                                 '-p', 'duration:=0.1'), monkeypatch, capfd, domain=86,
                                cwd=REPO)
    assert code == 0, err
    assert "unknown parameter 'no_such_param'" in err
    assert "unknown parameter 'omgea0' is ignored; did you mean 'omega0'?" in err


# -- property tests of the parameter values, in process --------------------------------------

BAD_FLOATS = st.sampled_from([math.inf, -math.inf, math.nan, 1e300, -1e300, 1e-300, 5e-324,
                              -5e-324, 0.0, -0.0])
ANY_FLOAT = st.one_of(BAD_FLOATS, st.floats(allow_nan=True, allow_infinity=True))
NUMERIC = ['a', 'b', 'delta', 'mass', 'gravity', 'theta0', 'omega0', 'tolerance']


@pytest.fixture(scope='module')
def ros_context():
    import rclpy
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=86)
    yield ctx
    rclpy.try_shutdown(context=ctx)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(name=st.sampled_from(NUMERIC), value=ANY_FLOAT)
def test_start_up_values_succeed_or_give_one_line(ros_context, name, value):
    """Any float for any numeric parameter: a valid run, or a one-line error. Never a hang."""
    from rclpy.parameter import Parameter
    from twodisk_ros.node.roller import Roller
    try:
        node = Roller(context=ros_context, parameter_overrides=[
            Parameter(name, value=value), Parameter('realtime', value=False),
            Parameter('duration', value=0.05)])
    except Exception as error:  # noqa: BLE001 - the node's and rclpy's one-line errors
        text = str(error)
        assert text and '\n' not in text.strip() and name in text, (name, value, text)
        assert 'Traceback' not in text
        return
    try:
        node.run_batch()
        assert node.samples_published == 6   # bounded work: 0.05 s at 100 Hz, then it ends
    finally:
        node.close()
        node.destroy_node()


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                  HealthCheck.function_scoped_fixture])
@given(name=st.sampled_from(NUMERIC + ['branch', 'mode', 'method', 'path_length']),
       value=st.one_of(ANY_FLOAT, st.integers(-10**9, 10**9), st.text(max_size=5),
                       st.booleans()))
def test_run_time_values_are_accepted_or_rejected_and_the_motion_goes_on(ros_context, name,
                                                                        value, monkeypatch):
    """The change comes between two batch blocks, made 20 samples here (node default 2000:
    the claim is a change between blocks, not the blocks' size; 2000 made every example
    compute 2000 samples before it)."""
    from rclpy.parameter import Parameter
    from twodisk_ros.node import roller as roller_module
    from twodisk_ros.node.roller import Roller
    monkeypatch.setattr(roller_module, 'BATCH_SAMPLES', 20)
    node = Roller(context=ros_context, parameter_overrides=[
        Parameter('realtime', value=False), Parameter('rate', value=1000.0),
        Parameter('duration', value=0.05)])
    try:
        # one block of 20 of the 51 samples; the change comes before the last 31
        node.run_batch(keep_going=lambda: node.samples_published < 5)
        assert 0 < node.samples_published < 51
        try:
            (result,) = node.set_parameters([Parameter(name, value=value)])
            accepted, reason = result.successful, result.reason
        except Exception as error:  # noqa: BLE001 - rclpy refuses a wrong type itself
            accepted, reason = False, str(error)
        assert accepted or reason.strip(), (name, value)
        before = node.samples_published
        node.run_batch()
        assert node.finished and node.samples_published > before
    finally:
        node.close()
        node.destroy_node()


def test_direct_method_in_real_time_runs_past_its_integration_chunks(ros_context):
    """method:=direct integrates in 10 s chunks; one sample per tick crosses them."""
    from rclpy.parameter import Parameter
    from twodisk_ros.node.roller import Roller
    node = Roller(context=ros_context, parameter_overrides=[
        Parameter('method', value='direct'), Parameter('rate', value=2.0),
        Parameter('tolerance', value=1e-6), Parameter('omega0', value=1.0),
        Parameter('realtime', value=False), Parameter('duration', value=10.5)])
    try:
        node.run_batch()
        assert node.samples_published == 22
    finally:
        node.close()
        node.destroy_node()
    from twodisk_ros.physics import MotionStream, RollingDynamics, EllipseBody
    from twodisk_ros.physics.mass.models import laminae
    dynamics = RollingDynamics(EllipseBody(0.1, 0.1, 0.05), laminae(0.1, 0.1, 0.05, 1.0))
    stream = MotionStream(dynamics, 0.3, 2.0, method='direct', chunk=0.5, tolerance=1e-8)
    reference = MotionStream(dynamics, 0.3, 2.0, method='direct', chunk=100.0, tolerance=1e-8)
    times = np.arange(0.0, 1.6, 0.05)
    one_by_one = np.array([stream.sample(np.array([t])) for t in times])[:, :, 0]
    u, u_dot = reference.sample(times)
    np.testing.assert_allclose(one_by_one[:, 0], u, rtol=0, atol=1e-6)
    np.testing.assert_allclose(one_by_one[:, 1], u_dot, rtol=0, atol=1e-5 * abs(u_dot).max())


def test_published_orientation_is_continuous_across_blocks(tmp_path, monkeypatch, capfd):
    """Batch blocks (node/roller.py BATCH_SAMPLES, 2000 samples) made 100 here: 10 s at
    100 Hz crosses ten block boundaries, at ten phases (was 40 s and two at the node's
    size). The node through its entry function in this process."""
    from twodisk_ros.node import roller as roller_module
    monkeypatch.setattr(roller_module, 'BATCH_SAMPLES', 100)
    target = tmp_path / 'q.mcap'
    code, err = run_roller_main(('--params-file', 'config/oloid.yaml', '-p', 'realtime:=false',
                                 '-p', 'rate:=100.0', '-p', 'duration:=10.0',
                                 '-p', 'omega0:=8.0', '-p', f'record:={target}'),
                                monkeypatch, capfd, domain=86, cwd=REPO)
    assert code == 0, err
    recording = read_recording(target, decode=lambda topic: topic == '/pose')
    q = np.array([[m.msg.pose.orientation.x, m.msg.pose.orientation.y,
                   m.msg.pose.orientation.z, m.msg.pose.orientation.w]
                  for m in recording.messages if m.topic == '/pose'])
    assert len(q) == 1001
    assert np.all(np.einsum('ij,ij->i', q[1:], q[:-1]) >= 0)

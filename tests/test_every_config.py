"""Every shipped body, end to end: each config/*.yaml runs in batch, records, and
``twodisk-inspect`` finds the recording consistent; recordings of non-elliptic bodies animate
(GIF and PNG) and replay in ``twodisk-view``, drawn with the outline that touches the ground.

What is asserted of the inspector's checks: every consistency check passes (the recording
against the body and the mass model its metadata describe, rebuilt through the run
description). ``rolling_validity`` is the model's verdict on the motion (lift-off, or
μ_required above the friction), not a consistency check: a superellipse's contact forces
spike where a contact crosses a flat vertex (the contact point runs along the rim infinitely
fast per unit of turn), physics, not an error. For it the test asserts that the inspector,
from the recorded wrenches, reaches the verdict the node reached while it ran
(:func:`~twodisk_ros.physics.forces.validity.check_validity` in the node, which logs "outside
the rolling model"): two readers of the same forces agree.

Nodes run in ROS domain 60 (discovery localhost-only): the oloid's run as a subprocess, the
others through the entry function in this process; the view runs with rclpy unimportable
(view_process.py).
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

import contextlib  # noqa: E402
import io  # noqa: E402
from pathlib import Path  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from PIL import Image  # noqa: E402

from roller_here import record_with_roller_main, run_roller_main  # noqa: E402

pytestmark = pytest.mark.ros

REPO = Path(__file__).resolve().parents[1]
DOMAIN = 60
TIMEOUT = 300      # s: a short batch run takes ~3 s alone; bound for a loaded 2-core machine
CONFIGS = sorted(p.stem for p in (REPO / 'config').glob('*.yaml'))


def _env():
    return dict(os.environ, PYTHONPATH=str(REPO), ROS_DOMAIN_ID=str(DOMAIN),
                ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1',
                MPLBACKEND='Agg')


def _record(directory, name, *params):
    out = Path(directory) / f'{name}.mcap'
    made = subprocess.run(
        [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', *params,
         '-p', 'realtime:=false', '-p', f'record:={out}'],
        cwd=directory, env=_env(), capture_output=True, text=True, timeout=TIMEOUT,
        stdin=subprocess.DEVNULL)
    return out, made


def _record_here(directory, name, *params):
    """As :func:`_record`, through the entry function in this process
    (tests/roller_here.py): what the node writes to stderr (rclpy's log lines, at the file
    descriptor, and Python's) is read from a file that stands in for fd 2 meanwhile."""
    out = Path(directory) / f'{name}.mcap'
    with tempfile.TemporaryFile() as log, io.StringIO() as said:
        sys.stderr.flush()
        saved = os.dup(2)
        os.dup2(log.fileno(), 2)
        try:
            with contextlib.redirect_stderr(said):
                code = record_with_roller_main(
                    (*params, '-p', 'realtime:=false', '-p', f'record:={out}'), DOMAIN,
                    cwd=directory)
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        log.seek(0)
        err = log.read().decode(errors='replace') + said.getvalue()
    return out, subprocess.CompletedProcess([], code, '', err)


@pytest.fixture(scope='module')
def recordings(tmp_path_factory):
    """path of a recording made once per module (node runs are the slow part), through the
    entry function in this process; with ``run=True`` (path, the finished run: exit code
    and the node's log)."""
    directory = tmp_path_factory.mktemp('recordings')
    made = {}

    def get(name, *params, run=False):
        if name not in made:
            out, process = _record_here(directory, name, *params)
            assert process.returncode == 0, process.stderr
            made[name] = out, process
        return made[name] if run else made[name][0]
    return get


EGG_SOLID = ('--params-file', str(REPO / 'config' / 'egg.yaml'), '-p', 'mass_model:=solid',
             '-p', 'duration:=1.0')
SQUARE = ('--params-file', str(REPO / 'config' / 'rounded_square.yaml'), '-p',
          'duration:=1.0')
#: Configs whose run here is the 1 s module recording the drawing tests use, not its own.
SHARED = {'rounded_square': SQUARE}


#: The config whose run is a real process (the cheapest: a 0.3 s run of the oloid); the
#: others run the same entry function in this process (tests/roller_here.py), without an
#: interpreter start each.
AS_A_PROCESS = 'oloid'


@pytest.mark.parametrize('config', CONFIGS)
def test_every_config_records_a_consistent_run(tmp_path, config, recordings, monkeypatch,
                                               capfd):
    from twodisk_ros.inspector import inspect_recording
    params = ('--params-file', str(REPO / 'config' / f'{config}.yaml'), '-p', 'duration:=0.3')
    if config in SHARED:
        out, made = recordings(config, *SHARED[config], run=True)
    elif config == AS_A_PROCESS:
        out, made = _record(tmp_path, config, *params)
    else:
        out = tmp_path / f'{config}.mcap'
        code, err = run_roller_main((*params, '-p', 'realtime:=false', '-p', f'record:={out}'),
                                    monkeypatch, capfd, domain=DOMAIN, cwd=tmp_path)
        made = subprocess.CompletedProcess([], code, '', err)
    assert made.returncode == 0, made.stderr
    checks = {check.name: check for check in inspect_recording(out).checks}
    failed = {name: check.detail for name, check in checks.items()
              if not check.passed and name != 'rolling_validity'}
    assert not failed, failed
    said = made.stdout + made.stderr
    assert 'published ' in said, said          # the node's log is read (its end line)
    node_says_invalid = 'outside the rolling model' in said
    assert checks['rolling_validity'].passed is not node_says_invalid, \
        (checks['rolling_validity'].detail, made.stderr[-400:])


@pytest.mark.parametrize('name, params', [('rounded_square', SQUARE), ('egg_solid', EGG_SOLID)])
def test_recorded_shapes_are_drawn_touching_the_ground(recordings, name, params):
    """At every recorded sample both drawn rims reach the ground and none goes below it, to
    the rims' polygon error: the recorded pose (of the body's origin: the solid egg's centre
    of mass, 2.7e-3 m off its laminae's centroid) places the laminae where they roll."""
    from twodisk_ros.physics.bodies.outline import DEFAULT_TOLERANCE
    from twodisk_ros.runs import recorded_run
    run = recorded_run(recordings(name, *params))
    assert run.settings.shape == ('superellipse' if name == 'rounded_square' else 'egg')
    error = DEFAULT_TOLERANCE * run.body.lamina.size
    for index in range(0, len(run), 5):
        for rim in run.outlines(index):
            assert -error <= rim[:, 2].min() <= error, (index, rim[:, 2].min())


@pytest.mark.parametrize('name, params', [('rounded_square', SQUARE), ('egg_solid', EGG_SOLID)])
def test_recorded_shapes_animate_to_gif_and_png(recordings, tmp_path, name, params):
    from twodisk_ros.plotting.animate_cli import main
    path = recordings(name, *params)
    assert main([str(path), '-o', str(tmp_path / 'run.gif'), '--fps', '5',
                 '--size', '320x240']) == 0
    assert main([str(path), '-o', str(tmp_path / 'run.png'), '--size', '320x240']) == 0
    with Image.open(tmp_path / 'run.gif') as gif:
        assert gif.n_frames == 6                      # 1 s at 5 frames per second, both ends
    with Image.open(tmp_path / 'run.png') as png:
        pixels = np.asarray(png.convert('RGB'), dtype=int)
    assert pixels.shape == (240, 320, 3)
    # the laminae are drawn: many pixels of disk 1's blue and disk 2's orange (palette)
    blue = (pixels[..., 2] > pixels[..., 0] + 40).sum()
    orange = (pixels[..., 0] > pixels[..., 2] + 40).sum()
    assert blue > 200 and orange > 200, (blue, orange)


def test_a_parameter_file_of_another_shape_animates(tmp_path):
    from twodisk_ros.plotting.animate_cli import main
    assert main(['-o', str(tmp_path / 'square.png'), '--params-file',
                 str(REPO / 'config' / 'rounded_square.yaml'), '--stop', '1',
                 '--size', '320x240']) == 0
    assert main(['-o', str(tmp_path / 'egg.gif'), '--shape', 'egg', '--egg-asymmetry', '0.5',
                 '--b', '0.08', '--delta', '0.04', '--mass-model', 'solid', '--stop', '0.4', '--fps', '5', '--size', '320x240']) == 0
    with Image.open(tmp_path / 'egg.gif') as gif:
        assert gif.n_frames == 3


def test_an_egg_recording_plays_in_the_view(recordings):
    """The view replays the solid egg's recording to its end, serving the body and every
    recorded pose (the recording's own stamps)."""
    from foxglove_client import collect
    from view_process import View
    path = recordings('egg_solid', *EGG_SOLID)
    view = View(path, '--port', 0, '--speed', 4.0)
    try:
        port = view.wait_serving()
        received = collect(port, ('/tf', '/body', '/parameters'),
                           lambda got: got.count('/body') and got.count('/parameters'))
        view.wait_line('the run ended after')
        status, stderr = view.stop()
    finally:
        view.kill()
    assert status == 0, stderr
    assert received.count('/body') >= 1
    assert 'egg' in str(received.messages['/parameters'][0][1])
    assert 'the run ended after 101 samples' in ''.join(view.stdout)

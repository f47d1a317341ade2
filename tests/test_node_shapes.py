"""The node with the shape parameters: bad input at start-up and at run time, and recorded runs
of non-elliptic bodies checked by ``twodisk-inspect`` (issue 20).

The end-to-end runs build :class:`~twodisk_ros.physics.bodies.lamina_body.LaminaBody` in the
node and fail if it cannot be built (nothing is skipped). Subprocess nodes use ROS domain 62,
in-process ones 63; discovery is localhost-only.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

import subprocess  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from twodisk_ros.physics.laminae.shapes import Superellipse  # noqa: E402
from twodisk_ros.physics.laminae.support import Egg  # noqa: E402

from roller_here import run_roller_main  # noqa: E402

pytestmark = pytest.mark.ros

REPO = Path(__file__).resolve().parents[1]
SUBPROCESS_DOMAIN = 62
IN_PROCESS_DOMAIN = 63
TIMEOUT = 120      # s: a short batch run starts and ends in a few seconds on a loaded machine


def env():
    return dict(os.environ, PYTHONPATH=str(REPO), ROS_DOMAIN_ID=str(SUBPROCESS_DOMAIN),
                ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', PYTHONUNBUFFERED='1')


def roller(*params, cwd):
    return subprocess.run([sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', *params],
                          cwd=cwd, env=env(), capture_output=True, text=True, timeout=TIMEOUT,
                          stdin=subprocess.DEVNULL)


def inspect(path, cwd):
    return subprocess.run([sys.executable, '-m', 'twodisk_ros.inspect_mcap', str(path)],
                          cwd=cwd, env=env(), capture_output=True, text=True, timeout=TIMEOUT,
                          stdin=subprocess.DEVNULL)


def egg_points(count=120):
    egg = Egg(0.1, 0.07, 0.4 * Egg.epsilon_max(0.1, 0.07))
    return egg.point(np.linspace(-np.pi, np.pi, count, endpoint=False))


# -- bad input at start-up: one line, exit 2, before any body is built ----------------------

@pytest.mark.parametrize('params, says', [
    (['-p', 'shape:=points'], 'shape_file must name a CSV or YAML outline file'),
    (['-p', 'shape:=points', '-p', 'shape_file:=/dev/zero'], 'shape_file /dev/zero: not a '
                                                            'regular file'),
    (['-p', 'shape:=points', '-p', 'shape_file:=missing.csv'], 'shape_file missing.csv: '
                                                               'cannot be read'),
    (['-p', 'shape:=hexagon'], 'shape'),
    (['-p', 'shape:=superellipse', '-p', 'exponent:=1.0'], 'exponent'),
    (['-p', 'shape:=egg', '-p', 'egg_asymmetry:=1.5'], 'egg_asymmetry'),
    (['-p', 'arrangement:=crossed'], 'arrangement'),
    (['-p', 'shape:=superellipse', '-p', 'exponent:=6'], 'exponent is a double: write 6.0'),
])
def test_bad_shape_values_at_start_up_exit_2_in_one_line(tmp_path, params, says, monkeypatch,
                                                       capfd):
    args = ('-p', 'realtime:=false', '-p', 'duration:=0.1', *params)
    if params[-1] in IN_A_PROCESS:
        result = roller(*args, cwd=tmp_path)
        code, err = result.returncode, result.stderr
    else:
        code, err = run_roller_main(args, monkeypatch, capfd, domain=IN_PROCESS_DOMAIN,
                                    cwd=tmp_path)
    lines = err.splitlines()
    assert code == 2, err
    assert len(lines) == 1 and 'Traceback' not in lines[0], err
    assert says in lines[0], lines[0]


#: Cases run as real processes: one refused by the argument check (before rclpy), one by the
#: node (after rclpy.init); the others call the same entry function in this process.
IN_A_PROCESS = ('exponent:=6', 'shape_file:=/dev/zero')


def test_a_shape_file_that_cannot_be_fitted_names_the_file(tmp_path):
    points = egg_points()
    points[30] *= 0.7                                     # a dent
    np.savetxt(tmp_path / 'dented.csv', points, delimiter=',')
    result = roller('-p', 'realtime:=false', '-p', 'duration:=0.1', '-p', 'shape:=points',
                    '-p', 'shape_file:=dented.csv', cwd=tmp_path)
    lines = result.stderr.splitlines()
    assert result.returncode == 2 and len(lines) == 1, result.stderr
    assert 'shape_file dented.csv: ' in lines[0] and 'convex' in lines[0], lines[0]


# -- bad input at run time: refused, the motion goes on ---------------------------------------

def test_a_bad_shape_at_run_time_is_refused_in_one_line(tmp_path):
    rclpy = pytest.importorskip('rclpy')
    from rclpy.parameter import Parameter
    from twodisk_ros.node.roller import Roller
    ctx = rclpy.Context()
    rclpy.init(context=ctx, domain_id=IN_PROCESS_DOMAIN)
    node = Roller(context=ctx, parameter_overrides=[Parameter('realtime', value=False),
                                                    Parameter('duration', value=0.1)])
    try:
        simulation = node.simulation
        for changes, says in (
                ([Parameter('shape', value='points')], 'shape_file must name'),
                ([Parameter('shape', value='points'),
                  Parameter('shape_file', value=str(tmp_path))], 'is a directory'),
                ([Parameter('shape', value='egg'), Parameter('delta', value=0.1)], 'delta')):
            result = node.set_parameters_atomically(changes)
            assert result.successful is False, changes
            assert says in result.reason and '\n' not in result.reason, result.reason
            assert node.get_parameter('shape').value == 'ellipse'
        assert node.simulation is simulation and not node.pending_changes
    finally:
        node.close()
        node.destroy_node()
        rclpy.try_shutdown(context=ctx)


# -- recorded runs of other shapes, checked offline (need LaminaBody) ------------------------

def checks_of(path):
    """{name: Check} of ``twodisk-inspect``'s checks of a recording (in process)."""
    from twodisk_ros.inspector import inspect_recording
    return {check.name: check for check in inspect_recording(path).checks}


def assert_consistent(checks, shape_words):
    """Every check of the recording's consistency passes (the model's own verdict on the
    motion, rolling_validity: lift-off or slip, may go either way), and the report names the
    shape."""
    failed = {name: check.detail for name, check in checks.items()
              if not check.passed and name != 'rolling_validity'}
    assert not failed, failed
    assert shape_words in ' '.join(checks['inputs'].detail), checks['inputs'].detail


@pytest.mark.parametrize('params, words', [
    (['-p', 'shape:=superellipse', '-p', 'exponent:=4.0', '-p', 'b:=0.08', '-p',
      'delta:=0.04'], 'body superellipse a = 0.1 m, b = 0.08 m, exponent 4'),
    (['-p', 'shape:=superellipse', '-p', 'exponent:=6.0', '-p', 'mass_model:=custom', '-p',
      'principal_moments:=[0.003, 0.004, 0.003]', '-p', 'friction:=.inf'],
     'body superellipse'),
    (['-p', 'shape:=egg', '-p', 'egg_asymmetry:=0.6', '-p', 'delta:=0.04', '-p',
      'mass_model:=solid'], 'body egg a = 0.1 m, b = 0.1 m, epsilon = 0.0075 m'),
    (['-p', 'shape:=egg', '-p', 'arrangement:=swapped', '-p', 'delta:=0.03', '-p',
      'mode:=kinematic'], 'delta = 0.03 m, swapped'),
], ids=['superellipse', 'superellipse-custom', 'egg-solid', 'egg-swapped-kinematic'])
def test_a_recorded_run_of_another_shape_is_consistent(tmp_path, params, words, monkeypatch,
                                                       capfd):
    """The first body's node and inspector run as real processes; the other bodies' through
    the same entry functions in this process (no interpreter start each)."""
    first = params[1] == 'shape:=superellipse' and params[3] == 'exponent:=4.0'
    args = ('-p', 'realtime:=false', '-p', 'duration:=0.3', '-p', 'record:=run.mcap', *params)
    if first:
        made = roller(*args, cwd=tmp_path)
        code, err = made.returncode, made.stderr
    else:
        code, err = run_roller_main(args, monkeypatch, capfd, domain=IN_PROCESS_DOMAIN,
                                    cwd=tmp_path)
    assert code == 0, err
    assert_consistent(checks_of(tmp_path / 'run.mcap'), words)
    # the command line, too
    if first:
        checked = inspect(tmp_path / 'run.mcap', tmp_path)
        code, out, err = checked.returncode, checked.stdout, checked.stderr
    else:
        from twodisk_ros.inspector.cli import main
        capfd.readouterr()
        code = main([str(tmp_path / 'run.mcap')])
        out, err = capfd.readouterr()
    assert code in (0, 1) and 'result: ' in out, err


def test_a_points_run_is_checked_without_its_shape_file(tmp_path, monkeypatch, capfd):
    """The node through its entry function in this process (the shape file relative to it)."""
    np.savetxt(tmp_path / 'egg.csv', egg_points(), delimiter=',', header='x,y', comments='')
    code, err = run_roller_main(
        ('-p', 'realtime:=false', '-p', 'duration:=0.3', '-p', 'record:=run.mcap',
         '-p', 'shape:=points', '-p', 'shape_file:=egg.csv', '-p', 'delta:=0.04',
         '-p', 'method:=direct'), monkeypatch, capfd, domain=IN_PROCESS_DOMAIN, cwd=tmp_path)
    assert code == 0, err
    (tmp_path / 'egg.csv').unlink()
    assert_consistent(checks_of(tmp_path / 'run.mcap'), 'body outline of')

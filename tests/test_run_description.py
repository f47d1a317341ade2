"""The shape parameters and the run description (issue 20, "The node, the files and the tools").

References are independent of the code under test: the ellipse's closed forms (EllipseBody's
θ_max, the superellipse at n = 2 is the ellipse), the egg's closed forms (ε_max = r/8 for a
circle, its ends at −(a + ε) and a − ε), points sampled from a known ellipse, and the energy
integral of a free motion (tests/energy_integral.py).
"""

import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings as hsettings, strategies as st

from twodisk_ros.node import arguments
from twodisk_ros.run.params_yaml import params_file_values
from twodisk_ros.run.parameters import BY_NAME, DEFAULTS, PARAMETERS, parse_recorded
from twodisk_ros.run.simulation import Simulation
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.run import shape as shapes
from twodisk_ros.run.description import RunDescription

from energy_integral import phase_rate, times_to

#: Ellipse used for the points outlines (m): half length a along the common axis, b across.
A, B = 0.1, 0.06


def ellipse_points(a=A, b=B, count=200, shift=(0.0, 0.0)):
    s = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
    return np.column_stack([b * np.sin(s) + shift[0], -a * np.cos(s) + shift[1]])


def write_csv(path, points):
    np.savetxt(path, points, delimiter=',', header='x,y', comments='')
    return str(path)


def one_line(error):
    text = str(error)
    assert '\n' not in text and 'Traceback' not in text, text
    return text


# -- the contract -----------------------------------------------------------------------------

def test_shape_parameters_are_in_the_contract_and_restart_the_motion():
    for name in ('shape', 'exponent', 'egg_asymmetry', 'shape_file', 'arrangement'):
        p = BY_NAME[name]
        assert p.physics and not p.read_only, name
    assert BY_NAME['shape'].choices == ('ellipse', 'superellipse', 'egg', 'points')
    assert DEFAULTS.shape == 'ellipse' and DEFAULTS.arrangement == 'parallel'
    assert DEFAULTS.with_values(shape='egg').physics_differs(DEFAULTS)
    # what the shape does not read does not restart the motion
    assert not DEFAULTS.with_values(exponent=6.0, shape_file='x.csv').physics_differs(DEFAULTS)
    superellipse = DEFAULTS.with_values(shape='superellipse')
    assert superellipse.with_values(exponent=6.0).physics_differs(superellipse)
    points = DEFAULTS.with_values(shape='points', shape_file='x.csv')
    assert not points.with_values(a=0.3, b=0.2, exponent=3.0).physics_differs(points)
    assert points.with_values(delta=0.02).physics_differs(points)


def test_an_ellipse_run_starts_where_its_parameters_say_and_is_the_energy_integral():
    """A run of two ellipses (solid hull) from its settings alone: it starts at θ0 with the
    body turning at ω0, and its motion is the energy integral of its own dynamics
    (tests/energy_integral.py; the phase to 1e-11 rad, the accuracy docs/physics.md states
    for the table method). The poses are the closed-form cycle at the recorded phases."""
    s = DEFAULTS.with_values(realtime=False, duration=1.0, mass_model='solid', theta0=0.7)
    simulation = Simulation(s)
    assert isinstance(simulation.body, EllipseBody)
    t = np.linspace(0.0, 1.0, 101)
    sample = simulation.sample(t)
    dynamics = simulation.dynamics
    assert abs(sample.theta[0] - s.theta0) < 1e-14
    turning = float(dynamics.angular_speed_per_phase(sample.phase[0]))
    assert abs(abs(sample.phase_rate[0]) * turning - s.omega0) < 1e-12 * s.omega0
    u0, rate0 = sample.phase[0], sample.phase_rate[0]
    assert np.all(np.diff(sample.phase) > 0)        # it rolls over: u̇ never 0
    energy = float(dynamics.energy(u0, rate0))
    assert np.max(np.abs(sample.phase_rate - phase_rate(dynamics, energy, sample.phase))) \
        < 1e-11 * rate0
    times = times_to(dynamics, energy, u0, sample.phase[10::10])
    assert np.max(np.abs(times - t[10::10]) * sample.phase_rate[10::10]) < 1e-11
    assert np.array_equal(sample.position_g, dynamics.cycle.poses(sample.phase).position_g)
    assert simulation.run.metadata() == s.as_strings()      # no outline keys for ellipses


def test_superellipse_at_exponent_2_has_the_ellipse_theta_max():
    # θ_max of the general contact geometry against the closed form (agree to ~2e-16 rel.)
    for a, b, delta in ((0.1, 0.1, 0.05), (0.1, 0.03, 0.02), (0.1, 0.5, 0.09)):
        limit = EllipseBody(a, b, delta).theta_max
        base = DEFAULTS.with_values(shape='superellipse', exponent=2.0, a=a, b=b, delta=delta)
        base.with_values(theta0=limit * (1 - 1e-12)).checked()
        with pytest.raises(ValueError, match='theta_max') as error:
            base.with_values(theta0=limit * (1 + 1e-12)).checked()
        one_line(error.value)


@pytest.mark.parametrize('radius', [0.05, 0.1, 2.0])
@pytest.mark.parametrize('asymmetry', [-0.95, -0.3, 0.5, 0.95])
def test_egg_asymmetry_is_a_share_of_the_largest_convex_epsilon(radius, asymmetry):
    # a circle's egg: ε_max = r/8 (docs/physics.md); the ends at −(a + ε) and a − ε
    s = DEFAULTS.with_values(shape='egg', a=radius, b=radius, delta=radius / 2,
                             egg_asymmetry=asymmetry).checked()
    egg = shapes.lamina_of(s)
    epsilon = asymmetry * radius / 8
    assert isinstance(egg, Egg)
    assert egg.epsilon == pytest.approx(epsilon, rel=1e-14, abs=0)   # minimize_scalar's 1e-13 rad
    x_max, y_min, y_max = egg.extents
    assert (y_min, y_max) == pytest.approx((-(radius + epsilon), radius - epsilon), rel=1e-13)
    assert shapes.axes_of(egg) == pytest.approx((radius, radius), rel=1e-13)


# -- points --------------------------------------------------------------------------------

def test_points_take_a_and_b_from_the_outline(tmp_path):
    path = write_csv(tmp_path / 'ellipse.csv', ellipse_points())
    s = DEFAULTS.with_values(shape='points', shape_file=path, delta=0.03).checked()
    outline = shapes.lamina_of(s)
    assert outline.fit_error < 1e-12                 # an exact ellipse is fitted to rounding
    assert shapes.axes_of(outline) == pytest.approx((A, B), rel=1e-12)
    limit = EllipseBody(A, B, 0.03).theta_max
    with pytest.raises(ValueError, match='theta_max'):
        s.with_values(theta0=limit * (1 + 1e-9)).checked()
    s.with_values(theta0=limit * (1 - 1e-9)).checked()
    # delta/a uses the outline's a (0.1 m), not the parameter a
    with pytest.raises(ValueError, match="the outline's a") as error:
        s.with_values(a=1.0, delta=0.1).checked()
    one_line(error.value)
    s.with_values(a=0.001, b=100.0).checked()         # the parameters a, b are not used


def test_an_outline_out_of_the_allowed_sizes_is_refused(tmp_path):
    path = write_csv(tmp_path / 'big.csv', ellipse_points(2000.0, 1000.0))
    with pytest.raises(ValueError, match="the outline's a must satisfy 0.001 <= a <= 1000 m"):
        DEFAULTS.with_values(shape='points', shape_file=path, delta=500.0).checked()


def test_yaml_outline_with_an_off_centre_axis(tmp_path):
    path = tmp_path / 'outline.yaml'
    points = ellipse_points(shift=(0.2, 0.0))    # x of the axis is found from the points
    path.write_text('points:\n' + ''.join(f'  - [{float(x)!r}, {float(y)!r}]\n'
                                           for x, y in points))
    s = DEFAULTS.with_values(shape='points', shape_file=str(path)).checked()
    outline = shapes.lamina_of(s)
    assert outline.axis_offset == pytest.approx(0.2, abs=1e-12)
    assert shapes.axes_of(outline) == pytest.approx((A, B), rel=1e-12)


@pytest.mark.parametrize('content, says', [
    (None, 'cannot be read'),
    ('x,y\n1,2\n3,4\n', '8 to 20000 distinct points'),
    ('x,y\n1,2\n3,a\n', 'line 3 must be two numbers'),
    ('\xff', None),
    ('points: [[1, 2], [3]]', 'point 1 must be [x, y]'),
])
def test_an_unusable_shape_file_is_one_line_naming_it(tmp_path, content, says):
    path = tmp_path / ('outline.yaml' if content and content.startswith('points') else 'o.csv')
    if content == '\xff':
        path.write_bytes(b'\xff\xfe 1, 2\n')
        says = 'cannot be read'
    elif content is not None:
        path.write_text(content)
    with pytest.raises(ValueError) as error:
        DEFAULTS.with_values(shape='points', shape_file=str(path)).checked()
    text = one_line(error.value)
    assert text.startswith(f'shape_file {path}: ') and says in text, text


@pytest.mark.parametrize('make, says', [
    (lambda tmp: '', "shape_file must name a CSV or YAML outline file"),
    (lambda tmp: str(tmp), 'is a directory'),
    (lambda tmp: '/dev/zero', 'not a regular file'),
    (lambda tmp: _fifo(tmp), 'not a regular file'),
    (lambda tmp: _big(tmp), 'more than the'),
    (lambda tmp: write_csv(tmp / 'dent.csv', _dented()), 'not'),
])
def test_shape_files_that_are_not_outlines_are_refused_without_reading(tmp_path, make, says):
    path = make(tmp_path)
    with pytest.raises(ValueError) as error:
        DEFAULTS.with_values(shape='points', shape_file=path).checked()
    assert says in one_line(error.value)


def _fifo(tmp):
    import os
    os.mkfifo(tmp / 'pipe.csv')
    return str(tmp / 'pipe.csv')


def _big(tmp):
    path = tmp / 'big.csv'
    path.write_bytes(b'0, 0\n' * (shapes.MAX_SHAPE_FILE_BYTES // 5 + 1))
    return str(path)


def _dented():
    points = ellipse_points()
    points[50] *= 0.8                                   # a dent: not convex
    return points


@hsettings(max_examples=40, deadline=None,
           suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rows=st.lists(st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)), max_size=40),
       junk=st.sampled_from(['', 'x,y\n', '# comment\n', 'a b c\n']))
def test_any_shape_file_gives_an_outline_or_one_line(tmp_path, rows, junk):
    path = tmp_path / f'h{abs(hash((tuple(rows), junk)))}.csv'
    path.write_text(junk + ''.join(f'{x!r}, {y!r}\n' for x, y in rows))
    try:
        outline = shapes.read_shape_file(str(path))
    except ValueError as error:
        assert one_line(error).startswith(f'shape_file {path}: ')
    else:
        assert outline.fit_error <= 1e-3 * outline.size


# -- any values: a valid run or one line ------------------------------------------------------

NAMES = ('shape', 'exponent', 'egg_asymmetry', 'arrangement', 'a', 'b', 'delta', 'theta0')


@hsettings(max_examples=80, deadline=None)
@given(shape=st.sampled_from(['ellipse', 'superellipse', 'egg', 'circle', '']),
       exponent=st.one_of(st.floats(allow_nan=True), st.floats(1.5, 120.0), st.just(2.0)),
       asymmetry=st.one_of(st.floats(-1.2, 1.2), st.floats(allow_nan=True)),
       arrangement=st.sampled_from(['parallel', 'swapped', 'diagonal']),
       a=st.floats(1e-4, 2e3), b_over_a=st.floats(5e-3, 200.0), delta_over_a=st.floats(0, 1.1),
       theta0=st.floats(-3.5, 3.5))
def test_any_shape_values_give_a_valid_run_or_one_line(shape, exponent, asymmetry, arrangement,
                                                      a, b_over_a, delta_over_a, theta0):
    values = dict(shape=shape, exponent=exponent, egg_asymmetry=asymmetry,
                  arrangement=arrangement, a=a, b=a * b_over_a, delta=a * delta_over_a,
                  theta0=theta0)
    try:
        s = DEFAULTS.with_values(**values).checked()
    except ValueError as error:
        text = one_line(error)
        assert any(name in text for name in NAMES), text
    else:
        assert s.shape in shapes.SHAPES and abs(s.egg_asymmetry) <= shapes.EGG_ASYMMETRY


@pytest.mark.parametrize('changes, says', [
    (dict(shape='circle'), 'shape must be one of ellipse, superellipse, egg, points'),
    (dict(shape='superellipse', exponent=1.5), 'exponent must satisfy 2 <= exponent <= 100'),
    (dict(exponent=math.nan), 'exponent must satisfy'),
    (dict(shape='egg', egg_asymmetry=0.96), 'egg_asymmetry must satisfy -0.95'),
    (dict(arrangement='diagonal'), 'arrangement must be one of parallel, swapped'),
    (dict(shape='egg', delta=0.1 - 1e-9), 'delta'),
    (dict(shape_file=3), 'shape_file must be a string'),
    # a hull of sharper corners is not resolved (hull_general refuses n = 100 at run time)
    (dict(shape='superellipse', exponent=60.0, mass_model='solid'),
     'exponent must be <= 50 for mass_model solid'),
    # 1000/s x 1 kg x (0.1 m)^2 = 10 N m s: stiffer damping is refused, not integrated for ever
    (dict(damping=10.5), 'damping must be <= 1000/s x mass x max(a, b)^2 = 10 N m s'),
])
def test_bad_shape_values_are_one_line_naming_the_parameter(changes, says):
    with pytest.raises(ValueError) as error:
        DEFAULTS.with_values(**changes).checked()
    assert says in one_line(error.value)


# -- parameter files (config/*.yaml style) ----------------------------------------------------

def params_file(tmp_path, body):
    path = tmp_path / 'shape.yaml'
    path.write_text('/**:\n  ros__parameters:\n' + ''.join(f'    {line}\n'
                                                            for line in body.splitlines()))
    return str(path)


def test_a_superellipse_params_file_runs_the_contract(tmp_path):
    path = params_file(tmp_path, 'shape: superellipse\nexponent: 6.0\na: 0.1\nb: 0.08\n'
                                 'delta: 0.04\narrangement: swapped')
    argv = ['roller', '--ros-args', '--params-file', path]
    assert arguments.check_arguments(argv) == []
    s = DEFAULTS.with_values(**params_file_values(path)).checked()
    assert (s.shape, s.exponent, s.arrangement) == ('superellipse', 6.0, 'swapped')


@pytest.mark.parametrize('line, says', [
    ('exponent: 6', 'exponent is a double: write 6.0, not 6'),
    ('shape_file: 12', "shape_file is a string, got the integer 12: quote it"),
    ('egg_asymmetry: .5x', "egg_asymmetry is a double, got the string '.5x'"),
])
def test_mistyped_shape_values_in_a_params_file_name_file_and_line(tmp_path, line, says):
    path = params_file(tmp_path, f'shape: superellipse\n{line}')
    with pytest.raises(arguments.ArgumentError) as error:
        arguments.check_arguments(['roller', '--ros-args', '--params-file', path])
    text = one_line(error.value)
    assert f'{path}, line 4' in text and says in text, text


def test_shape_parameters_the_shape_does_not_read_are_warned_about(tmp_path):
    argv = ['roller', '--ros-args', '-p', 'exponent:=6.0', '-p', "shape_file:=x.csv"]
    warnings = arguments.check_arguments(argv)
    assert len(warnings) == 2 and all('not used' in w for w in warnings), warnings
    argv = ['roller', '--ros-args', '-p', 'shape:=points', '-p', 'shape_file:=x.csv',
            '-p', 'a:=0.2']
    (warning,) = arguments.check_arguments(argv)
    assert 'a is set but not used with shape points' in warning
    assert arguments.check_arguments(['roller', '--ros-args', '-p', 'shape:=superellipse',
                                      '-p', 'exponent:=3.0']) == []


# -- recordings ---------------------------------------------------------------------------------

def test_a_points_outline_round_trips_through_the_metadata_exactly(tmp_path):
    path = tmp_path / 'ellipse.csv'
    s = DEFAULTS.with_values(shape='points', shape_file=write_csv(path, ellipse_points()),
                             delta=0.03).checked()
    fitted = shapes.lamina_of(s)
    strings = dict(s.as_strings(), **shapes.outline_metadata(fitted))
    json.dumps(strings)                                # text only, as MCAP metadata holds
    path.unlink()                                      # checked without the shape file
    shapes.clear_caches()
    parsed, problems = parse_recorded(strings)
    assert problems == [] and parsed == s
    outline = shapes.outline_from_metadata(strings)
    assert np.array_equal(outline.coefficients, fitted.coefficients)
    assert (outline.fit_error, outline.point_count) == (fitted.fit_error, 200)
    # the rebuilt outline gives the recorded body: θ_max of the ellipse it was sampled from
    limit = EllipseBody(A, B, 0.03).theta_max
    assert shapes.theta_max_of(parsed, outline) == pytest.approx(limit, rel=1e-12)


@pytest.mark.parametrize('outline, says', [
    (None, 'parameter outline is missing'),
    ('[1.0, "x"]', 'outline must be a list of 1 to 1024 numbers'),
    ('NaN', 'outline must be a list'),
    ('[NaN]', 'finite'),
    ('[0.1, 0.0, 0.2]', "h + h'' > 0"),            # not convex
])
def test_a_broken_recorded_outline_is_one_problem(outline, says):
    strings = DEFAULTS.with_values(shape='points', shape_file='gone.csv').as_strings()
    if outline is not None:
        strings['outline'] = outline
    settings, problems = parse_recorded(strings)
    assert settings is None and len(problems) == 1 and says in one_line(problems[0])


def test_recordings_without_the_shape_parameters_are_ellipse_runs():
    old = {p.name: text for p, text in zip(PARAMETERS, DEFAULTS.as_strings().values())
           if p.name not in ('shape', 'exponent', 'egg_asymmetry', 'shape_file', 'arrangement')}
    old.update(a='1.0', b='0.6', delta='0.5')
    run, problems = RunDescription.from_recorded(old)
    assert problems == [] and run.settings.shape == 'ellipse'
    assert isinstance(run.body, EllipseBody)
    assert run.body.theta_max == EllipseBody(1.0, 0.6, 0.5).theta_max
    assert 'ellipse a = 1 m, b = 0.6 m, delta = 0.5 m' == run.shape_line


def test_the_kinematic_flat_run_is_the_librarys_quadrature_bit_for_bit():
    """Kinematic mode on level ground without drive or losses takes the level ground's own
    solver inside the one motion class (SceneMotion.level): the library's ``simulate``
    (kinematic quadrature at the constant |omega0|), the rolling cycle's poses and the
    motor's contact forces of ContactForceModel, bit for bit, not the speed drive's DOP853
    (which agrees only to its tolerance, ~1e-12 here)."""
    from twodisk_ros.physics.forces.contact import ContactForceModel
    from twodisk_ros.physics.motion.simulate import simulate
    s = DEFAULTS.with_values(mode='kinematic', omega0=-2.5)
    sim = Simulation(s)
    assert sim.scene.level and sim.motion.solver == 'quadrature'
    t = np.linspace(0.0, 1.5, 61)     # (past one cycle of the oloid at 2.5 rad/s)
    got = sim.sample(t, forces=True)
    want = simulate(sim.dynamics, t, mode='kinematic', theta0=s.theta0, branch=s.branch,
                    omega0=s.omega0, method=s.method, tolerance=s.tolerance)
    poses = sim.dynamics.cycle.poses(want.phase)
    forces = ContactForceModel(sim.dynamics).kinematic(want.phase, 2.5)
    assert np.array_equal(got.phase, want.phase)
    assert np.array_equal(got.phase_rate, want.phase_rate)
    assert np.array_equal(got.position_g, poses.position_g)
    assert np.array_equal(got.quaternion, poses.quaternion)
    for name in ('normal_a', 'normal_b', 'mu_required', 'force_a', 'force_b'):
        assert np.array_equal(getattr(got.forces, name), getattr(forces, name)), name
    assert got.scene is None and sim.invariant(got, 30)[0] == 'angular_speed'

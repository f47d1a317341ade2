"""The runs behind the hybrid figures (plotting/hybrid_results.py, hybrid_figures.py) against
closed forms: a flight's rise found on a semi-implicit Euler parabola, the vertex kinds, the
free oloid's lift-off speed against the kinematic closed form, and the command line's
refusals. The figures themselves are not run here (75 s of CPU: ``make figures``)."""

import math

import numpy as np
import pytest

from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.forces.validity import liftoff_speed
from twodisk_ros.plotting import hybrid_figures
from twodisk_ros.plotting.hybrid_results import (OLOID, OLOID_PHASE, _flights, classify,
                                                 description, liftoff_threshold)


def test_a_flight_rises_as_semi_implicit_euler_under_gravity():
    """z by v ← v − g h, z ← z + h v (MuJoCo's free flight) from v0 at the first step in the
    air: the rise is v0²/2g − h v0/2 to within g h²/8 (the discrete apex between two steps),
    and the ballistic value reported is v0²/(2g) (16 ulps)."""
    g, h, v0 = 9.81, 5e-4, 0.7
    n = 400
    v = v0 - g * h * np.arange(n)
    z = 0.07 + np.concatenate([[0.0], np.cumsum(h * v[1:])])
    touching = np.ones((n + 20, 2), dtype=bool)
    touching[10:10 + n] = False
    zz = np.concatenate([np.full(10, 0.07), z, np.full(10, z[-1])])
    vz = np.concatenate([np.zeros(10), v, np.zeros(10)])
    t = h * np.arange(n + 20)
    (t0, t1, rise, ballistic), = _flights(t, zz, vz, touching, g)
    assert t0 == t[10] and t1 == t[10 + n - 1]
    assert abs(ballistic - v0 ** 2 / (2 * g)) <= 16 * np.finfo(float).eps * ballistic
    assert abs(rise - (v0 ** 2 / (2 * g) - 0.5 * h * v0)) <= g * h ** 2 / 8


def test_a_flight_that_does_not_rise_or_ends_before_its_apex_is_left_out():
    g, h = 9.81, 5e-4
    t = h * np.arange(30)
    touching = np.ones((30, 2), dtype=bool)
    touching[5:25] = False
    falling = -np.ones(30)
    assert _flights(t, np.zeros(30), falling, touching, g) == []
    assert _flights(t, np.zeros(30), np.ones(30), touching, g) == []   # no apex in the air


@pytest.mark.parametrize('pattern, flights, kind', [
    ('11 11 11', [], 'slide'),
    ('11 01 11', [], 'rock'),
    ('11 01 11 10 11', [], 'rattle'),
    ('11 01 00 11', [(0.0, 1.0)], 'hop'),
    ('11 01 01', [], 'rock'),          # left and not back within the stretch
])
def test_vertex_kinds(pattern, flights, kind):
    touching = np.array([[c == '1' for c in step] for step in pattern.split()])
    assert classify(touching, flights) == kind


def test_the_free_oloid_lifts_off_at_the_kinematic_lift_off_speed():
    """At the smallest ω0 that lifts a contact off, the free motion's |w| at the N = 0
    crossing is the closed form Ω_c of the kinematic model (liftoff_speed), since it lifts
    off at the phase where z_G is extreme and ẇ = 0: the bisection's width (1e-7 of ω0)
    bounds the difference, with margin 10."""
    _, run = description(OLOID)
    model = ContactForceModel(run.dynamics)
    critical = liftoff_speed(model)[0]
    omega0, when, phase, speed = liftoff_threshold(run.dynamics, model, OLOID_PHASE,
                                                   span=2.0, step=2e-4, rtol=1e-7)
    assert omega0 > critical                       # from π/4 it speeds up on the way down
    assert abs(speed / critical - 1) <= 1e-6, (speed, critical)
    assert 0 < when < 2.0
    assert abs(math.remainder(phase, 0.5 * math.pi)) < 1e-3


def test_the_command_line_refuses_in_one_line(tmp_path, capsys):
    assert hybrid_figures.main(['--out', str(tmp_path), '--span', '0.1']) == 2
    err = capsys.readouterr().err.strip()
    assert err.count('\n') == 0 and '--span must be 0.6 to 600 s' in err
    (tmp_path / hybrid_figures.NAMES[0]).write_bytes(b'old')
    assert hybrid_figures.main(['--out', str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count('\n') == 0 and (tmp_path / hybrid_figures.NAMES[0]).read_bytes() == b'old'

"""A run started exactly on a flat vertex: its initial state in the regular chart.

On the rounded square (superellipse n = 4, a = b = 0.1 m, Δ = 0.05 m) θ0 = 0 puts contact A
on a flat vertex (u0 = 0): the body does not turn in u there (|ω_u| = 0, evaluated as 3.3e-13
by rounding), so u̇0 = ω0/|ω_u| is infinite (9e12 rad/s as computed) and nothing derived from
it means anything: before the fix the diagnostics' energy at t = 0 drifted by 1.2e-5 (M g L)
in a free run and |ω| by 1.8e-4 in a kinematic one, and every scene's energy balance was off
by 3.2e-2 for the whole run (E₀ 0.973 J for 0.923 J). The start is now the angular speed
about AB, w0 = ω0 (docs/physics.md "Bodies that stop turning in u"), and everything about it
comes from w. References:

* the closed forms (no tables): E0 = ½ J(u0) ω0² + M g z_G(u0), J the moment of inertia about
  AB (``contact_line_inertia``) and z_G the body's height (``potential``);
* continuity: θ0 = 1e-7 rad (u0 = 4.3e-8 rad, off the vertex) gives the same state and motion
  to within what that shift and the solvers allow;
* the run's own parameter: the angular speed at t = 0 is omega0.
"""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from twodisk_ros.node import diagnostics, run_summary
from twodisk_ros.run.parameters import DEFAULTS
from twodisk_ros.run.simulation import Simulation

pytestmark = pytest.mark.ros

SQUARE = dict(shape='superellipse', exponent=4.0, a=0.1, b=0.1, delta=0.05, omega0=3.0,
              realtime=False, duration=1.0)
SCENES = {'free': {}, 'kinematic': dict(mode='kinematic'), 'damped': dict(damping=0.002),
          'slope': dict(slope=0.05), 'speed drive': dict(drive='speed')}
NEAR = 1e-7          # rad: θ0 of the start just off the vertex
_BUILT = {}


def simulation(theta0, scene):
    key = (theta0, scene)
    if key not in _BUILT:
        _BUILT[key] = Simulation(DEFAULTS.with_values(theta0=theta0, **SQUARE, **SCENES[scene]))
    return _BUILT[key]


@pytest.mark.parametrize('scene', SCENES)
def test_a_start_on_a_flat_vertex_is_the_angular_speed_omega0(scene):
    on, near = simulation(0.0, scene), simulation(NEAR, scene)
    start = on.initial_state()
    assert abs(start.phase) < 1e-15 and start.angular_speed == 3.0       # u0 = 0, w0 = ω0
    assert abs(near.initial_state().phase - start.phase) < 1e-7
    # E0: the closed forms at u0 (the slope's potential has another zero: continuity only)
    dynamics, scale = on.dynamics, on.dynamics.energy_scale
    if scene != 'slope':
        reference = (0.5 * dynamics.contact_line_inertia(start.phase) * 3.0**2
                     + dynamics.potential(start.phase))
        # tables against closed forms: spectral to rounding (measured 0 and 1.4e-16)
        assert abs(on.energy0 - reference) <= 1e-12 * scale, (on.energy0, reference)
    # continuity: u0 moves by 4.3e-8 rad where V′ = 0 and J′ is small (measured 0)
    assert abs(on.energy0 - near.energy0) <= 1e-12 * scale
    t = np.array([0.0, 0.05, 0.1])
    sample, other = on.sample(t, forces=True), near.sample(t, forces=True)
    # the angular speed at t = 0 is ω0 (to the rounding of √(J w0²/J)), and finite after
    assert abs(sample.angular_speed[0] - 3.0) <= 1e-14 * 3.0
    assert np.all(np.isfinite(sample.angular_speed))
    # the invariant at the start: exact (before: drift 1.2e-5, 1.8e-4, 3.2e-2)
    name, value, drift = on.invariant(sample, 0)
    assert math.isfinite(value) and drift <= 1e-13, (name, value, drift)
    # the motion from either start: the 4.3e-8 rad shift, and DOP853 (rtol 1e-10) where used
    assert np.max(np.abs(sample.phase - other.phase)) <= 1e-7
    assert np.max(np.abs(sample.angular_speed - other.angular_speed)) <= 1e-6
    # nothing NaN in what is published (forces at the vertex: ±inf or large, by design)
    for values in (sample.forces.normal_a, sample.forces.normal_b, sample.phase_rate,
                   sample.theta_rate, sample.psi_rate):
        assert not np.any(np.isnan(values))


def stub_node(sim):
    return SimpleNamespace(settings=sim.settings, simulation=sim, achieved_rate=lambda: None,
                           samples_dropped=0, dropped_reported=0, lag=[])


@pytest.mark.parametrize('scene', ['free', 'kinematic'])
def test_the_diagnostics_of_the_start_say_omega0_and_no_drift(scene):
    sim = simulation(0.0, scene)
    sample = sim.sample(np.array([0.0, 0.01]), forces=True)
    level, message, values = diagnostics.status(stub_node(sim), sample, 0)
    values = dict(values)
    assert values['angular_speed'] == pytest.approx(3.0, rel=1e-14, abs=0)
    drift = values['energy_drift' if scene == 'free' else 'angular_speed_drift']
    assert drift <= 1e-13 and 'drift' not in message
    # contact B lifts off at the vertex whatever the speed (docs/physics.md): the ERROR stays
    assert level == 2 and 'contact B would lift off at t = 0 s' in message


def test_the_start_up_log_names_a_flat_vertex_start():
    start = simulation(0.0, 'free')
    note = run_summary.start_note(start.body, start.initial_state())
    assert note.startswith('the start is on a flat vertex (phase u0 = 0 rad)')
    assert 'angular speed 3 rad/s about the contact line AB' in note
    assert run_summary.start_note(start.body, simulation(NEAR, 'free').initial_state()) is None
    at_rest = start.initial_state()._replace(angular_speed=0.0)
    assert run_summary.start_note(start.body, at_rest).endswith('it starts at rest there')
    ellipse = Simulation(DEFAULTS.with_values(theta0=0.0, realtime=False, duration=1.0))
    assert run_summary.start_note(ellipse.body, ellipse.initial_state()) is None

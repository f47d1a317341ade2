"""Bodies at the corners of the allowed range, and at extreme scales.

* b/a = 0.01, Δ/a → 1 is thin and nearly neutral: V varies by ~2e-8 M g L over a cycle, so
  every motion lies in the table method's separatrix band (defined in M g L). It used to be
  DOP853 through the sharp features of m(u) (~50 s of start-up for 0.5 s of motion); the
  quadrature is resolved there and is now used. Reference: t(u) = ∫ √(m / (2(E − V))) du by
  scipy's adaptive quad on the closed forms (no table, no solver of the package).
* b/a = 0.01, Δ/a = 1e-3 librates: the tables in φ stop refining at the noise floor of the
  tabulated V′ (they were refined to 2¹⁸ nodes for nothing, ~6 s).
* Scale invariance: θ_max, z_G / a at the equilibria and the advance per cycle S / a do not
  depend on the scale; outside LENGTH_RANGE a ValueError names the range.
"""

import math
import time
import warnings

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.integrate import IntegrationWarning, quad

from rounding import ulps
from twodisk_ros.physics import RollingCycle, RollingDynamics, EllipseBody, equilibria
from twodisk_ros.physics.bodies.ellipse import LENGTH_RANGE
from twodisk_ros.physics.mass.models import laminae
from twodisk_ros.physics.motion.simulate import MotionStream, simulate_phase
from twodisk_ros.physics.motion.solvers import LibrationSolution
from twodisk_ros.physics.motion.startup import NOTICE_SECONDS, startup_estimate

GRAVITY = 9.81


def _dynamics(abd):
    return RollingDynamics(EllipseBody(*abd), laminae(*abd, 1.0), GRAVITY)


def _start(dyn, theta0=0.3, omega0=3.0):
    u0 = float(dyn.body.phase_from_theta(theta0, 1))
    return u0, dyn.initial_phase_rate(u0, omega0)


def test_thin_nearly_neutral_body_rolls_in_closed_form():
    # the node's default start (theta0 0.3, omega0 3) on the body of the issue: a = 0.1,
    # b = 0.001, delta = 0.0999999 m; E is 3e-6 M g L above max V, 150 × the depth of V
    abd = (0.1, 0.001, 0.0999999)
    dyn = _dynamics(abd)
    u0, u_dot0 = _start(dyn)
    stream = MotionStream(dyn, u0, u_dot0)            # what the node builds (a 10 s chunk)
    # bounded work: the closed form, no right-hand side of an ODE (DOP853 took 50 s before)
    assert stream.solver == 'quadrature' and stream.nfev == 0
    # the closed form at t = 0 starts from u0, to its rounding (16 ulps of u0)
    assert stream.sample(np.array([0.0]))[0][0] == pytest.approx(u0, abs=ulps(16, u0))
    t = np.linspace(0.0, 0.5, 6)
    motion = simulate_phase(dyn, t, u0, u_dot0)
    assert motion.solver == 'quadrature'
    # independent reference: the time to reach each sampled phase, by adaptive quadrature
    # of the closed forms (quad's error estimate ≤ 2e-14 s); measured ≤ 1.6e-13 s
    energy = 0.5 * float(dyn.effective_mass(u0)) * u_dot0**2 + float(dyn.potential(u0))

    def inverse_speed(v):
        return math.sqrt(float(dyn.effective_mass(v))
                         / (2 * (energy - float(dyn.potential(v)))))
    for t_k, u_k in zip(t[1:], motion.phase[1:]):
        t_ref, _ = quad(inverse_speed, u0, u_k, limit=2000, epsabs=1e-14, epsrel=1e-13)
        assert abs(t_ref - t_k) <= 1e-11 * t_k        # claim: t(u) to 1e-11 relative
    assert motion.energy_drift <= 1e-13


def test_ordinary_body_near_the_barrier_keeps_dop853():
    # the band's resolution test does not take the quadrature where it is not resolved:
    # the Oloid 1e-5 M g L above its barrier (1/|u̇| peaks sharply at the top of V)
    abd = (0.1, 0.1, 0.05)
    dyn = _dynamics(abd)
    top = max(eq.phase for eq, period in dyn.equilibria_with_periods() if period is None)
    mass = float(dyn.tabulated(top)[0])
    u_dot0 = math.sqrt(2e-5 * dyn.energy_scale / mass)
    motion = simulate_phase(dyn, np.linspace(0.0, 0.2, 5), top, u_dot0)
    assert motion.solver == 'DOP853'


def test_thin_body_libration_stops_at_the_noise_floor():
    abd = (1.0, 0.01, 0.001)
    dyn = _dynamics(abd)
    u0, u_dot0 = _start(dyn)
    t = np.linspace(0.0, 10.0, 401)
    begin = time.process_time()
    motion = simulate_phase(dyn, t, u0, u_dot0)
    assert time.process_time() - begin < 2.0          # hang guard: 0.06 s measured, 6 s before
    assert motion.solver == 'libration' and motion.sol.resolved
    # the grid refined to its cap (2¹⁸ nodes, as before) gives the same motion: the extra
    # nodes only resampled the noise (measured 5.9e-9 rad over 10 s, ~50 cycles of u)
    full = LibrationSolution(dyn.tabulated_well(motion.sol.centre), u0 - motion.sol.centre,
                             u_dot0, dyn.table_size)
    full_phase = full(t)[0]
    assert np.max(np.abs(motion.phase - full_phase)) <= 2e-8


class _NodeStart:
    """The node's motion for these parameters over its first 0.5 s at 100 Hz.

    The flat free scene's path of :class:`~twodisk_ros.run.simulation.Simulation`: the
    MotionStream of the run's description (``RunDescription.stream``, what Simulation's
    its level SceneMotion samples) and the energy E = ½ J w² + V of each sample against E₀ (what
    ``Simulation.invariant`` gives there). The node's pose and contact-force tables are not
    built: no claim here reads them (at 2¹⁶ nodes they cost more than the motion itself).
    """

    def __init__(self, **values):
        from twodisk_ros.run.description import RunDescription    # the node's contract
        from twodisk_ros.run.parameters import DEFAULTS
        from twodisk_ros.run.scene_simulation import flat_free
        settings = DEFAULTS.with_values(**values)
        assert flat_free(settings)                 # Simulation's level path (SceneMotion.level)
        run = RunDescription(settings)
        self.dynamics, self.stream = run.dynamics, run.stream()
        self.t = np.arange(1, 51) / 100.0
        self.phase, _, self.angular_speed = self.stream.sample_with_speed(self.t)

    def energy_drift(self):
        """max |E − E₀| / (M g L) over the samples (Simulation.invariant's relative drift)."""
        return max(abs(float(self.dynamics.energy_turning(u, w)) - self.stream.initial_energy)
                   / self.dynamics.energy_scale
                   for u, w in zip(self.phase, self.angular_speed))


def test_thin_body_at_one_millimetre_starts_in_closed_form():
    # issue 19: a = 1 mm, b/a = 0.01, delta/a = 1 - 1e-6 at the default start (theta0 0.3,
    # omega0 3 rad/s). E - V is 1e-5 of V there; its rounding left 1/|u̇| a flat spectral
    # floor of ~5e-12 that failed the band's resolution test, and DOP853 ran > 5 min of CPU
    # for its first 10 s. Measured now: 1.5 s (table building included).
    node = _NodeStart(a=0.001, b=0.00001, delta=0.000999999)
    t = node.t
    # bounded work: the closed form, no right-hand side of an ODE (DOP853: > 300 s before)
    assert node.stream.solver == 'quadrature' and node.stream.nfev == 0
    # independent reference: the time to reach each sampled phase, by adaptive quadrature
    # of the closed forms (no table, no solver of the package). Its integrand carries the
    # rounding of E − V (1e-16 V / (E − V) ~ 1e-11 relative; quad warns of roundoff), so
    # the bound is 1e-10 relative (measured 3.4e-11)
    dyn = node.dynamics
    u0, u_dot0 = _start(dyn)
    energy = 0.5 * float(dyn.effective_mass(u0)) * u_dot0**2 + float(dyn.potential(u0))

    def inverse_speed(v):
        return math.sqrt(float(dyn.effective_mass(v))
                         / (2 * (energy - float(dyn.potential(v)))))
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', IntegrationWarning)
        for t_k, u_k in zip(t[9::10], node.phase[9::10]):
            t_ref, _ = quad(inverse_speed, u0, u_k, limit=2000, epsabs=1e-14, epsrel=1e-13)
            assert abs(t_ref - t_k) <= 1e-10 * t_k
    # and DOP853 on the closed forms at rtol 1e-13 over 0.1 s: u to 1.5e-11 rad measured
    # (1e-12: 5.9e-11, the reference's own error), the claim of ~1e-11 for poses
    reference = simulate_phase(dyn, t[:10], u0, u_dot0, method='direct', tolerance=1e-13)
    assert np.max(np.abs(node.phase[:10] - reference.phase)) <= 1e-10
    assert node.energy_drift() <= 1e-13


@pytest.mark.slow
def test_tiny_thin_body_rolling_over_the_barrier_runs_in_the_regular_chart():
    # issue 28: a = 1 mm, b/a = 0.01, Δ/a = 0.001 from θ0 = 0 at omega0 3 rad/s: E is 1e-4
    # above the barrier, no closed form is resolved, and DOP853 in t had to follow u̇ =
    # w/|ω_u| through swings of three orders of magnitude (m(u) spans six): 171 560 right-hand
    # sides for the first 0.05 s, a 0.5 s batch of the node took 356 s. In the regular chart
    # (u, w) of the Sundman time: 26 264 for the whole 0.5 s (measured).
    node = _NodeStart(a=0.001, b=0.00001, delta=0.000001, theta0=0.0)
    t = node.t
    stream = node.stream
    assert stream.solver == 'DOP853'
    assert stream.nfev <= 100_000                          # ~1.7 million in t
    # conservation: the energy of every sample against E0, relative (invariant()[2]'s). The
    # tables' error near the separatrix bounds it (measured 1.4e-9; in t: 1.2e-7 by 0.05 s)
    assert node.energy_drift() <= 1e-8
    # a second method: DOP853 in t on the closed forms (no table), rtol 1e-12, to the first
    # sample, before the first fast swing (past it the reference itself costs minutes):
    # measured 3.6e-11 rad apart, within the tables' 1e-10 of a pose
    dyn = node.dynamics
    u0, u_dot0 = _start(dyn, theta0=0.0)
    reference = simulate_phase(dyn, np.array([0.0, t[0]]), u0, u_dot0, method='direct',
                               tolerance=1e-12)
    assert abs(node.phase[0] - reference.phase[1]) <= 1e-10


@pytest.mark.slow
def test_thin_body_at_rest_near_the_barrier_starts_without_a_10_s_chunk():
    # issue 19: a = 0.1, b/a = 0.01, delta/a = 1 - 1e-6, omega0 = 0: at rest 8e-11 M g L
    # below the barrier, a libration the tables in φ cannot resolve (tail 2e-4 at 2¹⁴
    # nodes), so DOP853 on the tables. Its first 10 s chunk cost ~31 s of CPU before the
    # first sample; the stream now integrates only what is asked for. Measured: 2.8 s.
    node = _NodeStart(a=0.1, b=0.001, delta=0.0999999, omega0=0.0)
    t = node.t
    assert node.stream.solver == 'DOP853'
    # bounded work: the right-hand sides for the 0.5 s asked for (377 measured), not a
    # 10 s chunk's (~20 times as many)
    assert node.stream.nfev <= 2000
    # reference: DOP853 on the closed forms (method direct) at rtol 1e-12, over the first
    # 0.2 s (its cost grows with the span: 3 s of CPU, 10 s for 0.5 s). The claim near the
    # separatrix (tests/test_libration.py): |δ − δ_ref| ≤ 3e-8 A; measured 5.9e-10 A by
    # 0.2 s, 1.5e-9 A by 0.5 s, the same against rtol 1e-13 (the tables' part, not the
    # reference's); the energy below holds the whole 0.5 s
    dyn = node.dynamics
    u0, _ = _start(dyn, omega0=0.0)
    early = t <= 0.2
    reference = simulate_phase(dyn, np.concatenate([[0.0], t[early]]), u0, 0.0,
                               method='direct', tolerance=1e-12)
    centre = reference.sol.centre
    amplitude = abs(u0 - centre)
    assert np.max(np.abs(node.phase[early] - reference.phase[1:])) <= 3e-8 * amplitude
    assert node.energy_drift() <= 1e-11


def test_startup_estimate_names_the_costly_bodies():
    costly = startup_estimate(EllipseBody(1.0, 0.01, 0.001))
    assert costly.resolution == 65536
    assert costly.seconds > NOTICE_SECONDS
    assert costly.message.startswith('building tables for an extreme body (b/a = 0.01')
    assert f'about {costly.seconds:.0f} s' in costly.message
    assert startup_estimate(EllipseBody.oloid(0.1)).message is None
    # the estimate is the grid the cycle then uses
    assert RollingCycle(EllipseBody(1.0, 0.05, 0.02)).resolution == startup_estimate(
        EllipseBody(1.0, 0.05, 0.02)).resolution


# ------------------------------------------------------------------------- scale invariance
def _dimensionless(a, b_over_a, delta_over_a):
    body = EllipseBody(a, b_over_a * a, delta_over_a * a)
    found = equilibria(body)
    cycle = RollingCycle(body)
    return np.array([body.theta_max] + [eq.height / a for eq in found]
                    + [eq.phase for eq in found] + [abs(cycle.displacement.shift) / a])


@settings(max_examples=25, deadline=None)
@given(exponent=st.floats(math.log10(LENGTH_RANGE[0]) + 2, math.log10(LENGTH_RANGE[1]) - 1),
       b_over_a=st.floats(0.3, 3.0), delta_over_a=st.floats(0.05, 0.95))
def test_results_are_scale_invariant(exponent, b_over_a, delta_over_a):
    # independent reference: the same body at a = 1 m (the geometry has no scale)
    reference = _dimensionless(1.0, b_over_a, delta_over_a)
    scaled = _dimensionless(10.0**exponent, b_over_a, delta_over_a)
    # atol for the phases at 0: their rounding, 16 ulps of 2π
    np.testing.assert_allclose(scaled, reference, rtol=1e-12, atol=ulps(16, 2 * math.pi))


@pytest.mark.parametrize('a', [LENGTH_RANGE[0] / 0.3, LENGTH_RANGE[1]])
def test_scale_invariance_at_the_ends_of_the_range(a):
    # Δ = 0.3 a and b = 0.7 a at the lower end, a itself at the upper end
    np.testing.assert_allclose(_dimensionless(a, 0.7, 0.3), _dimensionless(1.0, 0.7, 0.3),
                               rtol=1e-12)


@pytest.mark.parametrize('args, name', [
    ((1e200, 1e200, 5e199), 'a'), ((1e-200, 1e-200, 5e-201), 'a'),
    ((1.0, 1e31, 0.5), 'b'), ((1.0, 1e-31, 0.5), 'b'), ((1e-29, 1e-29, 1e-31), 'delta')])
def test_lengths_outside_the_range_are_refused(args, name):
    with pytest.raises(ValueError, match=rf'^{name} must be in \[1e-30, 1e\+30\] m'):
        EllipseBody(*args)


@pytest.mark.parametrize('args', [
    (math.nan, 1.0, 0.5), (1.0, math.inf, 0.5), (1.0, 1.0, 1.0), (1.0, 1.0, 0.0),
    (-1.0, 1.0, 0.5), (0.0, 1.0, 0.5), ('1', 1.0, 0.5), (None, 1.0, 0.5), (1.0, 1.0, [0.5])])
def test_bad_parameters_are_value_errors(args):
    with pytest.raises(ValueError, match=r'^(a|b|delta) must be '):
        EllipseBody(*args)


@pytest.mark.ros
def test_the_node_says_what_an_extreme_body_costs_before_paying_it():
    """The costliest allowed body logs its start-up estimate first, then starts and ends."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    repo = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(repo), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               ROS_DOMAIN_ID='79')
    result = subprocess.run(
        [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '-p', 'a:=0.1', '-p',
         'b:=0.001', '-p', 'delta:=0.0001', '-p', 'realtime:=false', '-p', 'duration:=0.05'],
        env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    lines = result.stderr.splitlines()
    assert 'building tables for an extreme body (b/a = 0.01, delta/a = 0.001' in lines[0]
    assert 'rolling a=0.1 m' in lines[1] and 'published 6 samples' in lines[2]

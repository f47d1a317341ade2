"""Oscillations over several wells (physics/motion/turning.py) of a body with unequal maxima of V.

The parallel egg's V has maxima V(0) < V(π/2): an energy between them crosses the lower
maximum and swings between two turning points around two minima. References, independent of
the table method: DOP853 on the direct closed forms (m, m′, V′ of RollingDynamics, written
here from Lagrange's equation) at rtol 1e-13, its turning instants (events) and brentq on the
closed-form V = E for the turning points.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.forces.validity import mu_required_dynamic
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.physics.bodies.lamina_body import LaminaBody
from twodisk_ros.physics.mass.models import centred_on_mass
from twodisk_ros.physics.motion.simulate import MotionStream, simulate

#: G's position against the DOP853 reference over 3 s: measured ≤ 1.8e-9 of the size (over
#: the 2 s of T, one period and both turning points: ≤ 1e-9); the
#: reference itself moves by 1e-9 rad between rtol 1e-12 and 1e-13 (its m′ is a 5-point
#: difference of the closed form m, whose own energy drifts by 4e-11 M g L).
POSITION_TOL = 1e-8
#: energy conservation of the closed form, from the tables: measured ≤ 4e-14 M g L
ENERGY_TOL = 2e-13
#: period against the reference's turning instants: measured 2.5e-10 relative, the
#: reference's spread between successive half-periods 1e-10
PERIOD_TOL = 2e-9
#: turning points against brentq on the closed-form V: measured 3e-11 rad (table vs closed V)
TURNING_TOL = 1e-9
#: (θ0, ω0) starts with energy between the two maxima: at the lower maximum (θ = 0), from
#: rest on the higher one's slope (u0 = 1.17 rad, a turning point), on both branches of u
STARTS = [(0.3, 3.0), (0.0, -2.0), (2.2, 0.0), (-0.3, -3.0)]
#: one period (1.84 s to 1.90 s for these starts) and more: every start reaches both turning
#: points and crosses u = 0 (the reference's cost grows with the span, ~3 s of CPU per second)
T = np.linspace(0.0, 2.0, 41)
#: the start whose reference also gives the period: it runs 2.5 periods, with turning events
PERIOD_START = (0.3, 3.0)


@pytest.fixture(scope='module')
def egg():
    body, props = centred_on_mass('laminae', LaminaBody(Egg(0.1, 0.08, 0.004), 0.04), 1.0)
    return RollingDynamics(body, props)


def _energy_closed(dyn, u, u_dot):
    return 0.5 * dyn.effective_mass(u) * u_dot**2 + dyn.potential(u)


def _start(dyn, theta0, omega0):
    u0 = float(dyn.body.phase_from_theta(theta0))
    return u0, omega0 / float(dyn.angular_speed_per_phase(u0))


def _reference(dyn, u0, u_dot0, t_end, **events):
    def rhs(t, y):
        m, dm = (float(x) for x in dyn.effective_mass_jet(y[0]))
        return [y[1], -(float(dyn.potential_slope(y[0])) + 0.5 * dm * y[1] ** 2) / m]
    return solve_ivp(rhs, (0.0, t_end), [u0, u_dot0], method='DOP853', rtol=1e-13,
                     atol=1e-13, dense_output=True, **events)


def _turn(t, y):
    return y[1]


@pytest.fixture(scope='module')
def references(egg):
    """start -> the DOP853 reference from it, built once for the module: over T, and for
    PERIOD_START over 2.5 periods with its turning instants (events at u̇ = 0; the events
    do not change the steps)."""
    cache = {}

    def reference(theta0, omega0):
        if (theta0, omega0) not in cache:
            u0, u_dot0 = _start(egg, theta0, omega0)
            if (theta0, omega0) == PERIOD_START:
                period = simulate(egg, T, theta0=theta0, omega0=omega0,
                                  method='table').sol.period
                cache[theta0, omega0] = _reference(egg, u0, u_dot0,
                                                   max(T[-1], 2.5 * period), events=_turn)
            else:
                cache[theta0, omega0] = _reference(egg, u0, u_dot0, T[-1])
        return cache[theta0, omega0]
    return reference


def test_the_egg_has_unequal_maxima(egg):
    """The premise: V(0) < V(π/2), the starts lie between them."""
    low, high = (float(egg.potential(u)) for u in (0.0, math.pi / 2))
    assert egg.barrier == pytest.approx(high, rel=1e-12) and low < high - 0.02 * egg.energy_scale
    for theta0, omega0 in STARTS:
        u0, u_dot0 = _start(egg, theta0, omega0)
        energy = float(_energy_closed(egg, u0, u_dot0))
        assert low < energy < high and egg.well_rim(u0) == pytest.approx(low, rel=1e-12)


@pytest.mark.parametrize('theta0, omega0', STARTS)
def test_oscillation_over_two_wells_is_the_reference_motion(egg, references, theta0, omega0):
    """Claim: the table method's closed form over several wells moves the body as Lagrange's
    equation does (DOP853 on the closed forms), conserves E, crosses the lower maximum, and
    turns where V = E (brentq on the closed-form V)."""
    motion = simulate(egg, T, theta0=theta0, omega0=omega0, method='table')
    assert motion.solver == 'oscillation'
    assert motion.energy_drift <= ENERGY_TOL
    u0, u_dot0 = _start(egg, theta0, omega0)
    ref = references(theta0, omega0)
    gap = np.max(np.abs(egg.cycle.positions(motion.phase)[0]
                        - egg.cycle.positions(ref.sol(T)[0])[0]))
    assert gap <= POSITION_TOL * egg.body.size, gap
    assert motion.phase.min() < -0.5 and motion.phase.max() > 0.5      # over u = 0
    energy = float(_energy_closed(egg, u0, u_dot0))
    closed = [brentq(lambda u: float(egg.potential(u)) - energy, *bracket, xtol=1e-15)
              for bracket in ((-math.pi / 2, -1e-3), (1e-3, math.pi / 2))]
    assert np.max(np.abs(np.array(motion.sol.turning_points) - closed)) <= TURNING_TOL


def test_period_is_the_reference_period(egg, references):
    """Claim: the closed form's period = the time between the reference's turning instants."""
    motion = simulate(egg, T, theta0=PERIOD_START[0], omega0=PERIOD_START[1], method='table')
    ref = references(*PERIOD_START)
    assert ref.t[-1] >= 2.5 * motion.sol.period
    instants = ref.t_events[0]
    assert instants.size >= 4
    period = 0.5 * (instants[2] - instants[0] + instants[3] - instants[1])
    assert abs(motion.sol.period - period) <= PERIOD_TOL * period


def test_direct_method_and_stream_agree(egg, references):
    """Claim: the direct method (DOP853 in τ) and the node's stream follow the same motion."""
    u0, u_dot0 = _start(egg, *PERIOD_START)
    ref = references(*PERIOD_START)
    direct = simulate(egg, T, theta0=PERIOD_START[0], omega0=PERIOD_START[1],
                      method='direct')
    stream = MotionStream(egg, u0, u_dot0, method='table')
    assert stream.solver == 'oscillation'
    for u in (direct.phase, stream.sample(T)[0]):
        gap = np.max(np.abs(egg.cycle.positions(u)[0] - egg.cycle.positions(ref.sol(T)[0])[0]))
        assert gap <= POSITION_TOL * egg.body.size, gap


def test_mu_required_covers_the_whole_span(egg):
    """Claim: μ_required of a free motion over the lower maximum samples every phase between
    its turning points (the start's well alone would miss u < 0)."""
    model = ContactForceModel(egg)
    u0, u_dot0 = _start(egg, 0.3, 3.0)
    energy = float(egg.energy(u0, u_dot0))
    _, u, mu = mu_required_dynamic(model, energy, u0=u0, samples=512)
    motion = simulate(egg, T, theta0=0.3, omega0=3.0, method='table')
    assert u.min() == pytest.approx(motion.sol.turning_points[0], abs=1e-2)
    assert u.max() == pytest.approx(motion.sol.turning_points[1], abs=1e-2)
    assert np.all(np.isfinite(mu))

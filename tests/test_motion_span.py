"""Oscillations over several wells (physics/motion/turning.py) of a body with unequal maxima of V.

The parallel egg's V has maxima V(0) < V(π/2): an energy between them crosses the lower
maximum and swings between two turning points around two minima. References, independent of
the table method: DOP853 on the direct closed forms (m, m′, V′ of RollingDynamics, written
here from Lagrange's equation) at rtol 1e-13 (all starts in one solve), brentq on the
closed-form V = E for the turning points, and the energy integral 2 ∫ √(m / (2 (E − V))) du
between them (adaptive quadrature of the closed forms) for the period.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.forces.validity import mu_required_dynamic
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.physics.bodies.lamina_body import LaminaBody
from twodisk_ros.physics.mass.models import centred_on_mass
from twodisk_ros.physics.motion.simulate import MotionStream, simulate

#: G's position against the DOP853 reference over the 2 s of T (one period and both turning
#: points): measured ≤ 5.7e-10 of the size (≤ 1.8e-9 over 3 s); the reference itself moves by
#: 1e-9 rad between rtol 1e-12 and 1e-13 (its m′ is a 5-point difference of the closed form
#: m, whose own energy drifts by 4e-11 M g L).
POSITION_TOL = 1e-8
#: energy conservation of the closed form, from the tables: measured ≤ 4e-14 M g L
ENERGY_TOL = 2e-13
#: period against the energy integral: measured 2.7e-13 relative (against DOP853's turning
#: instants, the reference before: 2.5e-10, their spread between half-periods 1e-10)
PERIOD_TOL = 2e-9
#: turning points against brentq on the closed-form V: measured 3e-11 rad (table vs closed V)
TURNING_TOL = 1e-9
#: (θ0, ω0) starts with energy between the two maxima: at the lower maximum (θ = 0), from
#: rest on the higher one's slope (u0 = 1.17 rad, a turning point), on both branches of u
STARTS = [(0.3, 3.0), (0.0, -2.0), (2.2, 0.0), (-0.3, -3.0)]
#: one period (1.84 s to 1.90 s for these starts) and more: every start reaches both turning
#: points and crosses u = 0 (the reference's cost grows with the span: ~2.7 s of CPU per
#: second for the four starts in one solve)
T = np.linspace(0.0, 2.0, 41)
#: the start whose period is checked, and the direct method's and the stream's motion
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


def _references(dyn, starts, t_end):
    """DOP853 on Lagrange's equation for every start at once (state [u…, u̇…], the closed
    forms evaluated on all starts in one call: one solve costs what one start's did). The
    steps are controlled by the RMS of the scaled errors over the 2 n components, so rtol and
    atol are 1e-13 / √(2 n): every component's own error estimate is then ≤ 1e-13 relative,
    as when each start was integrated alone at rtol 1e-13."""
    u0, u_dot0 = np.array([_start(dyn, *start) for start in starts]).T
    n = len(starts)

    def rhs(t, y):
        u, u_dot = y[:n], y[n:]
        m, dm = dyn.effective_mass_jet(u)
        return np.concatenate([u_dot, -(dyn.potential_slope(u) + 0.5 * dm * u_dot**2) / m])
    tol = 1e-13 / math.sqrt(2 * n)
    sol = solve_ivp(rhs, (0.0, t_end), np.concatenate([u0, u_dot0]), method='DOP853',
                    rtol=tol, atol=tol, dense_output=True).sol
    return {start: (lambda t, k=k: sol(t)[k]) for k, start in enumerate(starts)}


@pytest.fixture(scope='module')
def references(egg):
    """start -> u(t) (rad) of the DOP853 reference over T, all starts in one solve, built once
    for the module."""
    return _references(egg, STARTS, T[-1])


def _turning_points(dyn, energy):
    """The turning points V(u) = E on either side of u = 0 (brentq on the closed-form V)."""
    return [brentq(lambda u: float(dyn.potential(u)) - energy, *bracket, xtol=1e-15)
            for bracket in ((-math.pi / 2, -1e-3), (1e-3, math.pi / 2))]


def _period_from_the_energy_integral(dyn, energy):
    """T = 2 ∫ √(m / (2 (E − V))) du between the turning points (s), by adaptive quadrature of
    the closed forms m and V, in u = c + r sin φ (the turning points' inverse square roots
    become a smooth integrand over φ ∈ [−π/2, π/2]; no table, no solver of the package)."""
    low, high = _turning_points(dyn, energy)
    centre, radius = 0.5 * (high + low), 0.5 * (high - low)

    def integrand(phi):
        u = centre + radius * math.sin(phi)
        gap = energy - float(dyn.potential(u))
        return math.sqrt(float(dyn.effective_mass(u)) / (2 * gap)) * radius * math.cos(phi)
    half, error = quad(integrand, -math.pi / 2, math.pi / 2, epsabs=0.0, epsrel=1e-13,
                       limit=200)
    return 2 * half, 2 * error


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
    ref = references[theta0, omega0]
    gap = np.max(np.abs(egg.cycle.positions(motion.phase)[0]
                        - egg.cycle.positions(ref(T))[0]))
    assert gap <= POSITION_TOL * egg.body.size, gap
    assert motion.phase.min() < -0.5 and motion.phase.max() > 0.5      # over u = 0
    energy = float(_energy_closed(egg, u0, u_dot0))
    closed = _turning_points(egg, energy)
    assert np.max(np.abs(np.array(motion.sol.turning_points) - closed)) <= TURNING_TOL


def test_period_is_the_reference_period(egg):
    """Claim: the closed form's period = the energy integral's over the whole swing (both
    wells), 2 ∫ √(m / (2 (E − V))) du between the turning points."""
    motion = simulate(egg, T, theta0=PERIOD_START[0], omega0=PERIOD_START[1], method='table')
    u0, u_dot0 = _start(egg, *PERIOD_START)
    period, error = _period_from_the_energy_integral(egg, float(_energy_closed(egg, u0, u_dot0)))
    assert error <= 1e-3 * PERIOD_TOL * period       # the reference is resolved
    assert abs(motion.sol.period - period) <= PERIOD_TOL * period


def test_direct_method_and_stream_agree(egg, references):
    """Claim: the direct method (DOP853 in τ) and the node's stream follow the same motion."""
    u0, u_dot0 = _start(egg, *PERIOD_START)
    ref = references[PERIOD_START]
    direct = simulate(egg, T, theta0=PERIOD_START[0], omega0=PERIOD_START[1],
                      method='direct')
    stream = MotionStream(egg, u0, u_dot0, method='table')
    assert stream.solver == 'oscillation'
    for u in (direct.phase, stream.sample(T)[0]):
        gap = np.max(np.abs(egg.cycle.positions(u)[0] - egg.cycle.positions(ref(T))[0]))
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

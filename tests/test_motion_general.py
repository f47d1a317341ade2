"""Motions of any RollingBody (physics/motion/integrate.py, closed_forms.py) against the ellipse's own motions.

The reference body is an ellipse seen through another phase (tests/reparametrised_body.py),
smooth or degenerate (the body does not turn in u at v = 0, π: m = 0, u̇ infinite there). Its
motion in time is the ellipse's: G's world position at each sample must agree with the
ellipse path's (closed forms, paper) through every method and mode.
"""

import numpy as np
import pytest

from reparametrised_body import ReparametrisedBody
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.mass.models import laminae
from twodisk_ros.physics.motion.simulate import simulate

BASE = (1.0, 1.6, 0.4)
#: G's position, closed-form solutions (quadrature, libration, rest) of both paths: measured
#: ≤ 1.4e-14 of the size (docs ≤ 1e-12; issue 20 asks ≤ 1e-11 of the size).
CLOSED_TOL = 1e-12
#: where a path integrates (DOP853 at rtol 1e-10 in u or in τ): both paths' own integration
#: errors, measured ≤ 1.2e-8 of the size over 3 s (0.6 s of which at 6 rad/s).
ODE_TOL = 3e-8
#: (θ0 (rad), ω0 (rad/s), span (s)). The two oscillations (period 3.29 s) run 3 s: each
#: passes both turning points and, on the degenerate double, crosses its stop at v = 0 from
#: both sides (the second start begins on it). Rolling over at 6 rad/s, 1.2 s takes u from
#: 0.45 past π (the degenerate double's other stop, v = π) to ~4.9 rad: the same branches
#: (a stop crossed while rolling over, the smooth double's features at speed) as the 3 s it
#: ran before, at two fifths of the right-hand sides (~2000 over 3 s in each of the 8 runs).
STARTS = [(0.3, 0.0, 3.0), (0.0, 1.0, 3.0), (0.2, 6.0, 1.2)]


@pytest.fixture(scope='module')
def bodies():
    base = EllipseBody(*BASE)
    mass = laminae(*BASE, 2.0)
    return RollingDynamics(base, mass), {kind: RollingDynamics(ReparametrisedBody(base, kind),
                                                               mass)
                                         for kind in ('smooth', 'degenerate')}


@pytest.fixture(scope='module')
def ellipse_motions(bodies):
    """(mode, method, θ0, ω0) -> the ellipse path's motion over its span, computed once for
    both doubles (the direct dynamic one at 6 rad/s costs seconds)."""
    reference, _ = bodies
    cache = {}

    def motion(mode, method, theta0, omega0, span):
        key = (mode, method, theta0, omega0, span)
        if key not in cache:
            cache[key] = simulate(reference, sample_times(span), mode=mode, theta0=theta0,
                                  omega0=omega0, method=method)
        return cache[key]
    return motion


def sample_times(span):
    """Samples every 0.1 s over [0, span] (s)."""
    return np.linspace(0.0, span, int(round(span / 0.1)) + 1)


@pytest.mark.parametrize('kind', ['smooth', 'degenerate'])
@pytest.mark.parametrize('mode', ['dynamic', 'kinematic'])
@pytest.mark.parametrize('method', ['table', 'direct'])
def test_motion_in_time_is_the_ellipse_motion(bodies, ellipse_motions, kind, mode, method):
    """Claim: the general path moves the body as the ellipse path does, also starting
    exactly where the body does not turn in u (θ = 0 on the degenerate double)."""
    reference, doubles = bodies
    dynamics = doubles[kind]
    for theta0, omega0, span in STARTS:
        ref = ellipse_motions(mode, method, theta0, omega0, span)
        got = simulate(dynamics, sample_times(span), mode=mode, theta0=theta0, omega0=omega0, method=method)
        gap = np.max(np.abs(reference.cycle.positions(ref.phase)[0]
                            - dynamics.cycle.positions(got.phase)[0]))
        closed = got.solver != 'DOP853' and ref.solver != 'DOP853'
        assert gap <= (CLOSED_TOL if closed else ODE_TOL) * reference.body.size, (
            theta0, omega0, got.solver, ref.solver, gap)


def test_periods_are_the_ellipse_periods(bodies):
    """Claim: small-oscillation periods, T = 2π √(J / (M g d²z_G/dγ²)) for any body, equal
    the ellipse's 2π √(m / V″) also where m = V″ = 0 in u (relative, measured ≤ 6e-14)."""
    reference, doubles = bodies
    expected = [p for _, p in reference.equilibria_with_periods()]
    for dynamics in doubles.values():
        got = [p for _, p in dynamics.equilibria_with_periods()]
        assert [p is None for p in got] == [p is None for p in expected]
        for p, q in zip(got, expected):
            if q is not None:
                assert abs(p - q) <= 2e-13 * q


#: LaminaBody(Ellipse) against the ellipse's closed forms (table method, closed-form
#: solutions): G measured ≤ 1.1e-12 of the size; small-oscillation periods ≤ 2.5e-11 relative
#: (LaminaBody's tables, docs: ≤ 1e-10)
LAMINA_TOL, LAMINA_PERIOD_RTOL = 5e-12, 1e-10


@pytest.mark.parametrize('mode', ['dynamic', 'kinematic'])
def test_lamina_body_of_an_ellipse_moves_as_the_ellipse(bodies, mode):
    """Claim: the general path on LaminaBody(Ellipse) (the lamina's support function, not the
    ellipse's closed forms) moves the body as the ellipse path does, with its periods."""
    from twodisk_ros.physics.bodies.lamina_body import LaminaBody
    reference, _ = bodies
    dynamics = RollingDynamics(LaminaBody(reference.body.lamina, reference.body.delta),
                               reference.mass)
    t = np.linspace(0.0, 3.0, 31)
    for theta0, omega0, _ in STARTS:
        ref = simulate(reference, t, mode=mode, theta0=theta0, omega0=omega0)
        got = simulate(dynamics, t, mode=mode, theta0=theta0, omega0=omega0)
        assert got.solver == ref.solver != 'DOP853'
        gap = np.max(np.abs(reference.cycle.positions(ref.phase)[0]
                            - dynamics.cycle.positions(got.phase)[0]))
        assert gap <= LAMINA_TOL * reference.body.size, (theta0, omega0, gap)
    for (_, p), (_, q) in zip(dynamics.equilibria_with_periods(),
                              reference.equilibria_with_periods()):
        assert (p is None) == (q is None) and (q is None or abs(p - q) <= LAMINA_PERIOD_RTOL * q)

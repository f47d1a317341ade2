"""The batched sweep path (twodisk_ros.sweep.batch.Ellipses through sweep.chunks.quantities)
against the library's scalar path.

Reference: :func:`~twodisk_ros.sweep.quantities.body_quantities`, the library's scalar calls
made body by body (one call per quantity), never the batch's own formulas; the oscillation
period also against the paper's closed forms of V″ at θ = 0 and θ = π/2 (tests/paper_forms.py),
which are exact near the neutral line, where the scalar path's spectral V″ is not.
Bodies: a seeded sample of the allowed range, the edges b/a ∈ {0.01, 100},
Δ/a ∈ {1e-3, 1 − 1e-6} (each of the four extremes once), the neutral line
b² − 2a² + 2Δ² = 0, masked bodies; both mass models.
"""

import math

import numpy as np
import pytest

from paper_forms import curvature_at_half_pi, curvature_at_theta0
from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.cycle import RollingCycle
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.mass.models import mass_properties
from twodisk_ros.sweep import batch
from twodisk_ros.sweep.batch import Ellipses
from twodisk_ros.sweep.chunks import chunk_bodies, quantities
from twodisk_ros.sweep.quantities import VARIABLES, body_quantities

#: Every quantity against the scalar path, relative (the issue's bound). Measured ≤ 5e-12
#: over the seeded sample (liftoff_speed and mu_required, whose tables hold spectral
#: derivatives; the closed forms and quadratures ≤ 1e-14).
RTOL = 1e-10
#: Lift-off speed and μ_required at the extreme shapes (b/a = 0.01 or 100): the scalar path
#: itself moves by up to 1.4e-9 there when only its table size changes (4 → 8 × resolution,
#: or a doubled cycle resolution: spectral derivatives of rounding noise); measured batch
#: against scalar ≤ 3.6e-9.
EDGE_RTOL = {'liftoff_speed': 1e-8, 'mu_required': 1e-8}
#: Oscillation period against the paper's V″ (T = 2π √(m(u*) / (V″_θ (dθ/du)²))): measured
#: ≤ 2e-15 everywhere, also within 1e-8 a² of the neutral line.
PAPER_RTOL = 1e-13

#: The edges for the laminae: every b/a extreme and every Δ/a extreme once. The reference
#: (the scalar path) costs 1.5-9 s of CPU per edge body (measured: (0.01, 1e-3) 8.7 s,
#: (0.01, 1 − 1e-6) 4.0 s, (100, 1e-3) 3.7 s, (100, 1 − 1e-6) 1.5 s), so the pair that
#: holds all four extremes at the least cost; the fourth corner combines two extremes that
#: each are checked here.
EDGES = [(0.01, 1 - 1e-6), (100.0, 1e-3)]
#: The edges for the solid model: both b/a extremes (the mass model only changes the
#: inertia, whose ratio to the laminae's depends on b/a), at the cheaper Δ/a extreme.
SOLID_EDGES = [(0.01, 1 - 1e-6), (100.0, 1 - 1e-6)]
#: Bodies the scalar path refuses at its first stage, with the reason it gives.
MASKED = [(1.0, 1.0), (0.5, 1.5), (math.nan, 0.3), (1.0, -0.2), (-1.0, 0.3), (1e300, 0.5)]


def _sample(seed=20231, size=10):
    """b/a log-uniform in [0.05, 20], Δ/a uniform in [0.01, 0.99], and three points on the
    neutral line b² = 2 (1 − Δ²)."""
    rng = np.random.default_rng(seed)
    b = np.exp(rng.uniform(math.log(0.05), math.log(20.0), size))
    d = rng.uniform(0.01, 0.99, size)
    neutral_d = np.array([0.05, 0.5, 0.9])
    return (np.concatenate([b, np.sqrt(2.0 - 2.0 * neutral_d**2)]),
            np.concatenate([d, neutral_d]))


def _paper_period(b, d, mass_model):
    """2π √(m(u*) / V″(u*)) with V″(u*) = V″_θ(θ*) (dθ/du)², V″_θ from the paper's closed
    forms and dθ/du from the phase's definition (tan θ = (b/a) tan(η_max sin u)): dθ/du =
    (b/a) η_max at θ* = 0 (u* = 0), (a/b) η_max cos u* at θ* = π/2; m(u*) is the library's
    closed form (RollingDynamics.effective_mass; the cycle's tables are not used)."""
    body = EllipseBody(1.0, b, d)
    dyn = RollingDynamics(body, mass_properties(mass_model, 1.0, b, d, 1.0), 1.0,
                          cycle=RollingCycle(body, resolution=512))
    if body.stability_margin > 0:
        u_star, stiffness = 0.0, curvature_at_theta0(1.0, b, d) * (b * body.eta_max) ** 2
    else:
        u_star = math.asin(math.pi / 2 / body.eta_max)
        stiffness = curvature_at_half_pi(1.0, b, d) * (body.eta_max * math.cos(u_star) / b) ** 2
    return 2 * math.pi * math.sqrt(float(dyn.effective_mass(u_star)) / stiffness)


def _agree(got, want, rtol):
    """Relative agreement; 0, inf and NaN exactly."""
    if not math.isfinite(want) or want == 0.0:
        return got == want or (math.isnan(got) and math.isnan(want))
    return abs(got - want) <= rtol * abs(want)


def _check(result, b, d, mass_model, edge=False):
    """Every quantity of every body of ``result`` against the scalar path (and the period
    against the paper's V″)."""
    for k, (bk, dk) in enumerate(zip(b, d)):
        values, failure = body_quantities(bk, dk, mass_model)
        where = (mass_model, float(bk), float(dk))
        assert result['failure'][k] == failure, where
        for name in VARIABLES:
            got, want = float(result[name][k]), values[name]
            if name == 'oscillation_period' and not failure and math.isfinite(want):
                # claim: the batch's V″(u*) is exact to rounding (paper's closed form)
                assert _agree(got, _paper_period(bk, dk, mass_model), PAPER_RTOL), where
                # and so is the per-body path's since equilibria() takes V″_θ (dθ/du)² too:
                # compared at RTOL also on the neutral line and at the edges
            rtol = EDGE_RTOL.get(name, RTOL) if edge else RTOL
            assert _agree(got, want, rtol), (where, name, got, want)


@pytest.mark.parametrize('mass_model', ['laminae', 'solid'])
def test_batch_equals_the_scalar_path_on_a_sample(mass_model):
    b, d = _sample()
    b = np.concatenate([b, [m[0] for m in MASKED]])
    d = np.concatenate([d, [m[1] for m in MASKED]])
    result = quantities(Ellipses(b, d), mass_model)
    assert set(result) == set(VARIABLES) | {'failure'}
    assert all(result[name].dtype == np.float64 and result[name].shape == b.shape
               for name in VARIABLES)
    _check(result, b, d, mass_model)
    # the neutral line: z_G constant, family 0 (both paths)
    assert np.all(result['stable_family'][-len(MASKED) - 3:-len(MASKED)] == 0)
    # masked bodies: every quantity NaN and the scalar path's own one-line reason
    for k in range(b.size - len(MASKED), b.size):
        assert result['failure'][k].startswith('body: ')
        assert all(math.isnan(result[name][k]) for name in VARIABLES)


@pytest.mark.slow
@pytest.mark.parametrize('mass_model, edges', [('laminae', EDGES), ('solid', SOLID_EDGES)])
def test_batch_equals_the_scalar_path_at_the_edges(mass_model, edges):
    b, d = np.array(edges).T
    _check(quantities(Ellipses(b, d), mass_model), b, d, mass_model, edge=True)


def test_near_the_neutral_line_the_period_is_the_papers():
    # |b² − 2a² + 2Δ²| from 1e-8 to 1e-3 on both sides (outside the neutral tolerance 1e-9)
    d = 0.3
    margins = np.array([1e-3, 1e-5, 1e-8, -1e-8, -1e-5, -1e-3])
    b = np.sqrt(2.0 - 2.0 * d * d + margins)
    result = quantities(Ellipses(b, np.full(b.size, d)))
    assert np.all(result['stable_family'] == np.sign(margins))
    for k in range(b.size):
        assert _agree(result['oscillation_period'][k], _paper_period(b[k], d, 'laminae'),
                      PAPER_RTOL), margins[k]


def test_near_the_neutral_line_the_scalar_period_is_the_papers_too():
    # the per-body path (equilibria(): V″(u*) = V″_θ (dθ/du)² at θ = 0, ±π/2) is exact there
    # too; its spectral derivative of dz_G/du was 2e-5 off at |b² − 2a² + 2Δ²| = 1e-6 a²
    d = 0.3
    for margin in (1e-4, 1e-6, -1e-6, -1e-4):
        b = math.sqrt(2.0 - 2.0 * d * d + margin)
        values, failure = body_quantities(b, d)
        assert failure == ''
        assert _agree(values['oscillation_period'], _paper_period(b, d, 'laminae'),
                      PAPER_RTOL), margin


def test_results_do_not_depend_on_the_batch():
    # a body's bits are the same alone, in any chunk, and in a task's batch (exponent 2)
    b = np.array([0.5, 1.0, 1.5, 2.5, 0.3, 1.2])
    d = np.array([0.25, 0.5, 0.75, 0.9, 0.2, 0.6])
    whole = quantities(chunk_bodies(b, d))
    for size in (1, 4):
        for start in range(0, b.size, size):
            part = quantities(Ellipses(b[start:start + size], d[start:start + size]))
            for name in VARIABLES:
                np.testing.assert_array_equal(part[name], whole[name][start:start + size],
                                              err_msg=name)


def test_a_body_the_batch_cannot_finish_goes_through_the_scalar_path(monkeypatch):
    # the batch hands a body whose values are not all finite to the scalar path: its values
    # and failure are then the scalar path's, bit for bit
    real = batch._block

    def spoiled(bodies, *args):
        values, good = real(bodies, *args)
        values['cycle_time'] = values['cycle_time'].copy()
        values['cycle_time'][0] = math.nan
        return values, good & ~np.isnan(values['cycle_time'])

    monkeypatch.setattr(batch, '_block', spoiled)
    timings = {}
    result = quantities(Ellipses([1.0, 2.0], [0.5, 0.3]), timings=timings)
    values, failure = body_quantities(1.0, 0.5)
    assert result['failure'][0] == failure == ''
    assert all(result[name][0] == values[name] or math.isnan(values[name])
               for name in VARIABLES)
    assert timings['scalar'] > 0 and set(timings) <= set(batch.BATCH_STAGES)


def test_liftoff_refinement_reaches_a_minimum_between_nodes():
    # the sweep's bodies have their lift-off minima at symmetric phases (nodes); here a
    # minimum of -N0/N2 between nodes, against scipy's bounded Brent on the exact functions
    from scipy.optimize import minimize_scalar
    from twodisk_ros.physics.forces.validity import liftoff_speed_batch

    def columns(u):
        n0 = np.stack([1.2 + 0.4 * np.cos(u - 0.3137), 1.5 + 0.2 * np.cos(3 * u)])
        n2 = np.stack([-(1.0 + 0.5 * np.sin(2 * u + 0.41)), -0.8 + 0 * u])
        return n0, n2

    n = 512
    u = 2 * math.pi * np.arange(n) / n
    n0, n2 = columns(u)
    ratio = lambda x: float(-columns(x)[0][0] / columns(x)[1][0])    # noqa: E731
    guess = u[np.argmin(-n0[0] / n2[0])]
    found = minimize_scalar(ratio, bounds=(guess - 0.1, guess + 0.1), method='bounded',
                            options={'xatol': 1e-12})
    assert abs(found.x - guess) > 0.1 * 2 * math.pi / n      # between nodes
    # claim: Newton on the quintic Hermite interpolant (on 512 nodes within ~1e-14 of
    # these trigonometric columns: h⁶ f⁽⁶⁾/46080) reaches the true minimum: 1e-12 relative
    got = liftoff_speed_batch(n0[:, :, None], n2[:, :, None])
    assert got[0] == pytest.approx(math.sqrt(found.fun), rel=1e-12)
    node_only = liftoff_speed_batch(n0[:, :, None], n2[:, :, None], iterations=0)
    assert abs(node_only[0] - got[0]) > 1e-9 * got[0]      # the refinement matters here


def test_a_block_that_raises_goes_through_the_scalar_path(monkeypatch):
    # masks instead of exceptions: a block failing for any reason loses no body
    def broken(*args):
        raise FloatingPointError('a numpy error in the block')

    monkeypatch.setattr(batch, '_block', broken)
    result = quantities(Ellipses([1.0, 1.0], [0.5, 2.0]))
    values, failure = body_quantities(1.0, 0.5)
    assert result['failure'] == ['', body_quantities(1.0, 2.0)[1]] and failure == ''
    assert all(result[name][0] == values[name] for name in VARIABLES
               if not math.isnan(values[name]))


def test_cycle_samples_are_the_scalar_bodys_closed_forms():
    # EllipseBodies.cycle_samples against EllipseBody body by body: values are the same
    # closed forms (measured ≤ 3.5e-16 of the largest; bitwise at the edges), and ω_u, whose
    # u-derivatives of n and t1 are closed forms in the batch, against the scalar body's
    # complex step (measured ≤ 3.1e-13 of max |ω_u| at b/a = 0.01, ≤ 3e-15 elsewhere)
    from twodisk_ros.physics.bodies.ellipse_batch import EllipseBodies
    b = np.array([0.01, 0.01, 100.0, 100.0, 1.0, 0.3])
    d = np.array([1e-3, 1 - 1e-6, 1e-3, 1 - 1e-6, 0.5, 0.2])
    n = 4096
    samples = EllipseBodies(1.0, b, d).cycle_samples(n)
    u = 2 * math.pi * np.arange(n) / n
    for k in range(b.size):
        body = EllipseBody(1.0, b[k], d[k])
        geo = body.phase_geometry(u)
        for got, want in ((samples.contact_a[:, :, k].T, geo.contact_a),
                          (samples.contact_b[:, :, k].T, geo.contact_b),
                          (samples.ground_normal[:, :, k].T, geo.ground_normal),
                          (samples.height[:, k], geo.height),
                          (samples.turn_rate[:, k], body.phase_rates(u)[1])):
            # the same closed forms by other code (arrays of bodies): 16 ulps of the largest
            assert np.max(np.abs(got - want)) <= ulps(16, np.max(np.abs(want))), (b[k], d[k])
        omega = body.phase_angular_velocity(u)
        got = samples.angular_velocity[:, :, k].T
        assert np.max(np.abs(got - omega)) <= 1e-12 * np.max(np.abs(omega)), (b[k], d[k])

"""Contact forces of bodies other than EllipseBody, against independent references.

* Newton–Euler with finite differences in time of the simulated poses (G's position, the
  orientation), solved for (N_A, N_B, T_A, T_B, S, τ): ``newton_euler_forces`` of
  tests/test_contact_forces.py, which never calls the force module;
* the test double (tests/reparametrised_body.py): the ellipse seen through u = g(v), also
  the degenerate g′ = 0 where the body stops turning in v: the same physical states must
  have the ellipse's forces;
* LaminaBody(Ellipse) against EllipseBody at the same contact angle θ;
* at a superellipse's flat vertex (n = 4) the growth N − N(Ω = 0) ∝ |γ − γ0|^(q − 2),
  q = n/(n − 1), of docs/physics.md#contact-forces, γ the body's turn integrated here from
  |ω_u| by scipy's quad.

Units SI; MASS and GRAVITY as in test_contact_forces.py; tolerances relative to M g.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from reparametrised_body import ReparametrisedBody
from test_contact_forces import GRAVITY, MASS, newton_euler_forces
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.forces.validity import (
    check_validity, liftoff_speed, mu_required_dynamic, mu_required_kinematic)
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.physics.laminae.shapes import Ellipse, Superellipse
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.physics.bodies.lamina_body import LaminaBody
from twodisk_ros.physics.mass.models import laminae, laminae_of

TWO_PI = 2 * math.pi
FIGURE3 = (0.2, 0.1, 0.1)
#: the double against the ellipse at the same states (relative to M g; torque to M g L):
#: measured ≤ 5.8e-13 (kinematic, dynamic, general; also at the stops), μ ≤ 3.2e-13 M g/N_min
DOUBLE_ATOL = 1e-12
#: Newton–Euler by 5-point differences of poses (test_contact_forces: the differences' own
#: error ≤ 2.3e-9 M g for ellipses); measured here ≤ 5.1e-10 on the double, ≤ 9.7e-10 on
#: the egg and the ellipse LaminaBody, 3.4e-9 on the superellipse n = 4 (its tables' tail
#: 2.9e-10, and poses up to 20 M g near its flat vertices)
FD_ATOL = 1e-8
#: LaminaBody(Ellipse) against EllipseBody at equal θ: LaminaBody's tables (its tail
#: 1.2e-13) and the matching of θ; measured ≤ 9.3e-14 M g
LAMINA_ATOL = 5e-13

_MODELS = {}


def ellipse_model():
    return model_of(EllipseBody(*FIGURE3), laminae(*FIGURE3, MASS))


def model_of(body, mass):
    key = repr(body)
    if key not in _MODELS:
        _MODELS[key] = ContactForceModel(RollingDynamics(body, mass, gravity=GRAVITY))
    return _MODELS[key]


def double(kind):
    base = EllipseBody(*FIGURE3)
    return model_of(ReparametrisedBody(base, kind), laminae(*FIGURE3, MASS))


SHAPES = {'egg': (Egg(0.1, 0.08, 0.005), 0.05), 'superellipse4': (Superellipse(0.1, 0.1, 4.0),
                                                                 0.05),
          'ellipse': (Ellipse(0.2, 0.1), 0.1)}


def lamina_model(name):
    lamina, delta = SHAPES[name]
    return model_of(LaminaBody(lamina, delta), laminae_of(lamina, delta, 'parallel', MASS))


def stops(model):
    """Phases (rad) where the body does not turn (s = 0 at the table nodes)."""
    return model.terms.u[model.terms.s == 0]


NAMES = ('normal_a', 'normal_b', 'tangential_a', 'tangential_b', 'along_ab', 'drive_torque',
         'mu_required')


def assert_same(a, b, atol, scale):
    """Forces within atol·M g (τ: M g L); μ_required within atol·M g/min(N_A, N_B) (an error
    δF moves μ by ~δF/N_min)."""
    for name in NAMES:
        x, y = getattr(a, name), getattr(b, name)
        tol = atol * scale
        if name == 'mu_required':
            tol = tol / np.minimum(b.normal_a, b.normal_b)
        assert np.all(np.abs(x - y) <= tol), (name, np.max(np.abs(x - y)) / scale)


# ------------------------------------------------------------------------ the test double
@pytest.mark.parametrize('kind', ['smooth', 'degenerate'])
def test_double_has_the_ellipse_forces_at_the_same_states(kind):
    ref, model = ellipse_model(), double(kind)
    body = model.body
    v = np.concatenate([np.linspace(-1.0, 7.5, 1201), [0.0, 1e-9, 1e-5, math.pi, -1e-7]])
    u = body.g(v)
    scale = ref.weight
    for omega in (0.0, 3.0, 7.0):
        assert_same(model.kinematic(v, omega), ref.kinematic(u, omega), DOUBLE_ATOL, scale)
    w = 2.5
    assert_same(model.dynamic(v, angular_speed=w),
                ref.dynamic(u, w / ref.dynamics.angular_speed_per_phase(u)), DOUBLE_ATOL, scale)
    # (v̇, v̈) ↔ (u̇, ü) = (g′ v̇, g′ v̈ + g″ v̇²), g″ = −4ε… : 2ε·(−2 sin 2v)
    v_dot, v_ddot = 1.7, -0.8
    g2 = -4 * body.epsilon * np.sin(2 * v)
    assert_same(model.forces(v, v_dot, v_ddot),
                ref.forces(u, body.g_prime(v) * v_dot, body.g_prime(v) * v_ddot + g2 * v_dot**2),
                DOUBLE_ATOL, scale)
    assert liftoff_speed(model)[0] == pytest.approx(liftoff_speed(ref)[0], rel=1e-12)


@pytest.mark.parametrize('kind, mode, omega0, theta0', [
    ('degenerate', 'kinematic', 4.0, 0.0),     # starts where the body stops turning in v
    ('degenerate', 'dynamic', 6.0, 0.0),
    ('smooth', 'dynamic', 1.0, 1.2),
])
def test_double_against_newton_euler(kind, mode, omega0, theta0):
    model = double(kind)
    centres = np.array([0.01, 0.23, 0.61, 0.97])
    reference, forces = newton_euler_forces(model, mode, omega0, theta0, centres)
    for j, name in enumerate(NAMES[:6]):
        assert np.max(np.abs(forces[name] - reference[:, j])) <= FD_ATOL * model.weight * (
            model.body.size if name == 'drive_torque' else 1.0), name


# ------------------------------------------------------------------------------ LaminaBody
@pytest.mark.parametrize('name, mode, omega0, theta0', [
    ('egg', 'kinematic', 4.0, 0.3),
    ('egg', 'dynamic', 6.0, 0.2),
    ('superellipse4', 'kinematic', 2.0, 0.2),
    ('ellipse', 'dynamic', 5.0, 0.0),
])
def test_lamina_body_against_newton_euler(name, mode, omega0, theta0):
    model = lamina_model(name)
    centres = np.linspace(0.02, 0.5, 7)
    reference, forces = newton_euler_forces(model, mode, omega0, theta0, centres)
    # a superellipse's flat vertex: forces infinite there; compare only away from the stops
    keep = np.isfinite(forces['normal_a']) & np.isfinite(forces['normal_b'])
    keep &= np.abs(forces['normal_a']) + np.abs(forces['normal_b']) < 20 * model.weight
    assert np.sum(keep) >= 4
    for j, quantity in enumerate(NAMES[:6]):
        error = np.abs(forces[quantity][keep] - reference[keep, j])
        assert np.max(error) <= FD_ATOL * model.weight * (
            model.body.size if quantity == 'drive_torque' else 1.0), quantity


def test_lamina_ellipse_matches_two_disk_body():
    lamina_bodied, ref = lamina_model('ellipse'), ellipse_model()
    u = np.linspace(-1.2, 1.2, 97)                     # branch +1, away from the turning points
    theta = lamina_bodied.body.phase_angles_with_rates(u)[0]
    u_ref = ref.body.phase_from_theta(theta, 1)
    for omega in (0.0, 4.0):
        assert_same(lamina_bodied.kinematic(u, omega), ref.kinematic(u_ref, omega),
                    LAMINA_ATOL, ref.weight)
    assert liftoff_speed(lamina_bodied)[0] == pytest.approx(liftoff_speed(ref)[0], rel=1e-9)


# --------------------------------------------------------------------------- flat vertices
def test_flat_vertex_force_grows_as_the_turn_power():
    """N − N(Ω = 0) ∝ |γ − γ0|^(q − 2) next to a flat vertex (q = 4/3 for n = 4)."""
    model = lamina_model('superellipse4')
    body = model.body
    u0 = float(stops(model)[0])

    def turn(u):
        return quad(lambda x: np.linalg.norm(body.phase_angular_velocity(np.array(x))), u0, u,
                    epsabs=1e-16, epsrel=1e-12)[0]
    deltas = np.array([1e-2, 3e-3, 1e-3])
    gammas = np.abs([turn(u0 + d) for d in deltas])
    omega = 2.0
    total = [model.kinematic(u0 + d, omega) for d in deltas]
    rest = [model.kinematic(u0 + d, 0.0) for d in deltas]
    excess = np.array([abs(f.normal_a + f.normal_b - r.normal_a - r.normal_b)
                       for f, r in zip(total, rest)])
    slopes = np.diff(np.log(excess)) / np.diff(np.log(gammas))
    q = 4.0 / 3.0
    assert np.all(np.abs(slopes - (q - 2)) < 0.05), slopes


@pytest.mark.parametrize('name', ['superellipse4', 'egg'])
def test_no_nan_anywhere_and_infinite_only_at_stops(name):
    model = lamina_model(name)
    u = np.concatenate([TWO_PI * np.arange(2048) / 2048, stops(model)])
    at_stop = np.isin(u, stops(model))
    for forces in (model.kinematic(u, 3.0), model.dynamic(u, angular_speed=3.0),
                   model.kinematic(u, 0.0)):
        for quantity in NAMES + ('along_a', 'along_b', 'ratio_a', 'ratio_b'):
            x = getattr(forces, quantity)
            assert not np.any(np.isnan(x)), quantity
        for vector in (forces.force_a, forces.force_b):
            assert not np.any(np.isnan(vector))
        finite = np.isfinite(forces.normal_a) & np.isfinite(forces.normal_b)
        assert np.all(finite[~at_stop])
    if name == 'superellipse4':
        assert not np.any(np.isfinite(model.kinematic(stops(model), 3.0).normal_a))


def test_liftoff_at_a_flat_vertex_at_any_speed():
    """Where the singular normal force at a stop is negative, any Ω > 0 lifts the contact:
    Ω_c = 0, and a driven motion through that phase is reported invalid there."""
    model = lamina_model('superellipse4')
    speed, phase, contact = liftoff_speed(model)
    assert speed == 0.0
    forces = model.kinematic(phase, 1e-3)
    normal = forces.normal_a if contact == 'A' else forces.normal_b
    assert normal == -np.inf and forces.mu_required == np.inf
    report = check_validity(np.array([0.0, 1.0]), model.kinematic(np.array([phase - 0.3, phase]),
                                                                   1e-3))
    assert report.kind == f'lift-off {contact}' and report.index == 1
    assert math.isinf(mu_required_kinematic(model, 1e-3))


def test_egg_liftoff_speed_against_a_dense_sweep():
    model = lamina_model('egg')
    speed, _, _ = liftoff_speed(model)
    u = np.linspace(0, TWO_PI, 20001)
    below, above = model.kinematic(u, speed * (1 - 1e-6)), model.kinematic(u, speed * (1 + 1e-4))
    assert np.all(below.normal_a > 0) and np.all(below.normal_b > 0)
    assert np.any(above.normal_a < 0) or np.any(above.normal_b < 0)
    peak, _, mu = mu_required_dynamic(model, model.dynamics.barrier + 0.05 * MASS * GRAVITY
                                      * model.body.size)
    assert math.isfinite(peak) and not np.any(np.isnan(mu))

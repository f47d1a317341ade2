"""Tests of the contact forces and the validity checks against independent references.

Nothing here compares the module with its own output. The references are:

* Newton's law for the whole body, M a_G = F_A + F_B − M g e_z, with a_G from finite
  differences in time of G's world position along a simulated motion (``simulate`` and
  ``RollingCycle.positions``);
* Euler's law about G, dH_G/dt = Σ (P − G) × F_P (+ τ ê with a drive), with H_G = R I_G Rᵀ ω
  and ω from finite differences of the orientation (log of R(t + s) R(t)ᵀ), not from
  ``phase_angular_velocity``;
* the energy balance of the drive, τ ê·ω = dE/dt = u̇ (m ü + ½ m′ u̇² + V′) from the
  dynamics tables;
* statics: at rest the forces are vertical and split by the lever rule along AB, built
  here from the world positions of A, B and G;
* the symmetries of the body: the mirror image (u → π − u) and the disk swap
  x ↦ (x3, −x2, x1), whose phase map is found here by matching contact vectors;
* N_A, N_B, T_A, T_B, S and τ solved from those two laws (six linear equations) with the
  finite differences, and μ_required from them by bisection on the friction cones
  (``least_friction``: the least μ for which the two cones' intervals along AB meet), not by
  the module's squeeze formula;
* brute force: the lift-off speed against a dense sweep of the cycle.

Units: SI (m, kg, s, rad, N). Tolerances are relative to M g (forces) or M g L (moments,
L = body size), stated with each constant.
"""

import math
import os

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from numpy.testing import assert_allclose
from scipy.spatial.transform import Rotation

from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics import RollingDynamics, simulate
from twodisk_ros.physics.stability.equilibria import STABLE, equilibria
from twodisk_ros.physics.mass.models import mass_properties
from twodisk_ros.physics.forces.contact import ContactForceModel, squeeze_split
from twodisk_ros.physics.forces.validity import (
    check_validity, liftoff_speed, motion_validity, mu_required_dynamic, mu_required_kinematic)

MASS = 1.3        # kg: not 1, so a missing factor M shows
GRAVITY = 9.81    # m/s²
TWO_PI = 2 * math.pi

OLOID = (0.1, 0.1, 0.05)                   # (a, b, Δ) in m
TCR = (0.1, 0.1, 0.1 / math.sqrt(2))
FIGURE3 = (0.2, 0.1, 0.1)                  # the paper's figure-3 body (config/figure3.yaml)
FAT = (0.1, 0.2, 0.05)                     # b² − 2a² + 2Δ² > 0: θ = 0 family stable

#: time step of the finite differences (s). 5-point stencils: truncation ~ h⁴ |G⁽⁶⁾| / 90
#: and rounding ~ 16 ε |G| / (3 h²). Measured on the worst shape met (b/a = 4, Δ/a = 0.25,
#: u̇ = 4.8 rad/s): force residual 4e-7 N at h = 1e-3 s, 2.5e-8 N at 5e-4 s, a rounding floor
#: of ~7e-9 N below; 4e-4 s keeps both terms below 1e-9 M g.
FD_STEP = 4e-4
#: force balance: |F_A + F_B − M g e_z − M a_G| ≤ FORCE_TOL · M g
FORCE_TOL = 2e-8
#: moment balance: |Σ (P − G) × F_P + τ ê − dH/dt| ≤ MOMENT_TOL · M g L
MOMENT_TOL = 2e-8
#: statics: vertical forces by the lever rule, no friction (relative to M g; torques to
#: M g L): measured ≤ 1.1e-15 at the stable equilibria and held by the drive anywhere.
STATIC_ATOL = 5e-15
#: mirror and disk-swap partners, evaluated at different phases of the tables (relative to
#: M g; torques to M g L): measured ≤ 6.1e-13, μ_required ≤ 1.8e-12 relative.
SYMMETRY_ATOL = 2e-12
SYMMETRY_MU_RTOL = 5e-12
#: world vectors against their components: sums of 3 rounded products, so 16 ulps of the
#: largest force (world_atol; measured ≤ 2e-16 M g); the unit vector ê against B − A from the
#: cycle's positions: ≤ 5e-15.
DIRECTION_ATOL = 2e-14
#: μ_required against the one from Newton–Euler by finite differences, times N_min / (M g)
#: (an error δF in the forces moves μ by ~δF/N_min): measured ≤ 2.8e-9, near lift-off.
MU_FD_TOL = 1e-8
#: μ_required of the squeeze rule against the least μ bisected here, relative, per unit of
#: max(N_A/N_B, N_B/N_A): B's share S − x of a split stored as A's share x carries the rounding
#: of S, amplified by N_A/N_B when B is nearly unloaded. Measured ≤ 6.6e-16 over 8e5 random
#: loads with N_A/N_B up to 1e4 (before the discriminant was formed without cancellation:
#: 3.3e-13, i.e. 7.6e-10 at N_A/N_B = 2300): 16 ulps, a sum of rounded terms.
SQUEEZE_RTOL = ulps(16)
#: The friction ratios √(T² + x²)/N of the split against np.hypot(T, x)/N: ≤ 4 rounded
#: operations each side, but libm's hypot has no stated last bit: 16 ulps, relative.
RATIO_RTOL = ulps(16)


def world_atol(*forces):
    """16 ulps of the largest of the forces (N), each of shape (..., 3)."""
    return ulps(16, max(np.max(np.linalg.norm(f, axis=-1)) for f in forces))


def make(shape, model='laminae', gravity=GRAVITY):
    body = EllipseBody(*shape)
    dynamics = RollingDynamics(body, mass_properties(model, *shape, MASS), gravity=gravity)
    return ContactForceModel(dynamics)


_MODELS = {}


def cached(shape, model='laminae'):
    key = (shape, model)
    if key not in _MODELS:
        _MODELS[key] = make(shape, model)
    return _MODELS[key]


def stencil_times(centres, reach, step=FD_STEP):
    """Times centres + j·h, j = −reach … reach, flattened; shape (len(centres), 2 reach + 1)."""
    offsets = step * np.arange(-reach, reach + 1)
    return (np.asarray(centres)[:, None] + offsets).ravel()


def derivative5(samples, axis=1):
    """5-point central first derivative at the middle of 5 samples along ``axis``."""
    s = np.moveaxis(samples, axis, 0)
    return (s[0] - 8 * s[1] + 8 * s[3] - s[4]) / (12 * FD_STEP)


def second_derivative5(samples, step=FD_STEP):
    s = np.moveaxis(samples, 1, 0)
    return (-s[0] + 16 * s[1] - 30 * s[2] + 16 * s[3] - s[4]) / (12 * step**2)


def check_force_balance(model, mode, omega0, theta0, centres, step=FD_STEP):
    dynamics = model.dynamics
    motion = simulate(dynamics, stencil_times(centres, 2, step), mode=mode, omega0=omega0,
                      theta0=theta0)
    g, _, _ = dynamics.cycle.positions(motion.phase)
    acc = second_derivative5(g.reshape(len(centres), 5, 3), step)
    forces = model.along(motion)
    mid = slice(2, None, 5)
    total = forces.force_a[mid] + forces.force_b[mid] - [0, 0, model.weight]
    rounding = MASS * 50 * np.finfo(float).eps * np.max(np.abs(g)) / step**2
    assert np.max(np.abs(total - MASS * acc)) <= FORCE_TOL * model.weight + rounding
    return motion, forces


# ----------------------------------------------------------------------------- Newton, Euler

@pytest.mark.parametrize('shape, mode, omega0, theta0', [
    (OLOID, 'dynamic', 6.0, 0.2),        # rolls over the top (quadrature)
    (OLOID, 'dynamic', 1.0, 1.2),        # oscillates in a well (libration)
    (FIGURE3, 'dynamic', 5.0, 0.0),
    (TCR, 'kinematic', 5.0, 0.3),        # driven: the drive's moment changes no force sum
    (FAT, 'kinematic', -3.0, -0.4),
])
def test_total_force_equals_mass_times_acceleration(shape, mode, omega0, theta0):
    check_force_balance(cached(shape), mode, omega0, theta0, np.array([0.31, 0.77, 1.43]))


def orientation_rate(rotations):
    """ω (world, rad/s) at the middle of 5 rotations spaced FD_STEP: d/ds log(R(t+s)R(t)ᵀ)."""
    middle = Rotation.from_matrix(rotations[:, 2])
    logs = np.stack([(Rotation.from_matrix(rotations[:, j]) * middle.inv()).as_rotvec()
                     for j in range(5)], axis=1)
    return derivative5(logs)


@pytest.mark.parametrize('shape, mass_model, mode, omega0, theta0', [
    (OLOID, 'laminae', 'dynamic', 6.0, 0.2),
    (OLOID, 'solid', 'dynamic', 2.0, 1.0),
    (FIGURE3, 'laminae', 'kinematic', 4.0, 0.5),
    (FAT, 'solid', 'kinematic', 3.0, 0.0),
])
def test_moment_about_g_equals_rate_of_angular_momentum(shape, mass_model, mode, omega0,
                                                        theta0):
    model = cached(shape, mass_model)
    inertia = model.dynamics.mass.inertia
    centres = np.array([0.23, 0.91])
    motion = simulate(model.dynamics, stencil_times(centres, 4), mode=mode, omega0=omega0,
                      theta0=theta0)
    rot = model.dynamics.cycle.state(motion.phase).rotation.reshape(len(centres), 9, 3, 3)
    momentum = []
    for i in range(2, 7):     # H at the five inner times of each stencil
        omega = orientation_rate(rot[:, i - 2:i + 3])
        r = rot[:, i]
        momentum.append(np.einsum('kij,jl,kml,km->ki', r, inertia, r, omega))
    rate = derivative5(np.stack(momentum, axis=1))
    g, a, b = model.dynamics.cycle.positions(motion.phase)
    forces = model.along(motion)
    mid = slice(4, None, 9)
    moment = (np.cross(a[mid] - g[mid], forces.force_a[mid])
              + np.cross(b[mid] - g[mid], forces.force_b[mid]))
    direction = (b[mid] - a[mid]) / np.linalg.norm(b[mid] - a[mid], axis=-1)[:, None]
    moment += forces.drive_torque[mid][:, None] * direction
    scale = model.weight * model.body.size
    assert np.max(np.abs(moment - rate)) <= MOMENT_TOL * scale
    if mode == 'dynamic':      # a free motion needs no drive: measured ≤ 6e-14 M g L
        assert np.max(np.abs(forces.drive_torque)) <= 3e-13 * scale


def newton_euler_forces(model, mode, omega0, theta0, centres):
    """Ground forces at the centres from Newton–Euler with finite differences of the poses.

    G's acceleration and dH_G/dt (H_G = R I_G Rᵀ ω, ω from the orientations) by 5-point
    differences in time along the simulated motion; A, B and G from ``cycle.positions``.
    With ê from A to B, p = e_z × ê and the squeeze left out (it changes neither sum), the
    force and moment balances about G are six linear equations for (N_A, N_B, T_A, T_B, S, τ).

    Returns
    -------
    components : ndarray, shape (len(centres), 6)
        N_A, N_B, T_A, T_B, S (N) and the drive torque τ (N m).
    forces : ContactForces
        The module's forces at the centres.
    """
    dynamics = model.dynamics
    inertia = dynamics.mass.inertia
    n = len(centres)
    motion = simulate(dynamics, stencil_times(centres, 4), mode=mode, omega0=omega0,
                      theta0=theta0)
    rot = dynamics.cycle.state(motion.phase).rotation.reshape(n, 9, 3, 3)
    g, a, b = (x.reshape(n, 9, 3) for x in dynamics.cycle.positions(motion.phase))
    momentum = []
    for i in range(2, 7):     # H at the five inner times of each stencil
        omega = orientation_rate(rot[:, i - 2:i + 3])
        r = rot[:, i]
        momentum.append(np.einsum('kij,jl,kml,km->ki', r, inertia, r, omega))
    rate = derivative5(np.stack(momentum, axis=1))
    force = MASS * (second_derivative5(g[:, 2:7]) + [0.0, 0.0, GRAVITY])
    g, a, b = g[:, 4], a[:, 4], b[:, 4]
    unit = (b - a) / np.linalg.norm(b - a, axis=-1)[:, None]
    up = np.broadcast_to([0.0, 0.0, 1.0], unit.shape)
    p = np.cross(up, unit)
    arm_a, arm_b = a - g, b - g
    columns = [(up, np.cross(arm_a, up)), (up, np.cross(arm_b, up)), (p, np.cross(arm_a, p)),
               (p, np.cross(arm_b, p)), (unit, np.cross(arm_b, unit)), (0 * unit, unit)]
    matrix = np.stack([np.concatenate(col, axis=-1) for col in columns], axis=-1)
    components = np.linalg.solve(matrix, np.concatenate([force, rate], axis=-1)[..., None])
    forces = model.along(motion)
    middle = slice(4, None, 9)
    picked = {name: getattr(forces, name)[middle] for name in (
        'normal_a', 'normal_b', 'tangential_a', 'tangential_b', 'along_ab', 'drive_torque',
        'mu_required')}
    return components[..., 0], picked


@pytest.mark.parametrize('shape, mass_model, mode, omega0, theta0', [
    (OLOID, 'laminae', 'dynamic', 6.0, 0.2),     # rolls over the top
    (OLOID, 'solid', 'dynamic', 2.0, 1.0),       # oscillates in a well
    (FAT, 'solid', 'kinematic', 3.0, 0.0),
    (FIGURE3, 'laminae', 'kinematic', None, 0.5),   # 0.99 Ω_c: N_B → 0, μ up to 3.5
])
def test_mu_required_from_newton_euler_by_finite_differences(shape, mass_model, mode, omega0,
                                                             theta0):
    """N, T, S and μ_required from the motion alone (Newton–Euler, differences in time)."""
    model = cached(shape, mass_model)
    if omega0 is None:
        omega0 = 0.99 * liftoff_speed(model)[0]
    components, forces = newton_euler_forces(model, mode, omega0, theta0,
                                             np.linspace(0.1, 2.0, 12))
    names = ('normal_a', 'normal_b', 'tangential_a', 'tangential_b', 'along_ab')
    for column, name in enumerate(names):
        assert_allclose(forces[name], components[:, column], rtol=0,
                        atol=FORCE_TOL * model.weight)
    scale = model.weight * model.body.size
    assert_allclose(forces['drive_torque'], components[:, 5], rtol=0, atol=MOMENT_TOL * scale)
    # μ_required: the least friction of those components, bisected (least_friction)
    loaded = np.minimum(components[:, 0], components[:, 1])
    assert np.all(loaded > 0)
    assert np.all(np.abs(forces['mu_required'] - least_friction(*components[:, :5].T))
                  <= MU_FD_TOL * model.weight / loaded)


def test_world_vectors_match_components_and_contact_line():
    model = cached(FIGURE3)
    u = np.linspace(-7.0, 20.0, 301)           # several cycles, also negative phases
    forces = model.kinematic(u, 3.0)
    _, a, b = model.dynamics.cycle.positions(u)
    unit = (b - a) / np.linalg.norm(b - a, axis=-1)[:, None]
    assert_allclose(forces.direction_ab, unit, atol=DIRECTION_ATOL)
    p = np.cross([0.0, 0.0, 1.0], unit)
    for f, n, t, x in ((forces.force_a, forces.normal_a, forces.tangential_a, forces.along_a),
                       (forces.force_b, forces.normal_b, forces.tangential_b, forces.along_b)):
        assert_allclose(f @ [0, 0, 1.0], n, atol=world_atol(f))
        assert_allclose(np.sum(f * p, -1), t, atol=world_atol(f))
        assert_allclose(np.sum(f * unit, -1), x, atol=world_atol(f))


def test_drive_torque_supplies_the_power():
    """τ ê·ω = dE/dt = u̇ (m ü + ½ m′ u̇² + V′); ω ∥ AB so ê·ω_u = ±|ω_u|."""
    model = cached(FIGURE3)
    body, dynamics = model.body, model.dynamics
    u = np.linspace(0.0, TWO_PI, 97)
    omega = 4.0
    forces = model.kinematic(u, omega)
    geo = body.phase_geometry(u)
    d = geo.contact_b - geo.contact_a
    along = np.sum(body.phase_angular_velocity(u) * d, -1) / np.linalg.norm(d, axis=-1)
    f, df = dynamics.tabulated(u), dynamics.tabulated(u, derivative=1)
    w, dw = f[:, 2], df[:, 2]
    u_dot, u_ddot = omega / w, -omega**2 * dw / w**3
    expected = (f[:, 0] * u_ddot + 0.5 * df[:, 0] * u_dot**2 + df[:, 1]) / along
    # measured: τ ≤ 8.8e-14 M g L, u̇ 6.7e-16 relative, ü ≤ 6e-13 Ω² (tables vs tables)
    assert_allclose(forces.drive_torque, expected,
                    atol=5e-13 * model.weight * body.size)
    assert_allclose(forces.phase_rate, u_dot, rtol=4e-15)
    assert_allclose(forces.phase_acceleration, u_ddot, atol=3e-12 * omega**2)


# ----------------------------------------------------------------------------- statics

def lever_rule(model, u):
    """(N_A, N_B) of a body at rest from the world positions: G's projection on AB."""
    g, a, b = model.dynamics.cycle.positions(u)
    length = np.linalg.norm(b - a, axis=-1)
    x_g = np.sum((g - a) * (b - a), -1) / length      # along AB from A (horizontal part)
    return model.weight * (length - x_g) / length, model.weight * x_g / length


@pytest.mark.parametrize('shape', [OLOID, FIGURE3, FAT])
def test_stable_equilibria_vertical_forces_lever_rule(shape):
    model = cached(shape)
    stable = [eq for eq in equilibria(model.body) if eq.stability == STABLE]
    assert len(stable) == 4
    u = np.array([eq.phase for eq in stable])
    for forces in (model.dynamic(u, 0.0), model.forces(u, 0.0, 0.0), model.kinematic(u, 0.0)):
        scale = STATIC_ATOL * model.weight
        for name in ('tangential_a', 'tangential_b', 'along_ab'):
            assert np.max(np.abs(getattr(forces, name))) <= scale, name
        assert np.max(forces.mu_required) <= STATIC_ATOL
        assert np.max(np.abs(forces.drive_torque)) <= STATIC_ATOL * model.weight * model.body.size
        n_a, n_b = lever_rule(model, u)
        assert_allclose(forces.normal_a, n_a, atol=scale)
        assert_allclose(forces.normal_b, n_b, atol=scale)
        assert np.all(forces.normal_a > 0) and np.all(forces.normal_b > 0)


def test_held_at_rest_anywhere_by_the_drive():
    """Ω = 0 in kinematic mode: vertical forces by the lever rule, τ balances −V′."""
    model = cached(OLOID)
    u = np.linspace(0.0, TWO_PI, 61)
    forces = model.kinematic(u, 0.0)
    n_a, n_b = lever_rule(model, u)
    assert_allclose(forces.normal_a, n_a, atol=STATIC_ATOL * model.weight)
    assert_allclose(forces.normal_b, n_b, atol=STATIC_ATOL * model.weight)
    assert np.max(np.abs(forces.tangential_a)) <= STATIC_ATOL * model.weight
    assert np.max(np.abs(forces.along_ab)) <= STATIC_ATOL * model.weight
    assert_allclose(forces.normal_a + forces.normal_b, model.weight, rtol=STATIC_ATOL)


# ----------------------------------------------------------------------------- symmetries

@pytest.mark.parametrize('shape', [OLOID, FIGURE3])
def test_mirror_branch_mirrors_forces(shape):
    model = cached(shape)
    u = np.linspace(-1.5, 1.5, 41)
    for here, there in ((model.dynamic(u, 4.0), model.dynamic(np.pi - u, -4.0)),
                        (model.kinematic(u, 6.0), model.kinematic(np.pi - u, 6.0))):
        scale = SYMMETRY_ATOL * model.weight
        for name, sign in (('normal_a', 1), ('normal_b', 1), ('tangential_a', -1),
                           ('tangential_b', -1), ('along_ab', 1)):
            assert_allclose(getattr(there, name), sign * getattr(here, name), atol=scale)
        assert_allclose(there.mu_required, here.mu_required, rtol=SYMMETRY_MU_RTOL)


def swap_phase(body, u):
    """u′ with r1(u′) = S r2(u), r2(u′) = S r1(u), n(u′) = S n(u), S: x ↦ (x3, −x2, x1)."""
    swap = np.array([[0, 0, 1.0], [0, -1.0, 0], [1.0, 0, 0]])
    geo = body.phase_geometry(u)
    target = np.concatenate([swap @ geo.contact_b, swap @ geo.contact_a, swap @ geo.ground_normal])

    def residual(x):
        g = body.phase_geometry(x)
        return np.concatenate([g.contact_a, g.contact_b, g.ground_normal], axis=-1) - target
    grid = np.linspace(0.0, TWO_PI, 2049)
    x = grid[np.argmin(np.sum(residual(grid) ** 2, axis=-1))]
    for _ in range(8):     # Gauss-Newton on the vector residual (a squared norm would stall)
        slope = (residual(x + 1e-7) - residual(x - 1e-7)) / 2e-7
        x -= np.dot(slope, residual(x)) / np.dot(slope, slope)
    assert np.max(np.abs(residual(x))) < 1e-13
    return x % TWO_PI


@pytest.mark.parametrize('shape', [OLOID, FIGURE3])
def test_disk_swap_swaps_contacts(shape):
    model = cached(shape)
    u = np.array([0.3, 1.0, math.pi / 2, 2.2, 4.0, 5.5])
    partner = np.array([swap_phase(model.body, x) for x in u])
    # the turning point θ = θ_max (u = π/2) is the pose θ = 0 (u = 0 or π) with disks swapped
    assert abs(math.remainder(partner[2], math.pi)) < 1e-9
    here, there = model.kinematic(u, 5.0), model.kinematic(partner, 5.0)
    scale = SYMMETRY_ATOL * model.weight
    assert_allclose(there.normal_a, here.normal_b, atol=scale)
    assert_allclose(there.normal_b, here.normal_a, atol=scale)
    assert_allclose(there.tangential_a, -here.tangential_b, atol=scale)
    assert_allclose(there.tangential_b, -here.tangential_a, atol=scale)
    assert_allclose(there.along_ab, -here.along_ab, atol=scale)
    assert_allclose(there.drive_torque, -here.drive_torque,
                    atol=SYMMETRY_ATOL * model.weight * model.body.size)
    assert_allclose(there.mu_required, here.mu_required, rtol=SYMMETRY_MU_RTOL)


# ----------------------------------------------------------------------------- squeeze, μ

def least_friction(normal_a, normal_b, tangential_a, tangential_b, along_ab):
    """min over the squeeze of max(f_A, f_B), by bisection on μ (independent of the module).

    The friction cones cut the horizontal line of the squeeze x (the share of S taken by A) in
    two intervals: f_A(x) ≤ μ for |x| ≤ r_A(μ) = √((μ N_A)² − T_A²), f_B(x) ≤ μ for
    |S − x| ≤ r_B(μ). A split needing no more than μ exists iff both radii are real and
    r_A + r_B ≥ |S|: increasing in μ, so the least such μ is bisected to adjacent floats
    between μ_low = max(|T_A|/N_A, |T_B|/N_B) and μ_low + |S|/min(N_A, N_B) (arrays, N > 0).
    """
    n_a, n_b, t_a, t_b, s = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (
        normal_a, normal_b, tangential_a, tangential_b, along_ab)))

    def enough(mu):
        r_a = np.sqrt(np.maximum((mu * n_a) ** 2 - t_a ** 2, 0.0))
        r_b = np.sqrt(np.maximum((mu * n_b) ** 2 - t_b ** 2, 0.0))
        return r_a + r_b >= np.abs(s)
    low = np.maximum(np.abs(t_a) / n_a, np.abs(t_b) / n_b)
    high = low + np.abs(s) / np.minimum(n_a, n_b)
    done = enough(low)
    high = np.where(done, low, high)
    for _ in range(200):
        middle = 0.5 * (low + high)
        if np.all((middle <= low) | (middle >= high)):
            break
        ok = enough(middle)
        high = np.where(ok, middle, high)
        low = np.where(ok, low, middle)
    return high


def test_squeeze_split_minimises_the_friction_needed():
    rng = np.random.default_rng(7)
    n = 400
    n_a, n_b = rng.uniform(0.05, 3, n), rng.uniform(0.05, 3, n)
    t_a, t_b, s = rng.normal(size=n), rng.normal(size=n), rng.normal(size=n) * 2
    t_a[:50] = 0.0          # degenerate cases: no determinate tangential part, equal loads
    n_b[50:100] = n_a[50:100]
    s[100:120] = 0.0
    # and loads of very different size (a contact close to lifting off), forces over 5 decades
    m = 4000
    n_a = np.concatenate([n_a, 10 ** rng.uniform(-3, 1, m)])
    n_b = np.concatenate([n_b, 10 ** rng.uniform(-3, 1, m)])
    t_a, t_b, s = (np.concatenate([v, rng.normal(size=m) * 10 ** rng.uniform(-4, 1, m)])
                   for v in (t_a, t_b, s))
    x, ratio_a, ratio_b, mu = squeeze_split(n_a, n_b, t_a, t_b, s)
    # the least μ from the intersection of the friction cones, bisected to adjacent floats
    rtol = SQUEEZE_RTOL * np.maximum(n_a / n_b, n_b / n_a)
    assert np.all(np.abs(mu / least_friction(n_a, n_b, t_a, t_b, s) - 1) <= rtol)
    # the reported split needs no more than that: f_A, f_B computed here from x
    assert np.all(np.hypot(t_a, x) / n_a <= mu * (1 + RATIO_RTOL))
    assert np.all(np.hypot(t_b, s - x) / n_b <= mu * (1 + RATIO_RTOL))
    assert_allclose(ratio_a, np.hypot(t_a, x) / n_a, rtol=RATIO_RTOL)
    assert_allclose(ratio_b, np.hypot(t_b, s - x) / n_b, rtol=RATIO_RTOL)
    lifted = squeeze_split([-1.0, 1.0], [1.0, 0.0], [0.1, 0.1], [0.1, 0.1], [1.0, 1.0])
    assert np.all(np.isinf(lifted[3]))


def test_mu_just_above_and_below_mu_required():
    model = cached(OLOID)
    t = np.linspace(0.0, 2.0, 401)
    motion = simulate(model.dynamics, t, mode='dynamic', omega0=6.0, theta0=0.2)
    forces = model.along(motion)
    peak = float(np.max(forces.mu_required))
    first = int(np.argmax(forces.mu_required >= peak))
    assert check_validity(t, forces, mu=peak * (1 + 1e-9)).valid
    report = check_validity(t, forces, mu=peak * (1 - 1e-9))
    assert not report.valid and report.kind == 'slip' and report.index == first
    assert report.reason.startswith(f'the body would slip at t = {t[first]:.6g} s')
    peak_dynamic, _, _ = mu_required_dynamic(model, float(motion.energy[0]), samples=8192)
    # the peak over 8192 phases of the cycle against the peak along the motion sampled every
    # 0.5 ms (measured 3.2e-10 apart; 7e-7 with the 401 samples above)
    dense = simulate(model.dynamics, np.linspace(0.0, 2.0, 4001), mode='dynamic', omega0=6.0,
                     theta0=0.2)
    assert peak_dynamic == pytest.approx(np.max(model.along(dense).mu_required), rel=1e-8)


# ----------------------------------------------------------------------------- lift-off

@pytest.mark.parametrize('shape', [OLOID, TCR, FIGURE3])
def test_liftoff_speed_against_a_dense_sweep(shape):
    model = cached(shape)
    speed, phase, contact = liftoff_speed(model)
    assert 0 < speed < np.inf and contact in 'AB'
    u = np.linspace(0.0, TWO_PI, 200001)
    below = model.kinematic(u, speed * (1 - 1e-6))
    above = model.kinematic(u, speed * (1 + 1e-4))
    assert min(below.normal_a.min(), below.normal_b.min()) >= 0
    assert min(above.normal_a.min(), above.normal_b.min()) < 0
    mu = mu_required_kinematic(model, [0.0, 0.5 * speed, speed * (1 + 1e-4)])
    assert mu[0] <= STATIC_ATOL and 0 < mu[1] < np.inf and mu[2] == np.inf


def test_liftoff_report_along_a_driven_motion():
    model = cached(OLOID)
    speed, _, _ = liftoff_speed(model)
    t = np.linspace(0.0, 3.0, 3001)
    fast = simulate(model.dynamics, t, mode='kinematic', omega0=1.2 * speed)
    report, forces = motion_validity(model, fast)
    assert not report.valid and report.kind.startswith('lift-off')
    i = report.index
    name = report.kind[-1]
    value = getattr(forces, 'normal_' + name.lower())[i]
    assert value < 0 and np.all(~forces.lift_off[:i])
    assert report.reason == (f'contact {name} would lift off at t = {t[i]:.6g} s: '
                             f'N_{name} = {value:.4g} N')
    slow = simulate(model.dynamics, t, mode='kinematic', omega0=0.9 * speed)
    assert motion_validity(model, slow)[0].valid


# ----------------------------------------------------------------------------- extremes

def test_spectral_tail_is_the_tables_and_is_computed_when_read():
    """ContactForceModel.spectral_tail (a report: no table reads it) is computed when first
    read, not at every build (an FFT of every column, ~1 s of a 2¹⁶-node body's start-up);
    its value is the largest tail, |c_k| for |k| > N/4 over max |c_k|, of the coefficient
    tables the model was built with (numpy's FFT here)."""
    model = make((0.1, 0.1, 0.05))
    assert 'spectral_tail' not in vars(model)
    expected = 0.0
    for columns in model._columns.values():
        coeffs = np.abs(np.fft.fft(columns[:, :-3], axis=0))
        k = np.abs(np.fft.fftfreq(coeffs.shape[0], d=1.0 / coeffs.shape[0]))
        expected = max(expected, float(np.max(coeffs[k > coeffs.shape[0] // 4]))
                       / float(np.max(coeffs)))
    assert model.spectral_tail == expected        # the same operations: the same bits
    assert model.spectral_tail <= 1e-12           # resolved (~1e-13 or less, the docstring)


@pytest.mark.parametrize('shape', [(1.0, 0.01, 0.5), (1.0, 1.0, 0.999)])
def test_extreme_shapes_are_finite(shape):
    model = make(shape)
    u = np.linspace(0.0, TWO_PI, 4001)
    forces = model.kinematic(u, 1.0)
    for name in ('normal_a', 'normal_b', 'tangential_a', 'tangential_b', 'along_ab',
                 'drive_torque', 'force_a', 'force_b'):
        assert np.all(np.isfinite(getattr(forces, name))), name
    assert_allclose(forces.normal_a + forces.normal_b - forces.force_a[:, 2]
                    - forces.force_b[:, 2], 0.0, atol=world_atol(forces.force_a, forces.force_b))
    speed = liftoff_speed(model)[0]
    assert 0 < speed < np.inf


@settings(max_examples=int(os.environ.get('FORCE_EXAMPLES', 8)), deadline=None)
@given(b_over_a=st.floats(0.05, 20.0), delta_over_a=st.floats(0.01, 0.99),
       omega0=st.floats(0.5, 5.0), theta0=st.floats(-1.0, 1.0))
def test_force_balance_over_shapes(b_over_a, delta_over_a, omega0, theta0):
    a = 0.1 / max(1.0, b_over_a)        # the larger semi-axis is 0.1 m
    shape = (a, a * b_over_a, a * delta_over_a)
    model = make(shape)
    theta0 = theta0 * model.body.theta_max
    # thin disks and small Δ have features of width ~ min(b/a, a/b, 2√(Δ/a)) in u: the step
    # resolves them at the fastest u̇ (measured: b/a = 0.125, Δ/a = 0.0625, u̇ = 14 rad/s
    # needs h ≤ 2e-4 s for a residual of 1e-9 M g)
    width = min(1.0, b_over_a, 1 / b_over_a, 2 * math.sqrt(delta_over_a))
    centres = np.array([0.17, 0.61])
    rates = simulate(model.dynamics, np.linspace(0.0, 0.7, 141), mode='kinematic',
                     omega0=omega0, theta0=theta0).phase_rate
    step = min(FD_STEP, 0.005 * width / np.max(np.abs(rates)))
    check_force_balance(model, 'kinematic', omega0, theta0, centres, step)

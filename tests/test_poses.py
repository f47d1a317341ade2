"""Tests of the fast pose path :meth:`RollingCycle.poses` and its continuous quaternion.

Convention under test: quaternions (x, y, z, w), body → world, a continuous function of the
phase u with w > 0 at u = 0 (:mod:`twodisk_ros.physics.bodies.orientation`). References:

* the orientation: ``Rotation.from_matrix(state.rotation)``, the closed-form R = R_z(α) C(u)
  (C from the body's closed-form t1 and n, per sample); quaternions are compared as
  rotations (q and −q are the same rotation), both by |q · q_ref| and componentwise up to
  that sign;
* continuity: signs of q_k · q_{k+1} over many cycles, and the same phases evaluated in
  arbitrary blocks, from arbitrary starting phases;
* positions: :meth:`RollingCycle.positions` (itself checked against closed forms, a direct
  integration and the oloid's elementary trace in tests/test_cycle.py), and the
  table's previous evaluation (:meth:`HermiteTable.__call__`) for the new vectorised one.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal
from scipy.spatial.transform import Rotation

from rounding import ulps
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.cycle import RollingCycle
from twodisk_ros.physics.bodies.orientation import quaternion_from_matrix
from twodisk_ros.physics.numerics.tables import HermiteTable

TWO_PI = 2 * math.pi

# -- tolerances --------------------------------------------------------------------------------
#: Tabulated against closed-form orientation, componentwise up to the global sign, over 7
#: cycles: measured ≤ 3.7e-14 (thin bodies, b/a = 0.05; ≤ 3e-15 for the oloid and the TCR,
#: ≤ 1.3e-14 for 10 random shapes of the hypothesis range; ≤ 2e-13 for the extremes
#: b/a ∈ {0.01, 100}, Δ/a ∈ {1e-3, 1 − 1e-6} of tests/test_cycle.py, not repeated here).
QUATERNION_ATOL = 1e-12
#: 1 − |q · q_ref| (≈ angle²/8, a weak check next to the above; measured ≤ 4.4e-16).
DOT_ATOL = 1e-10
#: Unit norm after the renormalisation: measured ≤ 2.2e-16; a norm of 4 rounded squares,
#: 16 ulps of 1.
NORM_ATOL = ulps(16)
#: The same phases evaluated in other blocks or shapes of array: the same elementwise code,
#: which a machine may round otherwise at an array's edges (SIMD tails): 16 ulps of 1.
BLOCK_ATOL = ulps(16)
#: At the fine sampling below (Δu ≤ 3.8e-3) q_k·q_{k+1} = cos(turn/2): measured ≥ 0.9993
#: (b/a = 20; 0.944 for b/a = 100, Δ/a = 1e-3, outside the range tested here).
FINE_DOT_MIN = 0.99
#: After k whole cycles q(u + 2πk) = (−ε)^k q(u) up to the cycle's excess turn about Z
#: (T − 2π ≤ 3e-11 rad, test_cycle) and rounding: measured ≤ 5e-14 for |k| ≤ 5.
CYCLE_ATOL = 1e-10
#: The vectorised table evaluation (weights + combine, and powers + expand) against
#: HermiteTable.__call__, relative to the largest node data: measured ≤ 1.5e-16 (combine)
#: and ≤ 3.1e-15 (expand: coefficients up to 30× the node data) over 300 random tables.
COMBINE_RTOL = 1e-14

NAMED = {
    'oloid': (1.0, 1.0, 0.5),
    'tcr': (1.0, 1.0, 1.0 / math.sqrt(2.0)),
    'thin': (1.0, 0.05, 0.3),
    'tall': (1.0, 20.0, 0.5),
    'close': (1.0, 1.0, 0.01),
    'far': (1.0, 1.0, 0.99),
    'thin_close': (1.0, 0.05, 0.01),
    'tall_far': (1.0, 20.0, 0.99),
}
SHAPES = st.tuples(st.floats(0.1, 10.0), st.floats(math.log(0.05), math.log(20.0)),
                   st.floats(0.01, 0.99))

_CYCLES = {}


def _cycle(shape):
    """RollingCycle of a shape, built once per session (≤ 0.5 s each here)."""
    if shape not in _CYCLES:
        _CYCLES[shape] = RollingCycle(EllipseBody(*shape))
    return _CYCLES[shape]


def _phases(start=-3 * math.pi, cycles=7, count=4000):
    """Phases over ``cycles`` cycles from ``start``, with every turning point and θ = 0."""
    u = np.linspace(start, start + TWO_PI * cycles, count)
    special = np.arange(math.ceil(start / (math.pi / 2)),
                        math.floor((start + TWO_PI * cycles) / (math.pi / 2)) + 1) * math.pi / 2
    return np.sort(np.concatenate([u, special]))


def _same_rotation(q, q_ref):
    """Componentwise distance of q to ±q_ref (the nearer sign), and 1 − |q·q_ref|."""
    dots = np.sum(q * q_ref, axis=-1)
    aligned = q_ref * np.where(dots < 0, -1.0, 1.0)[..., None]
    return np.max(np.abs(q - aligned)), np.max(1.0 - np.abs(dots))


def _check_against_closed_forms(cycle, u):
    state = cycle.state(u)
    poses = cycle.poses(u)
    q_ref = Rotation.from_matrix(state.rotation.reshape(-1, 3, 3)).as_quat()
    distance, dot_gap = _same_rotation(poses.quaternion.reshape(-1, 4), q_ref)
    assert distance <= QUATERNION_ATOL
    assert dot_gap <= DOT_ATOL
    assert_allclose(np.linalg.norm(poses.quaternion, axis=-1), 1.0, rtol=0, atol=NORM_ATOL)
    # the state carries the same continuous quaternion, and the same positions
    assert_array_equal(state.quaternion, poses.quaternion)
    for name in ('position_g', 'contact_a', 'contact_b', 'heading'):
        assert_array_equal(getattr(state, name), getattr(poses, name))


def _check_continuous(cycle, u):
    q = cycle.poses(u).quaternion
    dots = np.sum(q[1:] * q[:-1], axis=-1)
    assert dots.min() >= FINE_DOT_MIN


# -- the orientation against the closed forms ---------------------------------------------------
@pytest.mark.parametrize('name', sorted(NAMED))
def test_quaternion_matches_closed_form_rotation(name):
    _check_against_closed_forms(_cycle(NAMED[name]), _phases())


@settings(max_examples=6, deadline=None)
@given(SHAPES, st.floats(-50.0, 50.0))
def test_quaternion_across_shapes(drawn, start):
    scale, log_ba, da = drawn
    shape = (scale, scale * math.exp(log_ba), scale * da)
    cycle = RollingCycle(EllipseBody(*shape))
    u = _phases(start, cycles=3, count=1500)
    _check_against_closed_forms(cycle, u)
    _check_continuous(cycle, np.linspace(start, start + 3 * TWO_PI, 6000))
    assert_array_equal(cycle.poses(u).position_g, cycle.positions(u)[0])


# -- matrix to quaternion against scipy's Rotation ---------------------------------------------
@pytest.mark.parametrize('seed', [0, 1])
def test_quaternion_from_matrix_is_scipys_rotation(seed):
    """Every pivot of Markley's method: random rotations, half-turns about each axis (w = 0,
    the x, y or z pivot), the identity and tiny turns (the w pivot). Compared as rotations (up
    to the global sign) with ``Rotation.from_matrix``; the bound is 16 ulps of the unit
    components, a few rounded products and sums apiece."""
    rotations = Rotation.concatenate([
        Rotation.random(2000, random_state=seed),
        Rotation.from_rotvec(math.pi * np.eye(3)),
        Rotation.from_rotvec((math.pi - 1e-9) * np.eye(3)),
        Rotation.from_rotvec(1e-12 * np.eye(3)),
        Rotation.identity()])
    matrices = rotations.as_matrix()
    expected = rotations.as_quat()
    got = quaternion_from_matrix(matrices)
    sign = np.sign(np.sum(got * expected, axis=-1))[:, None]
    assert np.all(sign != 0)
    assert_allclose(got * sign, expected, rtol=0, atol=ulps(16))
    # one matrix gives one quaternion, the same as in a batch
    assert_array_equal(quaternion_from_matrix(matrices[7]), got[7])


# -- continuity -----------------------------------------------------------------------------------
@pytest.mark.parametrize('name', sorted(NAMED))
def test_quaternion_is_continuous_over_many_cycles(name):
    cycle = _cycle(NAMED[name])
    # 12 cycles forward and backward from u = 0, 2·10⁴ samples (Δu ≈ 3.8e-3)
    _check_continuous(cycle, np.linspace(-6 * TWO_PI, 6 * TWO_PI, 20001))


@pytest.mark.parametrize('name', ['oloid', 'thin', 'tall_far'])
def test_blocks_and_starting_phases_join_continuously(name):
    """Arbitrary splits of one array, evaluated separately, equal the whole (the node's blocks)."""
    cycle = _cycle(NAMED[name])
    rng = np.random.default_rng(7)
    for start in (-17.3, -TWO_PI, 0.0, 1.234, 40.0):
        u = start + np.arange(30000) * 3e-3            # 14 cycles
        whole = cycle.poses(u).quaternion
        cuts = np.sort(rng.choice(np.arange(1, u.size), size=40, replace=False))
        parts = np.concatenate([cycle.poses(p).quaternion for p in np.split(u, cuts)])
        states = np.concatenate([cycle.state(p).quaternion for p in np.split(u, cuts[::8])])
        assert_allclose(parts, whole, rtol=0, atol=BLOCK_ATOL)
        assert_allclose(states, whole, rtol=0, atol=BLOCK_ATOL)
        dots = np.sum(parts[1:] * parts[:-1], axis=-1)
        assert dots.min() >= FINE_DOT_MIN
        # single samples and a 2-D array agree with the array
        assert_allclose(cycle.poses(float(u[123])).quaternion, whole[123], rtol=0,
                        atol=BLOCK_ATOL)
        grid = cycle.poses(u[:600].reshape(20, 30))
        assert grid.quaternion.shape == (20, 30, 4) and grid.position_g.shape == (20, 30, 3)
        assert_allclose(grid.quaternion.reshape(-1, 4), whole[:600], rtol=0, atol=BLOCK_ATOL)


@pytest.mark.parametrize('name', sorted(NAMED))
def test_sign_convention_and_whole_cycles(name):
    cycle = _cycle(NAMED[name])
    q0 = cycle.poses(0.0).quaternion
    assert q0[3] > 0                                        # w > 0 at u = 0
    assert cycle.cycle_sign in (1.0, -1.0)
    # coarse arrays: after k whole cycles the continuous lift is (−ε)^k q (documented)
    u = 0.7 + TWO_PI * np.arange(-5, 6)
    q = cycle.poses(u).quaternion
    expected = q[5] * ((-cycle.cycle_sign) ** np.arange(-5, 6))[:, None]
    assert_allclose(q, expected, rtol=0, atol=CYCLE_ATOL)


# -- positions and the table evaluation ----------------------------------------------------------
@pytest.mark.parametrize('name', ['oloid', 'thin', 'tall'])
def test_positions_are_those_of_positions(name):
    cycle = _cycle(NAMED[name])
    u = np.linspace(-5 * TWO_PI, 5 * TWO_PI, 3 * cycle.BLOCK + 17)   # several blocks
    poses = cycle.poses(u)
    for got, expected in zip((poses.position_g, poses.contact_a, poses.contact_b),
                             cycle.positions(u)):
        assert_array_equal(got, expected)
    assert_allclose(poses.heading, cycle.heading(u), rtol=0, atol=1e-13)
    assert poses.heading.shape == u.shape


@settings(max_examples=20, deadline=None)
@given(st.integers(2, 40), st.integers(1, 5), st.integers(0, 2**31 - 1))
def test_combine_equals_call(nodes, columns, seed):
    rng = np.random.default_rng(seed)
    values, first, second = (rng.normal(size=(nodes + 1, columns)) for _ in range(3))
    table = HermiteTable(-1.0, 0.25, values, first, second)
    x = np.concatenate([rng.uniform(-1.0, -1.0 + 0.25 * nodes, 200),
                        -1.0 + 0.25 * np.arange(nodes + 1)])
    index, weights = table.weights(x)
    scale = np.max(np.abs(values)) + np.max(np.abs(first)) + np.max(np.abs(second))
    assert_allclose(table.combine(index, weights), table(x), rtol=0, atol=COMBINE_RTOL * scale)
    # the power basis (RollingCycle's path): the same interpolant, from coefficients of t
    assert_allclose(table.expand(*table.powers(x)), table(x), rtol=0, atol=COMBINE_RTOL * scale)
    # the same in reused work arrays (RollingCycle's blocks), a shorter block after a longer one
    scratch = table.scratch(x.size)
    assert_allclose(table.expand_into(x, scratch), table(x), rtol=0, atol=COMBINE_RTOL * scale)
    assert_allclose(table.expand_into(x[::-3], scratch), table(x[::-3]), rtol=0,
                    atol=COMBINE_RTOL * scale)
    # the nodes themselves are reproduced exactly
    assert_array_equal(table.combine(*table.weights(x[200:])), values)
    assert_array_equal(table.expand(*table.powers(x[200:-1])), values[:-1])
    assert_array_equal(table.expand_into(x[200:-1], scratch), values[:-1])

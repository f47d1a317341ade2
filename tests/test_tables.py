"""Quintic Hermite tables (physics/numerics/tables.py).

Reference: a quintic polynomial, which the quintic Hermite interpolant of its values and
first two derivatives at the nodes reproduces exactly (so f and f′ between the nodes are
the polynomial's own, to rounding).
"""

import numpy as np
import pytest

from twodisk_ros.physics.numerics.tables import HermiteTable

COEFFS = np.array([0.7, -1.3, 2.1, 0.4, -0.9, 0.25])     # p(x) = Σ c_k x^k


def _poly(x, d=0):
    return np.polyval(np.polyder(COEFFS[::-1], d) if d else COEFFS[::-1], x)


@pytest.mark.parametrize('derivative', [0, 1])
def test_batch_weights_reproduce_a_quintic_and_its_slope(derivative):
    nodes = np.linspace(-1.0, 2.0, 13)
    table = HermiteTable(nodes[0], nodes[1] - nodes[0], _poly(nodes), _poly(nodes, 1),
                         _poly(nodes, 2))
    x = np.random.default_rng(3).uniform(-1.0, 2.0, 200)
    got = table.combine(*table.weights(x, derivative))
    # exact for a quintic: rounding of values up to ~10 (1e-12 absolute)
    assert np.max(np.abs(got - _poly(x, derivative))) < 1e-12


def test_weights_refuse_a_second_derivative():
    table = HermiteTable(0.0, 1.0, np.zeros(3), np.zeros(3), np.zeros(3))
    with pytest.raises(ValueError, match='derivative must be 0 or 1'):
        table.weights(np.array([0.5]), 2)

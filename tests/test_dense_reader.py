"""numerics.dense.dense_reader against scipy's own OdeSolution (the reference it replaces):
the same values bit for bit (the same operations per time), in both directions of
integration, at the step boundaries and outside the span (scipy extrapolates the end steps)."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from twodisk_ros.physics.numerics.dense import dense_reader


@pytest.mark.parametrize('backward', [False, True])
@pytest.mark.parametrize('seed', range(4))
def test_values_are_scipys_bit_for_bit(seed, backward):
    rng = np.random.default_rng(seed)
    k, n = rng.uniform(0.5, 5.0), int(rng.integers(1, 5))

    def rhs(t, y):
        return -k * np.sin(y) + np.cos(t * np.arange(1, n + 1))
    span = (rng.uniform(5.0, 20.0), 0.0) if backward else (0.0, rng.uniform(5.0, 20.0))
    sol = solve_ivp(rhs, span, rng.normal(size=n), method='DOP853', rtol=1e-9,
                    dense_output=True).sol
    assert sol.n_segments > 10
    reader = dense_reader(sol)
    assert reader is not sol
    low, high = min(span), max(span)
    t = np.concatenate([rng.uniform(low - 1.0, high + 1.0, 2000), sol.ts,
                        np.nextafter(sol.ts, np.inf), np.nextafter(sol.ts, -np.inf)])
    rng.shuffle(t)
    expected, got = sol(t), reader(t)
    assert got.shape == expected.shape == (n, t.size)
    assert np.array_equal(got.view(np.int64), expected.view(np.int64))
    # scalars and empty arrays keep scipy's shapes
    assert np.array_equal(reader(t[0]), sol(t[0]))


def test_other_methods_are_left_to_scipy():
    sol = solve_ivp(lambda t, y: -y, (0.0, 1.0), [1.0], method='RK45', dense_output=True).sol
    assert dense_reader(sol) is sol

"""physics/numerics/vectors.py against numpy: ``cross`` against :func:`numpy.cross` (real, complex,
broadcast), ``vector`` against :func:`numpy.stack` (a copy of the values: exact)."""

import numpy as np
import pytest

from rounding import ulps
from twodisk_ros.physics.numerics.vectors import cross, vector


@pytest.mark.parametrize('shapes', [((3,), (3,)), ((7, 3), (7, 3)), ((4, 1, 3), (5, 3)),
                                    ((3,), (6, 3))])
@pytest.mark.parametrize('kind', [float, complex])
def test_cross_is_numpys(shapes, kind):
    """Each component is a difference of two rounded products: 16 ulps of |x| |y|."""
    rng = np.random.default_rng(7)

    def draw(shape):
        value = rng.normal(size=shape) * 10.0 ** rng.uniform(-3, 3, size=shape)
        return value + 1j * rng.normal(size=shape) if kind is complex else value
    x, y = draw(shapes[0]), draw(shapes[1])
    got, expected = cross(x, y), np.cross(x, y)
    assert got.shape == expected.shape and got.dtype == expected.dtype
    scale = np.linalg.norm(x, axis=-1)[..., None] * np.linalg.norm(y, axis=-1)[..., None]
    assert np.all(np.abs(got - expected) <= ulps(16, scale))
    # x × x = 0 and x × y = −(y × x): exactly for reals (the same rounded products, subtracted
    # the other way); a complex product's parts are sums whose order depends on the operand
    # order, so there to 16 ulps of |x|² and |x| |y|
    if kind is float:
        assert np.all(cross(x, x) == 0)
        np.testing.assert_array_equal(cross(y, x), -got)
    else:
        square = np.linalg.norm(x, axis=-1)[..., None] ** 2
        assert np.all(np.abs(cross(x, x)) <= ulps(16, square))
        assert np.all(np.abs(cross(y, x) + got) <= ulps(16, scale))


def test_vector_is_numpys_stack():
    rng = np.random.default_rng(3)
    x, y, z = (rng.normal(size=(4, 5)) for _ in range(3))
    np.testing.assert_array_equal(vector(x, y, z), np.stack([x, y, z], axis=-1))
    complex_z = z + 1j
    got = vector(x, y, complex_z)
    assert got.dtype == np.complex128
    np.testing.assert_array_equal(got, np.stack([x, y, complex_z], axis=-1))
    np.testing.assert_array_equal(vector(1.0, 2.0, 3.0), [1.0, 2.0, 3.0])

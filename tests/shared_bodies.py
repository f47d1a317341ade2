"""Lamina bodies that several test modules build alike, built once per test process.

Each xdist worker runs tests of many modules; a body built here is sampled once per worker
(LaminaBody's sampling costs ~0.5-1.5 s of CPU), not once per module that asks for it. The
same arguments give the same object, which the tests only read.
"""

import functools

from twodisk_ros.physics.bodies.lamina_body import LaminaBody
from twodisk_ros.physics.laminae.shapes import Superellipse
from twodisk_ros.physics.laminae.support import Egg

__all__ = ['egg_body', 'superellipse_body']


@functools.cache
def superellipse_body(a, b, n, delta, arrangement='parallel'):
    """LaminaBody(Superellipse(a, b, n), delta, arrangement) (m), shared."""
    return LaminaBody(Superellipse(a, b, n), delta, arrangement)


@functools.cache
def egg_body(a, b, epsilon, delta, arrangement='parallel'):
    """LaminaBody(Egg(a, b, epsilon), delta, arrangement) (m), shared."""
    return LaminaBody(Egg(a, b, epsilon), delta, arrangement)

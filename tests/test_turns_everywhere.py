"""The bodies' claim ``turns_everywhere`` (|ω_u| > 0 over the whole cycle), which picks the
chart in t for their stepped motions (physics/motion/integrate.py), checked against |ω_u|
sampled densely from each body's own phase functions, an independent evaluation of the claim.
"""

import numpy as np
import pytest

from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.bodies.lamina_body import LaminaBody
from twodisk_ros.physics.laminae.shapes import Superellipse
from twodisk_ros.physics.laminae.support import Egg
from twodisk_ros.physics.motion.closed_forms import REGULAR_RATE

PHASES = np.linspace(0.0, 2 * np.pi, 20001)


def _turn_rates(body, u=PHASES):
    return np.linalg.norm(body.phase_angular_velocity(u), axis=-1)


@pytest.mark.parametrize('b', [0.01, 0.1, 1.0, 10.0, 100.0])
@pytest.mark.parametrize('delta', [0.001, 0.5, 0.999])
def test_ellipse_turns_well_above_the_regular_threshold(b, delta):
    """Claim (closed_forms.REGULAR_RATE): an ellipse's |ω_u| stays above 2e-5 of its peak over
    b/a in [0.01, 100] and Δ/a in [0.001, 0.999] (measured 2.4e-5 at b/a 100, Δ/a 0.001), so u
    is regular for it everywhere, far above the threshold 1e-7 that marks a flat vertex."""
    body = EllipseBody(1.0, b, delta)
    rates = _turn_rates(body)
    assert body.turns_everywhere
    assert rates.min() >= 2e-5 * rates.max() >= 100 * REGULAR_RATE * rates.max()


def test_a_superellipse_with_flat_vertices_does_not_claim_it():
    """Claim: a body whose contacts cross a flat vertex (n = 4) stops turning there: |ω_u| at
    its flat-vertex phases is rounding (below REGULAR_RATE of the peak), and it says so."""
    body = LaminaBody(Superellipse(1.0, 0.7, 4.0), 0.3)
    assert not body.turns_everywhere
    vertices = body.flat_vertex_phases()
    assert len(vertices) > 0
    assert np.max(_turn_rates(body, vertices)) < REGULAR_RATE * _turn_rates(body,
                                                                          PHASES[::40]).max()


def test_an_egg_claims_it_and_turns_everywhere():
    """Claim: a lamina without flat vertices (an egg) turns at every phase."""
    body = LaminaBody(Egg(1.0, 0.8, 0.05), 0.4)
    rates = _turn_rates(body, PHASES[::20])
    assert body.turns_everywhere
    assert rates.min() > 1e-3 * rates.max()

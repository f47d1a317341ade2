"""The paper's closed forms at the equilibria (M g = 1), shared by the tests as references.

Paper, section 4, with the corrections of the physics notes.
"""

import math


def height_at_theta0(a, b, delta):
    """z_G at θ = 0 and at the turning points (m): b(a + Δ)/√(b² + 4aΔ + 4Δ²)."""
    return b * (a + delta) / math.sqrt(b * b + 4 * a * delta + 4 * delta * delta)


def curvature_at_theta0(a, b, delta):
    """d²z_G/dθ² at θ = 0 (m/rad²): a³(b² − 2a² + 2Δ²) / (b (b² + 4aΔ + 4Δ²)^{3/2})."""
    return a**3 * (b * b - 2 * a * a + 2 * delta**2) / (
        b * (b * b + 4 * a * delta + 4 * delta**2) ** 1.5)


def curvature_at_half_pi(a, b, delta):
    """d²z_G/dθ² at θ = π/2 (m/rad²): −√2 b³(b² − 2a² + 2Δ²) / (4a⁴)."""
    return -math.sqrt(2.0) * b**3 * (b * b - 2 * a * a + 2 * delta**2) / (4 * a**4)

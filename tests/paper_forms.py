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


def height_slope(a, b, delta, theta):
    """dz_G/dθ on either branch (m/rad): a³b³ sin θ cos θ (b² − 2a² + 2Δ²) / (D N³).

    D = √(a² sin²θ + b² cos²θ), N = √(a⁴ sin²θ + b⁴ cos²θ + Q) with Q = a⁴ sin²θ
    + 4abΔ cos θ D + 4b²Δ² cos²θ (clipped at 0: Q = 0 at the turning points θ = ±θ_max).
    """
    s, c = math.sin(theta), math.cos(theta)
    d = math.hypot(a * s, b * c)
    q = a**4 * s * s + 4 * a * b * delta * c * d + 4 * b * b * delta * delta * c * c
    n = math.sqrt(a**4 * s * s + b**4 * c * c + max(q, 0.0))
    return a**3 * b**3 * s * c * (b * b - 2 * a * a + 2 * delta * delta) / (d * n**3)

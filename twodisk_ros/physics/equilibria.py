"""Equilibria of the body on the plane and their stability (paper, section 4).

Over one cycle the height of G, z_G(u), has eight critical points: θ = 0 on both branches
(ψ = ±ψ_max), θ = ±π/2 on both branches, and the two turning points θ = ±θ_max (ψ = 0).
The turning points are equivalent to θ = 0 by the symmetry that swaps the disks, so their
natural coordinate is ψ. Stability alternates with the sign of b² − 2a² + 2Δ²
(docs/physics.md#equilibria-and-their-stability).
"""

from dataclasses import dataclass
import math

import numpy as np

from .analytic import complex_step
from .spectral import refine_grid, spectral_derivative_at, spectral_tail

__all__ = ['Equilibrium', 'equilibria', 'stability_map', 'STABLE', 'UNSTABLE', 'NEUTRAL']

STABLE, UNSTABLE, NEUTRAL = 'stable', 'unstable', 'neutral'

#: |b² − 2a² + 2Δ²| below this fraction of max(a, b)² is reported as neutral.
NEUTRAL_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Equilibrium:
    """One equilibrium of the body at rest on the plane."""

    name: str                 #: e.g. 'theta=0 (branch +1)'
    phase: float              #: u (rad) in [0, 2π)
    theta: float              #: θ (rad)
    psi: float                #: ψ (rad)
    branch: int               #: +1 / −1
    height: float             #: z_G (m)
    coordinate: str           #: 'theta' or 'psi': the coordinate of ``curvature``
    curvature: float          #: d²z_G/d(coordinate)² (m/rad²)
    phase_curvature: float    #: d²z_G/du² (m/rad²)
    stability: str            #: 'stable', 'unstable' or 'neutral'


def _height_phase_curvatures(body, phases):
    """d²z_G/du² at the given phases: spectral derivative of the complex-step dz_G/du.

    z_G is smooth and 2π-periodic in u; the grid is doubled until the upper half of the
    spectrum of dz_G/du is below 1e-13 of its peak (or dz_G/du vanishes: the neutral case).
    """
    def sample(n):
        u = 2 * math.pi * np.arange(n) / n
        slope = complex_step(body.phase_height, u)
        flat = np.max(np.abs(slope)) <= 1e-12 * body.size
        return (0.0 if flat else spectral_tail(slope)), slope
    _, slope = refine_grid(sample, 256, 2**17)
    return spectral_derivative_at(slope, phases)


def _psi_rate(body, u):
    """dψ/du near ψ = 0, where ψ = arctan(σ√Q / (−a² cos θ)) is analytic."""
    def psi_near_zero(x):
        _, cos_t, _, _ = body.phase_angles(x)
        return np.arctan(body.phase_signed_sqrt_q(x) / (-body.a**2 * cos_t))
    return float(complex_step(psi_near_zero, u))


def _classify(curvature, margin_is_zero):
    if margin_is_zero:
        return NEUTRAL
    return STABLE if curvature > 0 else UNSTABLE


def equilibria(body, neutral_tolerance=NEUTRAL_TOLERANCE):
    """All eight equilibria of one cycle, ordered by phase.

    Parameters
    ----------
    body : TwoDiskBody
    neutral_tolerance : float
        |b² − 2a² + 2Δ²| ≤ neutral_tolerance · max(a, b)² is reported as 'neutral'
        (z_G is then constant: the neutral case of the paper).

    Returns
    -------
    list of Equilibrium
    """
    neutral = abs(body.stability_margin) <= neutral_tolerance * max(body.a, body.b) ** 2
    u_half_pi = math.asin(min(1.0, (math.pi / 2) / body.eta_max))
    entries = [
        ('theta=0', 0.0), ('theta=+pi/2', u_half_pi), ('turning theta=+theta_max', math.pi / 2),
        ('theta=+pi/2', math.pi - u_half_pi), ('theta=0', math.pi),
        ('theta=-pi/2', math.pi + u_half_pi), ('turning theta=-theta_max', 1.5 * math.pi),
        ('theta=-pi/2', 2 * math.pi - u_half_pi),
    ]
    found = []
    phase_curvatures = _height_phase_curvatures(body, [u for _, u in entries])
    for (label, u), phase_curv in zip(entries, phase_curvatures):
        geo = body.phase_geometry(u)
        branch = 1 if math.cos(u) >= -1e-12 else -1
        if label.startswith('turning'):
            coordinate = 'psi'
            curvature = phase_curv / _psi_rate(body, u) ** 2
            branch = 1 if u < math.pi else -1
        else:
            coordinate = 'theta'
            theta = float(geo.theta)
            curvature = float(body.height_second_derivative(theta))
        found.append(Equilibrium(
            name=f'{label} (branch {branch:+d})', phase=u, theta=float(geo.theta),
            psi=float(geo.psi), branch=branch, height=float(geo.height), coordinate=coordinate,
            curvature=curvature, phase_curvature=phase_curv,
            stability=_classify(curvature, neutral)))
    return found


def stability_map(b_over_a, delta_over_a, neutral_tolerance=NEUTRAL_TOLERANCE):
    """Which family of equilibria is stable over a grid of shapes (a = 1).

    Parameters
    ----------
    b_over_a, delta_over_a : array_like
        Broadcast together; 0 < Δ/a < 1.

    Returns
    -------
    ndarray of int
        +1: θ = 0 and the turning points are stable (θ = ±π/2 unstable);
        −1: θ = ±π/2 are stable; 0: neutral (z_G constant). From the sign of
        b² − 2a² + 2Δ² (paper, V″ at θ = 0 and θ = π/2).
    """
    b = np.asarray(b_over_a, dtype=float)
    d = np.asarray(delta_over_a, dtype=float)
    margin = b * b - 2 + 2 * d * d
    scale = np.maximum(1.0, b * b)
    return np.where(np.abs(margin) <= neutral_tolerance * scale, 0, np.sign(margin)).astype(int)

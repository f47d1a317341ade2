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

from ..numerics.analytic import complex_step
from .certified import (certified_roots, classify_root, max_rotation_rate,
                                 root_series_curvatures)
from ..bodies.protocol import check_rolling_body
from ..numerics.spectral import node_sum, refine_grid, spectral_derivative_at, spectral_tail

__all__ = ['Equilibrium', 'EquilibriumArrays', 'equilibria', 'equilibria_batch', 'stability_map',
           'STABLE', 'UNSTABLE', 'NEUTRAL']

STABLE, UNSTABLE, NEUTRAL = 'stable', 'unstable', 'neutral'
TWO_PI = 2 * math.pi

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
    #: q of z_G − z* ≈ A|γ|^q, γ the body's turn about AB (2 for every ellipse equilibrium)
    order: float = 2.0
    #: d²z_G/dγ² (m/rad²) when q = 2 (nan for the ellipse path: use ``curvature``)
    gamma_curvature: float = math.nan
    #: A (m/rad^q) of z_G − z* ≈ A|γ|^q (nan for the ellipse path)
    leading: float = math.nan
    #: |ω_u(u*)| (rad per rad of u): 0 at a degenerate phase (the body does not turn in u)
    rotation_rate: float = math.nan

    @property
    def has_linear_period(self):
        """True if stable with z_G quadratic in the turn: a small-oscillation period exists."""
        return self.stability == STABLE and self.order == 2.0


def _height_phase_curvatures(body, phases):
    """d²z_G/du² at the given phases: spectral derivative of the complex-step dz_G/du.

    Used at the turning points; at θ = 0, ±π/2 :func:`equilibria` takes the exact
    (d²z_G/dθ²)(dθ/du)² instead, since within ~1e-3 a² of the neutral line the rounding noise
    of the samples dominates the spectrum (1e-9 relative at 1e-4 a², 1e-4 at 1e-8 a²).

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


def _psi_rates(body, u):
    """dψ/du near ψ = 0, where ψ = arctan(σ√Q / (−a² cos θ)) is analytic (arrays)."""
    def psi_near_zero(x):
        _, cos_t, _, _ = body.phase_angles(x)
        return np.arctan(body.phase_signed_sqrt_q(x) / (-body.a**2 * cos_t))
    return complex_step(psi_near_zero, u)


def _psi_rate(body, u):
    """dψ/du at one phase u (float)."""
    return float(_psi_rates(body, u))


def _entry_phases(eta_max):
    """The phases of the eight equilibria in order (θ = 0, +π/2, θ_max, +π/2, 0, −π/2, −θ_max,
    −π/2), from η_max (array) as in :func:`equilibria`; also u at θ = π/2."""
    u_half_pi = np.arcsin(np.minimum(1.0, (np.pi / 2) / eta_max))
    zero = np.zeros_like(u_half_pi)
    return [zero, u_half_pi, zero + np.pi / 2, np.pi - u_half_pi, zero + np.pi,
            np.pi + u_half_pi, zero + 1.5 * np.pi, 2 * np.pi - u_half_pi], u_half_pi


def _classify(curvature, margin_is_zero):
    if margin_is_zero:
        return NEUTRAL
    return STABLE if curvature > 0 else UNSTABLE


def equilibria(body, neutral_tolerance=NEUTRAL_TOLERANCE, certificate=False):
    """All equilibria of one cycle, ordered by phase.

    Parameters
    ----------
    body : RollingBody
        A :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody`: the eight equilibria at the
        ellipse's fixed angles (exact). Any other body: every root of dz_G/du over the cycle
        with a certificate that none is missed (:mod:`~twodisk_ros.physics.stability.certified`).
    neutral_tolerance : float
        Ellipse: |b² − 2a² + 2Δ²| ≤ neutral_tolerance · max(a, b)² is reported as 'neutral'
        (z_G is then constant: the neutral case of the paper). Other bodies:
        |d²z_G/dγ²| ≤ neutral_tolerance · size is 'neutral'.
    certificate : bool
        Also return the :class:`~twodisk_ros.physics.stability.certified.RootCertificate`
        (None for the ellipse, whose equilibria are known in closed form).

    Returns
    -------
    list of Equilibrium, or (list, RootCertificate or None)
    """
    check_rolling_body(body)
    found, proof = body.solve_equilibria(
        lambda searched: _general_equilibria(searched, neutral_tolerance),
        lambda known: (_ellipse_equilibria(known, neutral_tolerance), None))
    return (found, proof) if certificate else found


def _general_equilibria(body, neutral_tolerance):
    """Equilibria of any RollingBody: certified roots of dz_G/du, classified (module
    stability.certified)."""
    roots, proof = certified_roots(body)
    if not roots:
        return [], proof
    curvatures = root_series_curvatures(body, roots, proof.nodes)
    max_rate = max_rotation_rate(body, proof.nodes)
    phases = np.array([u for u, _, _ in roots])
    found = []
    for i, ((u, _, _), series_curv) in enumerate(zip(roots, curvatures)):
        if len(phases) > 1:
            gaps = np.abs(np.remainder(phases - u + math.pi, TWO_PI) - math.pi)
            reach = 0.5 * float(np.min(np.delete(gaps, i)))
        else:
            reach = math.pi / 2
        local = classify_root(body, float(series_curv), u, min(reach, math.pi / 4), max_rate)
        geo = body.phase_geometry(u)
        if local['order'] == 2.0:
            curvature = local['gamma_curvature']
            stability = (NEUTRAL if abs(curvature) <= neutral_tolerance * body.size
                         else STABLE if curvature > 0 else UNSTABLE)
        else:
            curvature = math.nan
            stability = STABLE if local['leading'] > 0 else UNSTABLE
        branch = int(geo.branch)
        found.append(Equilibrium(
            name=f'theta={float(geo.theta):+.6f} (branch {branch:+d})', phase=float(u),
            theta=float(geo.theta), psi=float(geo.psi), branch=branch,
            height=float(geo.height), coordinate='gamma', curvature=curvature,
            phase_curvature=0.0 if local['degenerate'] else float(series_curv),
            stability=stability, order=local['order'], gamma_curvature=curvature,
            leading=local['leading'], rotation_rate=local['rate']))
    return found, proof


def _ellipse_equilibria(body, neutral_tolerance):
    """The eight equilibria of the ellipse at their fixed angles (exact)."""
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
        else:   # dz_G/dθ = 0: d²z_G/du² = (d²z_G/dθ²)(dθ/du)², exact also near neutral
            coordinate = 'theta'
            theta = float(geo.theta)
            curvature = float(body.height_second_derivative(theta))
            phase_curv = curvature * float(body.phase_angles_with_rates(u)[2]) ** 2
        # the body turns in u everywhere (|ω_u| > 0): d²z_G/dγ² = (d²z_G/du²) / |ω_u|²
        rate = float(np.linalg.norm(body.phase_angular_velocity(u)))
        found.append(Equilibrium(
            name=f'{label} (branch {branch:+d})', phase=u, theta=float(geo.theta),
            psi=float(geo.psi), branch=branch, height=float(geo.height), coordinate=coordinate,
            curvature=curvature, phase_curvature=phase_curv,
            stability=_classify(curvature, neutral), gamma_curvature=phase_curv / rate**2,
            rotation_rate=rate))
    return found


@dataclass(frozen=True)
class EquilibriumArrays:
    """The eight equilibria of B bodies (:func:`equilibria_batch`); rows in the order of
    :func:`equilibria`, columns the bodies."""

    phase: np.ndarray             #: u (rad), (8, B)
    theta: np.ndarray             #: θ (rad), (8, B)
    height: np.ndarray            #: z_G (m), (8, B)
    curvature: np.ndarray         #: d²z_G/dθ² (rows θ) or d²z_G/dψ² (turning points), (8, B)
    phase_curvature: np.ndarray   #: d²z_G/du² (m/rad²), (8, B)
    stable: np.ndarray            #: bool (8, B): the equilibrium is stable
    neutral: np.ndarray           #: bool (B,): the body is neutral (every entry 'neutral')


def equilibria_batch(bodies, slope, neutral_tolerance=NEUTRAL_TOLERANCE):
    """:func:`equilibria` of a batch of bodies at once (arrays instead of a list).

    Ellipses only (EllipseBodies: the eight equilibria at the fixed angles); a batch of other
    bodies takes :func:`equilibria` body by body.

    Parameters
    ----------
    bodies : EllipseBodies
        B bodies (:mod:`~twodisk_ros.physics.bodies.ellipse_batch`).
    slope : ndarray, shape (N, B)
        dz_G/du (m/rad) at u_j = 2πj/N, N a multiple of 4, resolved (e.g.
        :attr:`~twodisk_ros.physics.bodies.ellipse_batch.CycleSamples.height_slope` on a cycle's
        table nodes): d²z_G/du² at the turning points is its spectral derivative, as in
        :func:`equilibria`.
    neutral_tolerance : float
        As in :func:`equilibria`.

    Returns
    -------
    EquilibriumArrays

    Notes
    -----
    At the six equilibria θ = 0, ±π/2, where dz_G/dθ = 0, d²z_G/du² = (d²z_G/dθ²)(dθ/du)²
    with both factors by complex step of closed forms (the paper's V′ carries the factor
    b² − 2a² + 2Δ²): exact to rounding, also near the neutral line. :func:`equilibria` takes the
    same product; the spectral derivative of dz_G/du, which both use at the turning points,
    would lose digits here within ~1e-3 a² of the neutral line (1e-9 relative at 1e-4 a²,
    1e-4 at 1e-8 a²), where the rounding noise of the samples (~1e-16 a) dominates its
    spectrum.
    """
    n = slope.shape[0]
    neutral = np.abs(bodies.stability_margin) <= neutral_tolerance * np.maximum(
        bodies.a, bodies.b) ** 2
    phases, _ = _entry_phases(bodies.eta_max)
    phase = np.stack(phases)
    geo = bodies.phase_geometry(phase)
    curvature = np.empty(phase.shape)
    phase_curvature = np.empty(phase.shape)
    rows, turning = [0, 1, 3, 4, 5, 7], [2, 6]
    curvature[rows] = bodies.height_second_derivative(geo.theta[rows])
    theta_rate = bodies.phase_angles_with_rates(phase[rows])[2]
    phase_curvature[rows] = curvature[rows] * theta_rate**2
    # turning points u = π/2, 3π/2 (nodes): Re Σ i k c_k e^{iku}, e^{ikπ/2} = i^k (N % 4 == 0)
    k = np.fft.fftfreq(n, d=1.0 / n)[:, None]
    coeffs = np.fft.fft(slope, axis=0) / n
    coeffs[n // 2] = 0.0
    quarter = (1j ** (np.arange(n) % 4))[:, None]
    weighted = 1j * k * coeffs
    phase_curvature[turning] = [np.real(node_sum(weighted * quarter)),
                                np.real(node_sum(weighted * quarter.conj()))]
    curvature[turning] = phase_curvature[turning] / _psi_rates(bodies, phase[turning]) ** 2
    stable = ~neutral & (curvature > 0)
    return EquilibriumArrays(phase=phase, theta=geo.theta, height=geo.height,
                             curvature=curvature, phase_curvature=phase_curvature,
                             stable=stable, neutral=neutral)


def stability_map(b_over_a, delta_over_a, neutral_tolerance=NEUTRAL_TOLERANCE):
    """Which family of equilibria is stable over a grid of shapes (a = 1).

    Ellipses only (the paper's margin b² − 2a² + 2Δ²); for other laminae the symmetric
    equilibria's stability is :mod:`~twodisk_ros.physics.stability.symmetric`.

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

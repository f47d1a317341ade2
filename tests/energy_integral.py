"""An independent reference for a free rolling motion on level ground: the energy integral.

With no losses, E = ½ m(u) u̇² + V(u) is constant, so u̇(u) = √(2 (E − V(u)) / m(u)) and the
time to reach u is t(u) = ∫ du / u̇(u). Here the integral is taken by composite
Gauss–Legendre quadrature (16 nodes on panels of at most PANEL rad, all nodes in one array
evaluation; checked against the same rule on panels half as wide, to 1e-13 relative) from
the dynamics' closed-form m(u) and V(u): it shares no code with the solvers, tables or closed
forms that produce u(t). For a motion that rolls over (u̇ never 0 on the stretch).
"""


import numpy as np


#: the widest panel (rad) of :func:`times_to`: a few hundredths of the bodies' sharpest
#: features in u (width ~min(1, b/a, a/b, 2√(Δ/a)), 1 for the oloid); 16 Gauss nodes on it
#: integrate the analytic 1/u̇(u) to rounding
PANEL = 0.05
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(16)


def phase_rate(dynamics, energy, u):
    """u̇(u) (rad/s) of a motion of energy ``energy`` (J) at the phases ``u`` (rad), shape
    u.ravel(): the closed forms at all phases in one array evaluation."""
    u = np.ravel(np.asarray(u, dtype=float))
    return np.sqrt(2.0 * (energy - dynamics.potential(u)) / dynamics.effective_mass(u))


def times_to(dynamics, energy, u0, u):
    """t(u_k) − t(u0) (s) for the increasing phases ``u`` (rad), by the energy integral."""
    bounds = np.r_[u0, np.asarray(u, dtype=float)]
    coarse, fine = (_integral(dynamics, energy, bounds, width) for width in (PANEL, PANEL / 2))
    # the rule has converged: halving the panels moves no time by more than 1e-13 relative
    assert np.all(np.abs(fine - coarse) <= 1e-13 * np.abs(fine)), np.max(np.abs(fine - coarse))
    return fine


def _integral(dynamics, energy, bounds, width):
    """Σ over the stretches bounds[k] → bounds[k + 1] of ∫ du / u̇ (s), cumulated: composite
    Gauss–Legendre on ⌈length/width⌉ equal panels a stretch."""
    panels = np.maximum(np.ceil(np.diff(bounds) / width).astype(int), 1)
    stretch = np.repeat(np.arange(panels.size), panels)
    index = np.arange(stretch.size) - np.repeat(np.cumsum(panels) - panels, panels)
    h = (np.diff(bounds) / panels)[stretch]
    left = bounds[:-1][stretch] + index * h
    x = left[:, None] + 0.5 * h[:, None] * (_NODES + 1.0)
    rate = phase_rate(dynamics, energy, x).reshape(x.shape)
    sums = 0.5 * h * ((_WEIGHTS / rate).sum(axis=1))
    return np.cumsum(np.bincount(stretch, sums, minlength=panels.size))

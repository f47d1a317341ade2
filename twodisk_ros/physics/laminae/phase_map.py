"""The phase parameter of a lamina: its boundary parameter re-spaced for the regular phase.

docs/physics.md#the-phase-of-a-general-body. The regular phase u
(:mod:`~twodisk_ros.physics.bodies.regular_phase`) is the polar angle of the contacts' parameters;
every function of the cycle is then as smooth in u as the laminae's points are in those
parameters. A superellipse |x/b|ⁿ + |y/a|ⁿ ≤ 1 is only C^⌊n⌋ at its four vertices
(|s|ⁿ terms in its points when n is not an even integer), and for large n its corners (at
s = ±π/4, ±3π/4 of its radial parameter s) are curved within ~π/(2n) of s. Both limit a
Fourier series in s: algebraically (coefficients ~ k^−(n+1)) and through a nearby complex
singularity (~ e^(−πk/(2n))). So the phase is built on a phase parameter t, s = w(t), with
w a composition of maps

    w_α(t) = t − α sin(4t)/4,    w_α′(t) = 1 − α cos 4t,

each odd, increasing, entire, with w_α(t + π/2) = w_α(t) + π/2 (the vertices kπ/2 and the
diagonals π/4 + kπ/2 are fixed). α = 1 stops at the vertices: s − kπ/2 ≈ (8/3)(t − kπ/2)³,
so |s − kπ/2|ⁿ becomes |t − kπ/2|^(3n) (three times the derivatives; nested d times,
3^d n). α < 0 dwells at the corners: w′ = 1 − |α| there, 1 + |α| at the vertices, spreading
the corner's curvature over 1/(1 − |α|) times more of t. Other laminae (ellipse, egg,
fitted outline) are analytic in their parameters and keep t = s. Each lamina gives its own
map (``Lamina.phase_map``); this module holds the maps and the superellipse's rule.
"""

import math

import numpy as np

__all__ = ['CORNER_ASPECT', 'CORNER_DWELL', 'CORNER_EXPONENT', 'PhaseMap', 'VERTEX_SMOOTHNESS',
           'superellipse_phase_map']

HALF_PI = 0.5 * math.pi
#: Nested vertex maps (α = 1) for a superellipse of non-even exponent n < this: the least
#: number d with 3^d n ≥ VERTEX_SMOOTHNESS (|t|^12 is far smoother than the spectra resolve;
#: measured in docs/physics.md: more nesting only coarsens the grid elsewhere).
VERTEX_SMOOTHNESS = 12.0
#: From this exponent on, the corners are the sharpest feature: one corner map α = −CORNER_DWELL,
#: for aspect ratios b/a within CORNER_ASPECT (beyond, the ends of the long thin lamina are
#: sharper still and the map's thinning there costs more than it gains: docs/physics.md).
CORNER_EXPONENT = 16.0
CORNER_DWELL = 0.8
CORNER_ASPECT = (0.1, 10.0)


class PhaseMap:
    """s = w(t), the composition of w_α for the ``alphas`` in order (module docstring).

    Parameters
    ----------
    alphas : sequence of float
        Each 1 (stop at the vertices) or in [−1, 1) (α < 0: dwell at the corners); empty: the
        identity.
    """

    def __init__(self, alphas=()):
        self.alphas = tuple(float(a) for a in alphas)
        if not all(a == 1.0 or -1.0 < a < 1.0 for a in self.alphas):
            raise ValueError(f'alphas must each be 1 or in (-1, 1), got {alphas!r}')

    def __repr__(self):
        return f'PhaseMap({self.alphas!r})'

    @property
    def stops_at_vertices(self):
        """True when w′ = 0 at the vertices kπ/2 (some α = 1)."""
        return 1.0 in self.alphas

    def __call__(self, t):
        """s = w(t) (rad), any shape (real)."""
        s = np.asarray(t, dtype=float)
        for alpha in reversed(self.alphas):
            s = _w(s, alpha)
        return s

    def derivative(self, t):
        """ds/dt = w′(t), any shape."""
        s = np.asarray(t, dtype=float)
        rate = np.ones_like(s)
        for alpha in reversed(self.alphas):
            rate = rate * (1.0 - alpha * np.cos(4.0 * s))
            s = _w(s, alpha)
        return rate

    def inverse(self, s):
        """t = w⁻¹(s) (rad), any shape: Newton's method on each map, reduced to the nearest
        vertex kπ/2 (exact there).

        Near a vertex of a map that stops there t − kπ/2 ~ (s − kπ/2)^(1/3): a rounding error
        δ of s moves t by up to δ^(1/3) (per nesting), but the functions of t are as flat
        there, so the point of the curve that t names moves by about δ only.
        """
        s = np.asarray(s, dtype=float)
        if not self.alphas:
            return s
        k = np.round(s / HALF_PI)
        t = s - k * HALF_PI
        for alpha in self.alphas:
            t = _inverse_once(t, alpha)
        return t + k * HALF_PI


def _x_minus_sin(x):
    """x − sin x (no cancellation for small |x|: its series there)."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1.0
    xs = np.where(small, x, 0.0)
    x2 = xs * xs
    term, total = xs * x2 / 6.0, 0.0
    for j in range(2, 13):                     # x³/3! − x⁵/5! + …, to x²⁵/25! < 1e-25 x³
        total = total + term
        term = -term * x2 / ((2 * j) * (2 * j + 1))
    return np.where(small, total, x - np.sin(x))


def _w(t, alpha):
    """w_α(t) = t − α sin(4t)/4 (for α = 1 without cancellation near the vertices)."""
    if alpha == 1.0:
        return _x_minus_sin(4.0 * t) / 4.0
    return t - 0.25 * alpha * np.sin(4.0 * t)


def _inverse_once(s, alpha):
    """t ∈ [−π/4, π/4] with w_α(t) = s ∈ [−π/4, π/4].

    w_α is odd; on [0, π/4] it is convex for α > 0 and concave for α < 0, so Newton's method
    from t = s (for α = 1 from the vertex's cubic, (3s/8)^(1/3)) crosses the root at most once
    and then converges monotonically.
    """
    target = np.abs(s)
    t = np.cbrt(3.0 * target / 8.0) if alpha == 1.0 else target.copy()
    for _ in range(100):
        slope = (2.0 * np.sin(2.0 * t) ** 2 if alpha == 1.0
                 else 1.0 - alpha * np.cos(4.0 * t))
        f = _w(t, alpha) - target
        step = np.divide(f, slope, out=np.zeros_like(t), where=slope > 0)
        t = np.clip(t - step, 0.0, 0.25 * math.pi)
        if np.all(np.abs(step) <= 8 * np.finfo(float).eps * t):   # the last bits
            break
    return np.copysign(t, s)


def superellipse_phase_map(n, aspect):
    """The :class:`PhaseMap` of a superellipse of exponent n and aspect ratio b/a (module
    docstring): for a non-even n < VERTEX_SMOOTHNESS, d vertex maps with 3^d n ≥
    VERTEX_SMOOTHNESS; for n ≥ CORNER_EXPONENT one corner map (b/a within CORNER_ASPECT);
    otherwise the identity."""
    if n >= CORNER_EXPONENT:
        low, high = CORNER_ASPECT
        return PhaseMap((-CORNER_DWELL,) if low <= aspect <= high else ())
    alphas = []
    if n % 2.0 != 0.0:
        while 3.0 ** len(alphas) * n < VERTEX_SMOOTHNESS:
            alphas.append(1.0)
    return PhaseMap(alphas)

"""Equilibria of any rolling body: every root of dz_G/du over one cycle, with a certificate.

For a :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody` :func:`equilibria.equilibria` uses the
eight fixed angles of the ellipse; every other :class:`~twodisk_ros.physics.bodies.protocol.
RollingBody` comes here (docs/physics.md#equilibria-of-any-body).

**The search.** f(u) = dz_G/du (m/rad, complex step of ``phase_height``) is sampled on N
nodes, N doubled until its spectrum is resolved (upper half below 1e-13 of the peak, or at
its noise floor). Its trigonometric interpolant f_N has coefficients c_k, so on an interval
of half-width r about a centre c, by Taylor's theorem,

    |f_N(u)| ≥ |f_N(c)| − Σ_{j=1}^{K−1} |f_N^(j)(c)| r^j / j! − B_K r^K / K!,
    B_K = Σ_k |k|^K |c_k| ≥ max |f_N^(K)|,

and |f − f_N| ≤ ε, ε = 2 Σ_{|k|>N/4} |c_k| + 64 ulp · max |f| (the unresolved spectrum is
below its resolved upper half: geometric decay; plus the samples' rounding). An interval
where that lower bound exceeds ε holds no root of f: **certified root-free**. Starting from
the N intervals between nodes, every other interval is bisected until it is certified, or
|f_N| ≤ ε at its centre (f is below its own accuracy there), or it is narrower than 1e-13 rad.
The uncertified pieces are merged into clusters: each root of f lies in a cluster. A cluster
with a sign change of f between its ends holds an odd number of roots (counted as one
equilibrium, located by bisection of f's sign); one without holds none or an even number
(reported in the certificate, not as an equilibrium). K = 4. The jets f_N^(j)(c) of one
bisection level are read off one zero-padded inverse FFT per derivative when the level has
many intervals (its centres are the odd points of a grid of M = 2π/r points), else summed
directly over the half spectrum: the same values to rounding, O(M log M) instead of O(N²). A bracket holding a phase
where a contact sits on a flat vertex (:func:`flat_vertex_phases`) has its root snapped to
that phase, exact by construction: bisection stops ~1e-5 rad off there, where z_G − z* ~
(u − u*)⁴ or flatter is below rounding.

**Stability.** At a root u* where the body turns (|ω_u| ≠ 0), d²z_G/du² is the series'
derivative and, γ being the angle the body has turned about the contact line AB (dγ/du =
|ω_u|), d²z_G/dγ² = (d²z_G/du²)/|ω_u|². Where |ω_u(u*)| vanishes (a degenerate phase, e.g. a
contact on a superellipse's flat vertex) u is not a physical coordinate; z_G − z* is then
taken as a function of γ (both by Gauss quadrature from u*, no cancellation), its order q
from z_G − z* = w ≈ A|γ|^q + Bγ²: two levels that give q ≈ 2 give d²z_G/dγ² from a
polynomial fit of w/γ²; otherwise q and A come from three levels γ_j (1e-3 rad, ratio 1/4)
with the γ² term cancelled, r_j = w_{j+1} − (γ_{j+1}/γ_j)² w_j = A γ_j^q (ρ^q − ρ²) (a plain
two-level ratio was off by 0.2 at the tips of Superellipse n = 3: Bγ² is not small there),
and q < 2 gives stability from the sign of A and **no linear small-oscillation period**. An
exponent n within ~0.05 of 2 (q = n/(n − 1) near 2, its well (A/|B|)^(1/(2−q)) below 1e-4
rad) is seen as quadratic, Bγ², at the levels rounding allows.
"""

from dataclasses import dataclass
import math

import numpy as np

from ..numerics.analytic import complex_step
from ..numerics.spectral import refine_grid, spectral_tail

__all__ = ['RootCertificate', 'certified_roots', 'classify_root', 'flat_vertex_phases',
           'max_rotation_rate',
           'root_series_curvatures', 'TAYLOR_ORDER']

TAYLOR_ORDER = 4
#: narrowest interval bisected (rad)
MIN_HALF_WIDTH = 5e-14
#: |ω_u(u*)| below this fraction of its maximum: a degenerate phase (classified in γ)
DEGENERATE_RATE = 1e-6
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(24)
TWO_PI = 2 * math.pi
#: Gauss panels of the quadratures from u* (_local_samples)
PANELS = 4
#: the order's probe levels: PROBE_GAMMA·PROBE_RATIO^j (rad), j = 0, 1, 2, on each side,
#: reached within PROBE_SPAN (rad) of u*
PROBE_GAMMA, PROBE_RATIO, PROBE_SPAN = 1e-3, 0.25, 0.5 * math.pi
#: relative accuracy of the γ levels of the local fit (_offsets_for)
OFFSET_RTOL = 1e-8
#: offsets reach·2^−j, j < LADDER_STEPS, bracketing the γ levels (_offsets_for)
LADDER_STEPS = 48
#: largest grid evaluated by FFT in the interval search (points)
MAX_GRID = 2**22


@dataclass(frozen=True)
class RootCertificate:
    """Why no root of dz_G/du over the cycle is missed (module docstring)."""

    nodes: int             #: N, samples of dz_G/du over one cycle
    order: int             #: K of the Taylor bound
    derivative_bound: float  #: B_K = Σ |k|^K |c_k| (m/rad^(K+1))
    error_bound: float     #: ε (m/rad): |f − f_N| assumed below it
    intervals: int         #: intervals examined (the N initial ones and their bisections)
    brackets: tuple        #: ((low, high), ...) clusters with a sign change (rad)
    unsigned: tuple        #: ((low, high), ...) clusters without a sign change (rad)
    flat: bool             #: |dz_G/du| ≤ ε everywhere: z_G constant to accuracy

    @property
    def complete(self):
        """True: every root lies in a bracket (no unsigned cluster, not flat)."""
        return not self.unsigned and not self.flat

    def statement(self):
        """One line: the certificate in words."""
        if self.flat:
            return f'dz_G/du is within its accuracy {self.error_bound:.2g} m/rad of 0: flat'
        return (f'{len(self.brackets)} sign changes of dz_G/du, every other interval of the '
                f'cycle certified root-free (N = {self.nodes}, Taylor order {self.order}, '
                f'B = {self.derivative_bound:.3g}, eps = {self.error_bound:.2g}); '
                f'{len(self.unsigned)} clusters without a sign change')


class _Series:
    """The trigonometric interpolant of N real samples and its derivatives anywhere."""

    def __init__(self, samples):
        n = len(samples)
        coeffs = np.fft.fft(samples) / n
        coeffs[n // 2] = 0.0
        self.k = np.fft.fftfreq(n, d=1.0 / n)
        self.c = coeffs
        # real samples: c_{−k} = conj(c_k), so f_N = Re Σ_{0 ≤ k < N/2} w_k c_k e^{ikx}
        self._half_k = np.arange(n // 2, dtype=float)
        self._half_c = coeffs[:n // 2] * np.where(self._half_k > 0, 2.0, 1.0)

    def jets(self, x, order):
        """f_N^(j)(x) for j < order: array (order, len(x)), by direct summation."""
        x = np.asarray(x, dtype=float)
        out = np.empty((order, x.size))
        k = self._half_k
        weights = np.array([self._half_c * (1j * k) ** j for j in range(order)]).T
        for start in range(0, x.size, 256):
            part = x[start:start + 256]
            e = np.exp(1j * np.outer(part, k))
            out[:, start:start + 256] = np.real(e @ weights).T
        return out

    def grid_jets(self, points, order):
        """f_N^(j)(2πm/M) for j < order on all M points of a fine grid (M ≥ N, a multiple
        of N), by one zero-padded inverse FFT per derivative: array (order, M)."""
        index = self.k.astype(int) % points
        out = np.empty((order, points))
        padded = np.zeros(points, dtype=complex)
        for j in range(order):
            padded[index] = self.c * (1j * self.k) ** j
            out[j] = np.real(np.fft.ifft(padded)) * points
        return out

    def jets_at_grid(self, centres, half_width, order):
        """:meth:`jets` at centres that are odd multiples of ``half_width`` = 2π/M (the
        intervals of one bisection level), by :meth:`grid_jets` when the M-point FFT is
        cheaper than summing the series at every centre; the same values to rounding."""
        points = int(round(TWO_PI / half_width))
        if (points > MAX_GRID or abs(points * half_width - TWO_PI) > 1e-12
                or len(centres) * self.k.size <= points * math.log2(points)):
            return self.jets(centres, order)
        grid = self.grid_jets(points, order)
        return grid[:, np.rint(np.asarray(centres) / half_width).astype(int) % points]


def _slope_samples(body, n):
    u = TWO_PI * np.arange(n) / n
    return complex_step(body.phase_height, u)


def certified_roots(body):
    """(roots, certificate): the phases u* ∈ [0, 2π) where dz_G/du changes sign.

    Parameters
    ----------
    body : RollingBody

    Returns
    -------
    roots : list of (float, float, float)
        (u*, low, high): the root located by bisection of the sign of dz_G/du and its cluster.
    certificate : RootCertificate
    """
    scale = body.size

    def sample(n):
        f = _slope_samples(body, n)
        flat = np.max(np.abs(f)) <= 1e-14 * scale
        return (0.0 if flat else spectral_tail(f)), f
    n, f = refine_grid(sample, 256, 2**17, floor=1e-9)
    series = _Series(f)
    k_abs, c_abs = np.abs(series.k), np.abs(series.c)
    order = TAYLOR_ORDER
    bound = float(np.sum(k_abs**order * c_abs))
    eps = 2 * float(np.sum(c_abs[k_abs > n // 4])) + 64 * np.finfo(float).eps * float(
        np.max(np.abs(f)))
    h = TWO_PI / n
    factorials = np.array([math.factorial(j) for j in range(order + 1)], dtype=float)

    def lower_bounds(centres, r):
        jets = series.jets_at_grid(centres, r, order)
        powers = r ** np.arange(order)[:, None] / factorials[:order, None]
        taylor = np.sum(np.abs(jets[1:]) * powers[1:], axis=0)
        return np.abs(jets[0]) - taylor - bound * r**order / factorials[order], jets[0]

    todo_c = (np.arange(n) + 0.5) * h
    r = h / 2
    leaves = []            # (low, high, certified)
    examined = 0
    while todo_c.size:
        examined += todo_c.size
        low_bound, value = lower_bounds(todo_c, r)
        good = low_bound > eps
        stop = ~good & ((np.abs(value) <= eps) | (r < MIN_HALF_WIDTH))
        for c in todo_c[good]:
            leaves.append((c - r, c + r, True))
        for c in todo_c[stop]:
            leaves.append((c - r, c + r, False))
        rest = todo_c[~good & ~stop]
        r = r / 2
        todo_c = np.concatenate([rest - r, rest + r])
    leaves.sort()
    if not any(cert for _, _, cert in leaves):
        return [], RootCertificate(n, order, bound, eps, examined, (), (), True)
    # rotate so that the list starts with a certified interval, then merge the others
    first = next(i for i, leaf in enumerate(leaves) if leaf[2])
    leaves = leaves[first:] + [(lo + TWO_PI, hi + TWO_PI, c) for lo, hi, c in leaves[:first]]
    clusters = []
    for lo, hi, cert in leaves:
        if cert:
            continue
        if clusters and abs(clusters[-1][1] - lo) <= 1e-15 * TWO_PI:
            clusters[-1][1] = hi
        else:
            clusters.append([lo, hi])
    brackets, unsigned, roots = [], [], []
    flat_phases = flat_vertex_phases(body)
    for lo, hi in clusters:
        ends = series.jets([lo, hi], 1)[0]
        if ends[0] * ends[1] < 0:
            brackets.append((lo % TWO_PI, hi % TWO_PI))
            inside = flat_phases[np.mod(flat_phases - lo, TWO_PI) <= hi - lo]
            root = (float(inside[0]) if inside.size
                    else _bisect_sign(body, lo, hi, ends[0] > 0))
            roots.append((root % TWO_PI, lo % TWO_PI, hi % TWO_PI))
        else:
            unsigned.append((lo % TWO_PI, hi % TWO_PI))
    roots.sort()
    certificate = RootCertificate(n, order, bound, eps, examined, tuple(sorted(brackets)),
                                  tuple(sorted(unsigned)), False)
    return roots, certificate


def flat_vertex_phases(body):
    """The phases u ∈ [0, 2π) (rad) where a contact sits on a flat vertex (zero curvature).

    There z_G − z* ~ |u − u*|^(2q) with the body not turning (|ω_u| = 0), so dz_G/du is flat
    to rounding and bisection of its sign stops up to ~1e-5 rad off; a signed cluster that
    holds one of these phases has its root there (dz_G/du = |ω_u| dz_G/dγ vanishes at it, and
    changes sign there if anywhere in the cluster). The body's own
    :meth:`~twodisk_ros.physics.bodies.protocol.RollingBody.flat_vertex_phases`, in [0, 2π).
    """
    return np.mod(np.asarray(body.flat_vertex_phases(), dtype=float), TWO_PI)


def _bisect_sign(body, low, high, positive_low):
    """A sign change of dz_G/du (the true function) between low and high (rad)."""
    for _ in range(200):
        mid = 0.5 * (low + high)
        if not low < mid < high:
            break
        value = float(complex_step(body.phase_height, mid))
        if value == 0.0:
            return mid
        if (value > 0) == positive_low:
            low = mid
        else:
            high = mid
    return 0.5 * (low + high)


def _rotation_rate(body, u):
    return np.linalg.norm(body.phase_angular_velocity(np.asarray(u, dtype=float)), axis=-1)


def _local_samples(body, centre, offsets):
    """(γ, z_G − z*) at u* + offsets by composite Gauss quadrature (:data:`PANELS` equal
    panels) of |ω_u| and dz_G/du from u*."""
    offsets = np.asarray(offsets, dtype=float)
    x = ((np.arange(PANELS)[:, None] + 0.5 * (1 + _GAUSS_X)) / PANELS).ravel()
    u = centre + offsets[:, None] * x
    w = 0.5 * np.tile(_GAUSS_W, PANELS) / PANELS * offsets[:, None]
    gamma = np.sum(w * _rotation_rate(body, u), axis=1)
    rise = np.sum(w * complex_step(body.phase_height, u), axis=1)
    return gamma, rise


def _offsets_for(body, centre, targets, reach):
    """Offsets δ (signed, rad) with γ(u* + δ) = targets to 1e-8 relative: a vectorised
    Newton iteration on log|γ| against log|δ| (dγ/dδ = |ω_u(u* + δ)|; near a degenerate
    phase γ is a power of δ, a straight line there), from a bracket and guess read off a
    geometric ladder of offsets, safeguarded by geometric bisection of the bracket. The
    callers use the γ actually reached, so the levels need not be exact."""
    targets = np.asarray(targets, dtype=float)
    side, goal = np.sign(targets), np.abs(targets)
    # bracket and first guess from |γ| on a geometric ladder of offsets (log-log interpolation)
    ladder = reach * 0.5 ** np.arange(LADDER_STEPS)
    low, high = np.zeros(targets.size), np.full(targets.size, reach)
    x = 0.5 * (low + high)
    for sign in (-1.0, 1.0):
        mine = side == sign
        if not np.any(mine):
            continue
        reached = np.abs(_local_samples(body, centre, sign * ladder)[0])[::-1]  # increasing
        steps = ladder[::-1]
        at = np.clip(np.searchsorted(reached, goal[mine]), 1, LADDER_STEPS - 1)
        g0, g1, s0, s1 = reached[at - 1], reached[at], steps[at - 1], steps[at]
        low[mine], high[mine] = np.where(g0 <= goal[mine], s0, 0.0), np.where(
            g1 >= goal[mine], s1, reach)
        with np.errstate(divide='ignore', invalid='ignore'):
            guess = s0 * np.exp(np.log(goal[mine] / g0) * np.log(s1 / s0) / np.log(g1 / g0))
        fine = np.isfinite(guess) & (guess > low[mine]) & (guess < high[mine])
        x[mine] = np.where(fine, guess, 0.5 * (low[mine] + high[mine]))
    todo = np.ones(targets.size, dtype=bool)
    for _ in range(60):
        gamma, _ = _local_samples(body, centre, side[todo] * x[todo])
        reached = np.abs(gamma)
        miss = np.log(reached / goal[todo])
        done = np.abs(miss) <= OFFSET_RTOL
        lo, hi, xs = low[todo], high[todo], x[todo]
        lo, hi = np.where(miss < 0, xs, lo), np.where(miss < 0, hi, xs)
        # Newton on log|γ| against log|δ| (a power law near a degenerate phase: ~linear)
        slope = xs * _rotation_rate(body, centre + side[todo] * xs) / reached
        with np.errstate(divide='ignore', invalid='ignore', over='ignore'):
            newton = xs * np.exp(-miss / slope)
        inside = np.isfinite(newton) & (newton > lo) & (newton < hi)
        middle = np.where(lo > 0, np.sqrt(lo * hi), 0.5 * hi)
        xs = np.where(done, xs, np.where(inside, newton, middle))
        low[todo], high[todo], x[todo] = lo, hi, xs
        todo[np.flatnonzero(todo)[done]] = False
        if not np.any(todo):
            break
    return side * x


def classify_root(body, series_curvature, centre, reach, max_rate):
    """Local behaviour of z_G at the root u* = ``centre`` (rad).

    Parameters
    ----------
    series_curvature : float
        d²z_G/du² at u* (m/rad²) from the spectral series.
    reach : float
        Half the distance to the nearest other root (rad): the local analysis stays inside.
    max_rate : float
        max |ω_u| over the cycle (rad/rad).

    Returns
    -------
    dict with order q, leading A (m/rad^q: z_G − z* ≈ A|γ|^q), gamma_curvature d²z_G/dγ²
    (m/rad², nan if q < 2), rate |ω_u(u*)|.
    """
    rate = float(_rotation_rate(body, centre))
    if rate > DEGENERATE_RATE * max_rate:
        curvature = series_curvature / rate**2
        return dict(order=2.0, leading=0.5 * curvature, gamma_curvature=curvature, rate=rate,
                    degenerate=False)
    # degenerate phase: γ as coordinate. The phase may dwell near u* (γ ≪ 1 far out in u):
    # the quadratic fit's levels stay within half the γ-distance to the nearest other root
    # (at 2·reach in u); the order's probe levels are absolute (γ ≤ PROBE_GAMMA), also beyond
    # it: the expansion w = z_G − z* = A|γ|^q + Bγ² + o(γ²) does not care where the next root
    # is (a narrow well, |γ| < (A/|B|)^(1/(2−q)) ≪ 1, has its maxima close by)
    reach = 1.9 * reach
    g_left, _ = _local_samples(body, centre, [-reach, -PROBE_SPAN])
    g_right, _ = _local_samples(body, centre, [reach, PROBE_SPAN])
    gamma_max = min(0.05, 0.5 * min(abs(float(g_left[0])), abs(float(g_right[0]))))
    top = min(PROBE_GAMMA, 0.5 * min(abs(float(g_left[1])), abs(float(g_right[1]))))
    # order from three small levels ρ apart on each side
    probe = top * PROBE_RATIO ** np.arange(3.0)
    delta = _offsets_for(body, centre, np.concatenate([-probe, probe]), PROBE_SPAN)
    gamma, rise = _local_samples(body, centre, delta)
    g, w = np.abs(gamma).reshape(2, 3), rise.reshape(2, 3)
    plain = [math.log(w[i, 1] / w[i, 0]) / math.log(g[i, 1] / g[i, 0])
             for i in range(2) if w[i, 0] * w[i, 1] > 0]
    order = float(np.mean(plain)) if plain else math.nan
    if not abs(order - 2.0) < 0.05:
        # q < 2: the Bγ² term cancelled, r_j = w_{j+1} − (γ_{j+1}/γ_j)² w_j = A γ_j^q (ρ^q − ρ²)
        ratio = g[:, 1:] / g[:, :-1]
        r = w[:, 1:] - ratio**2 * w[:, :-1]
        sides = [i for i in range(2) if r[i, 0] * r[i, 1] > 0]
        if sides:
            order = float(np.mean([math.log(r[i, 1] / r[i, 0]) / math.log(ratio[i, 0])
                                   for i in sides]))
            leading = float(np.mean([r[i, 0] / (g[i, 0]**order * (ratio[i, 0]**order
                                                                  - ratio[i, 0]**2))
                                     for i in sides]))
        else:
            leading = float(np.mean(w[:, 1] / g[:, 1] ** order))
        return dict(order=order, leading=leading, gamma_curvature=math.nan, rate=rate,
                    degenerate=True)
    # quadratic: fit (z_G − z*)/γ² by a polynomial in γ on Chebyshev levels, value at 0
    nodes = 24
    levels = gamma_max * np.cos((2 * np.arange(nodes) + 1) * math.pi / (2 * nodes))
    delta = _offsets_for(body, centre, levels, reach)
    gamma, rise = _local_samples(body, centre, delta)
    fit = np.polynomial.chebyshev.chebfit(gamma / gamma_max, rise / gamma**2, 12)
    curvature = 2 * float(np.polynomial.chebyshev.chebval(0.0, fit))
    return dict(order=2.0, leading=0.5 * curvature, gamma_curvature=curvature, rate=rate,
                degenerate=True)


def root_series_curvatures(body, roots, nodes):
    """d²z_G/du² at the roots (rad) from the spectral series of dz_G/du on ``nodes`` nodes."""
    series = _Series(_slope_samples(body, nodes))
    return series.jets([u for u, _, _ in roots], 2)[1] if roots else np.zeros(0)


def max_rotation_rate(body, nodes):
    """max |ω_u| over the nodes (rad/rad)."""
    u = TWO_PI * np.arange(nodes) / nodes
    return float(np.max(_rotation_rate(body, u)))

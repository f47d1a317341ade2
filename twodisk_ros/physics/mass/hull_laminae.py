"""The solid convex hull of two congruent laminae of any shape: volume and moments.

Body frame of bodies/contact_solver.py (metres): O, the midpoint of the disk centres, is the origin,
e2 the common axis, disk 1 in the plane x3 = 0, disk 2 in the plane x1 = 0 (σ = ±1 by the
arrangement). The moments here are about O; mass/models.py moves them to the centre of mass.

**The surface.** A boundary point of the hull lies on a segment AB whose ends A (on rim 1) and
B (on rim 2) share a supporting plane: the resting poses of the rolling body. No flat part of
either disk is on the boundary (each disk plane cuts the other disk), so the hull's surface is
the ruled surface of these segments over one rolling cycle. It is developable: the supporting
plane, with outward normal m = −n, is tangent to the surface along the whole segment. So
x·m = H, the support height of the pose, is constant along a segment, and with a cycle
parameter p the surface element is m·(x_p × w) dλ dp = ((1 − λ) α + λ β) dλ dp, x = A + λ w,
w = B − A, α = m·(A_p × w), β = m·(B_p × w). The divergence theorem gives

    vol = ⅓ ∮ H dS,   ∫ x dV = ¼ ∮ H x dS,   ∫ x xᵀ dV = ⅕ ∮ H x xᵀ dS,

polynomials in λ (3-point Gauss–Legendre, exact).

**The rates.** In the θ chart (p = θ, A's polar angle about C1) A_θ = ρ² t_A / (p × t_A) with
ρ = |A − C1| (exact, from A's tangent). B's rate follows from the plane staying tangent to both
rims: m·t_A = m·t_B = 0 and m·w = 0 give m_p = μ e (e = m × w / |w|) and
μ e·t = κ ℓ_p (m·ν) on each rim (κ its curvature, ν its in-plane outward normal, ℓ its arc
length), so ℓ_B,p = ℓ_A,p κ_A (m·ν_A)(e·t_B) / (κ_B (m·ν_B)(e·t_A)).

**The charts.** θ is a regular parameter of A, but B passes disk 2's far tip at the turning
points θ = ±θ_max, where its rate in θ is infinite (and, at a superellipse's flat tip, B is not
even a smooth function of θ). There the **dual chart** is used: the same hull seen from disk 2,
ContactSolver(L′, Δ, arrangement) with L′ the lamina mirrored in its x axis for the
parallel arrangement (itself for swapped), related to the body by the disk-swap rotation
R: (x1, x2, x3) ↦ (x3, −x2, x1); its θ′ is B's polar angle about C2. The cycle is cut into four
arcs at |θ| = θ_c, the polar angle of A's lamina parameter halfway between disk 1's side
vertex (normal +x) and the turning point: two arcs through θ = 0 (branches ±1) in θ, two
through the turning points in θ′. On each arc every integrand is as smooth as the rims are
(analytic for ellipses, eggs, fitted outlines and even-exponent superellipses: the flat
vertices are crossed in the chart whose parameter is the flat rim), so Gauss–Legendre in the
arc's parameter converges exponentially. The node count is doubled until two successive
results agree to ``rtol`` (:func:`~twodisk_ros.physics.mass.hull.relative_change`).
"""

from functools import lru_cache
import math

import numpy as np

from ..bodies.contact_solver import ContactSolver
from .hull import PAIRS, relative_change
from ..laminae.shapes import AreaMoments, Lamina, Support

__all__ = ['MirroredLamina', 'general_hull_moments']

#: Gauss–Legendre nodes per arc: first grid and the last one tried.
N_START = 16
N_MAX = 2048
# Below this relative change, successive grids differ by roundoff, not truncation.
_ROUNDOFF = 1e-13
# Gauss–Legendre along each segment AB (λ in [0, 1]); the integrands have degree 3 in λ.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(3)
_LAMBDA = 0.5 * (_GL_X + 1.0)
_LAMBDA_W = 0.5 * _GL_W
#: The disk-swap rotation (x1, x2, x3) ↦ (x3, −x2, x1): proper, symmetric, its own inverse.
SWAP = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
_FLIP = np.array([1.0, -1.0])


class MirroredLamina(Lamina):
    """A lamina mirrored in its x axis, (x, y) ↦ (x, −y), with laminae/shapes.py's conventions.

    Its parameter s is the original's π − s (so s = 0 is again the tip on −y and s increases
    counterclockwise). The dual chart of a parallel body uses it for disk 2 seen as disk 1.
    """

    def __init__(self, lamina):
        self.original = lamina

    def __repr__(self):
        return f'MirroredLamina({self.original!r})'

    def point(self, s):
        return self.original.point(np.pi - np.asarray(s, dtype=float)) * _FLIP

    def normal(self, s):
        return self.original.normal(np.pi - np.asarray(s, dtype=float)) * _FLIP

    def curvature(self, s):
        return self.original.curvature(np.pi - np.asarray(s, dtype=float))

    def rim_speed(self, s):
        return self.original.rim_speed(np.pi - np.asarray(s, dtype=float))

    def log_curvature(self, s):
        return self.original.log_curvature(np.pi - np.asarray(s, dtype=float))

    def support(self, direction):
        found = self.original.support(np.asarray(direction, dtype=float) * _FLIP)
        parameter = np.pi - np.asarray(found.parameter, dtype=float)
        parameter = np.where(parameter > np.pi, parameter - 2 * np.pi, parameter)
        return Support(found.height, np.asarray(found.point) * _FLIP, parameter)

    @property
    def moments(self):
        m = self.original.moments
        return AreaMoments(m.area, np.asarray(m.centroid) * _FLIP, m.second_xx, m.second_yy,
                           -m.second_xy)


def _det(a, b, c):
    """a·(b × c) row by row."""
    return np.einsum('...i,...i->...', a, np.cross(b, c))


def _arc_integrand(body, s, branch):
    """Volume, first and second moment integrands (about O, per unit s) on a chart of s.

    Parameters
    ----------
    body : ContactSolver
    s : numpy.ndarray, shape (k,)
        A's lamina parameter (rad), away from the turning points ±s_max.
    branch : int or numpy.ndarray, shape (k,)
        +1 or −1 (per node).

    Returns
    -------
    numpy.ndarray, shape (k, 10)
        Columns: vol, ∫x (3), ∫x_i x_j (6, order of :data:`~twodisk_ros.physics.mass.hull.PAIRS`),
        each per unit s; non-negative surface element (the orientation of the cycle is not
        needed: α and β have one sign on an arc and vanish together only at its ends).
    """
    lam, sigma = body.lamina, body.sigma
    point = lam.point(s)
    g = body.geometry(np.arctan2(point[..., 0], -point[..., 1]), branch)
    a = g.contact_a + body.centroid
    b = g.contact_b + body.centroid
    m = -g.ground_normal
    w = b - a
    e = np.cross(m, w)
    e /= np.linalg.norm(e, axis=-1, keepdims=True)
    # disk 1: rate of A per unit s, curvature, m·ν_A = 1/√(1 + τ²)
    t_a = g.tangent_a
    speed_a = lam.rim_speed(s)
    cos_a = 1.0 / np.sqrt(1.0 + g.elevation ** 2)
    # disk 2: where B is on its rim (the support in disk 2's in-plane direction of m)
    s_b = lam.support(np.stack([m[..., 2], sigma * m[..., 1]], axis=-1)).parameter
    t2, n2 = lam.tangent(s_b), lam.normal(s_b)
    zero = np.zeros_like(s)
    t_b = np.stack([zero, sigma * t2[..., 1], t2[..., 0]], axis=-1)
    nu_b = np.stack([zero, sigma * n2[..., 1], n2[..., 0]], axis=-1)
    cos_b = np.einsum('...i,...i->...', m, nu_b)
    e_ta = np.einsum('...i,...i->...', e, t_a)
    e_tb = np.einsum('...i,...i->...', e, t_b)
    ratio = np.exp(lam.log_curvature(s) - lam.log_curvature(s_b))     # κ_A / κ_B
    speed_b = speed_a * ratio * cos_a * e_tb / (cos_b * e_ta)
    alpha = np.abs(speed_a * _det(m, t_a, w))
    beta = np.abs(speed_b * _det(m, t_b, w))
    height = g.support_height
    out = np.zeros((s.size, 10))
    for lam_, weight in zip(_LAMBDA, _LAMBDA_W):
        point = a + lam_ * w
        dh = weight * height * ((1.0 - lam_) * alpha + lam_ * beta)
        out[:, 0] += dh / 3.0
        out[:, 1:4] += point * (dh / 4.0)[:, None]
        for col, (i, j) in enumerate(PAIRS, start=4):
            out[:, col] += point[:, i] * point[:, j] * dh / 5.0
    return out


def _rotate(sums, rotation):
    """The 10 integrals of a patch P from those of rotation·P (rotation orthogonal)."""
    first = rotation.T @ sums[1:4]
    second = np.empty((3, 3))
    for col, (i, j) in enumerate(PAIRS, start=4):
        second[i, j] = second[j, i] = sums[col]
    second = rotation.T @ second @ rotation
    return np.concatenate([[sums[0]], first, [second[i, j] for i, j in PAIRS]])


@lru_cache(maxsize=16)
def _gauss_legendre(n):
    """Gauss–Legendre nodes and weights on [−1, 1] (read-only, remembered)."""
    nodes, weights = np.polynomial.legendre.leggauss(n)
    nodes.setflags(write=False)
    weights.setflags(write=False)
    return nodes, weights


class _Arcs:
    """The four arcs of the cycle (module docstring) and their Gauss–Legendre sums."""

    def __init__(self, lamina, delta, arrangement):
        self.body = ContactSolver(lamina, delta, arrangement)
        dual_lamina = MirroredLamina(lamina) if self.body.sigma > 0 else lamina
        self.dual = ContactSolver(dual_lamina, delta, arrangement)
        side = float(lamina.support(np.array([1.0, 0.0])).parameter)
        s_cut = 0.5 * (side + self.body.s_max)
        # pieces (body, s_from, s_to, branch, rotation): cut where a rim may be flat (the
        # tips and side vertices), so that each piece is analytic up to its ends
        cuts = (-s_cut, -side, 0.0, side, s_cut)
        self.arcs = [(self.body, lo, hi, branch, None) for branch in (1, -1)
                     for lo, hi in zip(cuts[:-1], cuts[1:])]
        point = lamina.point(s_cut)
        theta_cut = math.atan2(float(point[0]), -float(point[1]))
        for sign in (1.0, -1.0):
            pose = self.body.geometry(sign * theta_cut, 1)
            b = pose.contact_b + self.body.centroid
            limit = abs(math.atan2(float(b[2]), float(b[1]) - delta))
            s_limit = float(self.dual.parameter_of_theta(limit))
            self.arcs += [(self.dual, -s_limit, 0.0, -int(sign), SWAP),
                          (self.dual, 0.0, s_limit, -int(sign), SWAP)]

    def integrals(self, n):
        """The 10 integrals over the whole surface with n Gauss–Legendre nodes per piece.

        The pieces of one chart are evaluated in one vectorised call (the bisections of
        ContactSolver cost per call, not per node)."""
        nodes, weights = _gauss_legendre(n)
        total = np.zeros(10)
        for chart, rotation in ((self.body, None), (self.dual, SWAP)):
            pieces = [p for p in self.arcs if p[0] is chart]
            lo = np.array([p[1] for p in pieces])[:, None]
            hi = np.array([p[2] for p in pieces])[:, None]
            branch = np.repeat([p[3] for p in pieces], n)
            s = (0.5 * (hi + lo) + 0.5 * (hi - lo) * nodes).ravel()
            values = _arc_integrand(chart, s, branch).reshape(len(pieces), n, 10)
            sums = np.einsum('k,pkc,p->c', weights, values, 0.5 * (hi - lo)[:, 0])
            total += sums if rotation is None else _rotate(sums, rotation)
        return total


def general_hull_moments(lamina, delta, arrangement='parallel', rtol=1e-9):
    """Volume and moments about O of the convex hull of two congruent laminae, to ``rtol``.

    Parameters
    ----------
    lamina : Lamina
        The shape of both disks (laminae/shapes.py).
    delta : float
        Half the distance between the disk centres (m), as ContactSolver allows.
    arrangement : str
        'parallel' or 'swapped' (bodies/contact_solver.py).
    rtol : float
        Requested relative change between the last two grids (0 < rtol < 1; the roundoff
        floor is about 1e-13).

    Returns
    -------
    volume : float
        m³.
    first : numpy.ndarray, shape (3,)
        ∫ x dV about O (m⁴, body frame).
    second : numpy.ndarray, shape (3, 3)
        ∫ x xᵀ dV about O (m⁵).
    error : float
        Relative change between the last two grids (:func:`~twodisk_ros.physics.mass.hull.
        relative_change`).

    Raises
    ------
    ValueError
        From ContactSolver for a body it refuses (one line).
    RuntimeError
        If ``rtol`` cannot be reached with N_MAX nodes per arc.
    """
    arcs = _Arcs(lamina, delta, arrangement)
    n = N_START
    with np.errstate(all='ignore'):
        coarse = arcs.integrals(n)
    previous = math.inf
    while True:
        n *= 2
        with np.errstate(all='ignore'):
            fine = arcs.integrals(n)
        if not np.all(np.isfinite(fine)):
            raise RuntimeError(f'solid hull quadrature failed for {lamina!r}, delta = {delta!r}: '
                               'the pose where both rims are at their flat side vertices is '
                               'not resolved in floating point (exponent too large)')
        error = relative_change(coarse, fine)
        if error <= rtol:
            second = np.empty((3, 3))
            for col, (i, j) in enumerate(PAIRS, start=4):
                second[i, j] = second[j, i] = fine[col]
            return float(fine[0]), fine[1:4].copy(), second, error
        if n >= N_MAX or (error < _ROUNDOFF and previous < _ROUNDOFF):
            raise RuntimeError(f'solid hull quadrature cannot reach rtol = {rtol!r} for '
                               f'{lamina!r}, delta = {delta!r}: relative change {error:.3g} '
                               f'with {n} nodes per arc (roundoff floor about 1e-13)')
        previous = error
        coarse = fine

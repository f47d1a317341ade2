"""Stability of the symmetric equilibria of two congruent laminae, in closed form.

Issue 20 (docs/physics.md#stability-of-the-symmetric-equilibria-for-any-laminae). The body is
that of :mod:`~twodisk_ros.physics.bodies.contact_solver` (frame, arrangement σ, G on the common axis at g e2). Three resting
poses are fixed by a symmetry of the body, so z_G is stationary there:

* ``'theta=0'``: disk 1 stands on its far tip (lamina vertex −y), disk 2 on the tangent from
  that tip; fixed by the mirror x1 → −x1;
* ``'turning point'`` (θ = ±θ_max): disk 2 stands on its far tip (lamina vertex +y if σ = +1,
  −y if σ = −1), disk 1 on the tangent from it; fixed by the mirror x3 → −x3;
* ``'side vertices'`` (θ = ±π/2 for the ellipse): both disks touch at their +x vertices. An
  equilibrium when G lies midway, along the axis, between the two contacts: always in the
  swapped arrangement, in the parallel one only if the lamina's widest point is level with its
  centroid (true for ellipses and superellipses, not for eggs).

Along the rolling motion, γ is the angle the body has turned about the contact line AB (the
arc length of the ground normal's path in the body frame; the kinetic energy is ½ I_AB γ̇²),
and p a component of the ground normal n: p = n1, n3, n2 for the three poses, with γ = p·rate
to leading order. With the rolling vertex's support function
h(d + t d⊥) = e + y_v t + c|t|^q + o(t²) (:class:`~twodisk_ros.physics.laminae.shapes.Vertex`; q = 2,
c = ρ/2 for a radius of curvature ρ):

    z_G − z_G* = A |p|^q + B p² + o(p²)

* tips: A = χ c sin^(1−q) β, B = −z*/2, rate 1; ℓ = |GA| along the axis (tip to G), β the angle
  of the ground to the axis, λ = |AB|, z* = ℓ sin β, χ = 1 − ℓ cos β/λ = N_A/(M g), the share
  of the weight on the tip. For q = 2: d²z_G/dγ² = (ρχℓ − z*²)/z*, stable iff ρχℓ > z*².
* sides: A = 2^((q−1)/2) c, B = −(z*/2)(1 + 2Δe²/w²), rate √(1 + 2Δe²/w²), z* = w/√2, w the
  half width, Δe = Δ − (1 − σ)y*/2 half the axial spacing of the contacts, y* the vertex's y.
  For q = 2: d²z_G/dγ² = (w/√2)(2wρ − w² − 2Δe²)/(w² + 2Δe²), stable iff 2wρ > w² + 2Δe².

For the ellipse the criteria are (b²(a + Δ)/(a W)) s and −s, s = b² − 2a² + 2Δ²,
W = b² + 4aΔ + 4Δ². At a flat vertex (q < 2) the |p|^q term decides: V = M g z_G is not twice
differentiable there and no linear small-oscillation period exists.
"""

from dataclasses import dataclass
import math

import numpy as np

from .equilibria import NEUTRAL, STABLE, UNSTABLE
from ..bodies.contact_solver import ContactSolver
from ..laminae.shapes import normal_of_angle

__all__ = ['NOT_AN_EQUILIBRIUM', 'SymmetricEquilibrium', 'symmetric_equilibria']

NOT_AN_EQUILIBRIUM = 'not an equilibrium'
#: A criterion within this fraction of size² (m²; of 1 for the load share at a flat tip, of the
#: size for G's offset from the contacts' midpoint) is reported as zero.
NEUTRAL_TOLERANCE = 1e-9


@dataclass(frozen=True)
class SymmetricEquilibrium:
    """One symmetric resting pose and its stability (lengths in m, angles in rad)."""

    name: str            #: 'theta=0', 'turning point' or 'side vertices'
    contact: str         #: what touches the ground, in words
    coordinate: str      #: p: 'n1', 'n3' or 'n2', the component of the ground normal n
    theta: float         #: θ of A on branch +1 (θ ≥ 0 of the symmetric pair)
    psi: float           #: ψ of B on branch +1
    height: float        #: z_G* (m)
    vertex: object       #: the rolling lamina :class:`~twodisk_ros.physics.laminae.shapes.Vertex`
    load_share: float    #: χ, the share of the weight on that vertex's contact at rest
    lever: float         #: tips: ℓ = |GA| along the axis; sides: Δe (m)
    slope: float         #: dz_G/dγ (m/rad): 0 at an equilibrium
    rate: float          #: dγ/dp at the pose
    order: float         #: q in (1, 2]
    coefficients: tuple  #: (A, B) (m): z_G − z_G* = A|p|^q + B p² + o(p²)
    leading: float       #: z_G − z_G* ≈ leading · |γ|^q (m/rad^q), = A / rate^q
    curvature: float     #: d²z_G/dγ² (m/rad²) when q = 2, else nan
    margin: float        #: the criterion (m²), positive when stable, when q = 2, else nan
    well: float          #: q < 2, A > 0 > B: |p| below which z_G > z_G*, (A/|B|)^(1/(2−q))
    stability: str       #: 'stable', 'unstable', 'neutral' or 'not an equilibrium'
    verdict: str         #: one line

    @property
    def has_linear_period(self):
        """True when T = 2π √(I_AB / (M g d²z_G/dγ²)) exists: q = 2 and stable."""
        return self.order == 2.0 and self.stability == STABLE


def _tangent_from_axis(lamina, y):
    """Contact point (m) of the tangent from (0, y), beyond the lamina's end, on its +x side.

    Its outward normal n(φ) = (sin φ, −cos φ) solves h(n) = n·(0, y): one root on each side.
    """
    from scipy.optimize import brentq
    def gap(phi):
        n = normal_of_angle(phi)
        return float(lamina.support(n).height) - float(n[1]) * y
    low, high = (0.0, 0.5 * math.pi) if y < 0 else (0.5 * math.pi, math.pi)
    phi = brentq(gap, low, high, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=400)
    return np.asarray(lamina.support(normal_of_angle(phi)).point, dtype=float)


def _well(a, b, q):
    if not (q < 2.0 and a > 0):
        return math.nan
    if b >= 0:
        return math.inf
    try:
        return math.exp(math.log(a / -b) / (2.0 - q))
    except OverflowError:
        return math.inf


def _verdict(name, stability, order, leading, curvature, margin, well, rate):
    if stability == NOT_AN_EQUILIBRIUM:
        return (f'{name}: not an equilibrium (dz_G/dgamma != 0: G is off the midpoint of the '
                'contacts; the equilibrium nearby is not symmetric)')
    if order == 2.0:
        text = (f'{name}: {stability}: d2z_G/dgamma2 = {curvature:.6g} m/rad2 '
                f'(criterion {margin:.6g} m2)')
        if stability == STABLE:
            return text + '; linear period 2 pi sqrt(I_AB / (M g d2z_G/dgamma2))'
        return text + ('; higher orders decide' if stability == NEUTRAL else '')
    text = (f'{name}: {stability}: flat vertex (infinite radius of curvature), '
            f'z_G - z_G* ~ {leading:.6g} |gamma|^{order:.6g} m; V not twice differentiable, '
            'no linear small-oscillation period')
    if stability == STABLE and well * rate < 0.1:     # else beyond the expansion's reach
        text += f' (z_G > z_G* only for |gamma| < {well * rate:.3g} rad)'
    return text + ('; the next term, -z_G* p2/2, is negative' if stability == NEUTRAL else '')


def _result(name, contact, coordinate, angles, height, vertex, share, lever, slope, rate,
            coefficients, margin, criterion_scale, tolerance):
    """Assemble one :class:`SymmetricEquilibrium`; ``margin`` (m²) decides when q = 2 and
    ``share`` (the sign of A at a tip) when q < 2 (sides: A > 0)."""
    q = float(vertex.order)
    a, b = coefficients
    curvature = 2.0 * (a + b) / rate**2 if q == 2.0 else math.nan
    if abs(slope) > tolerance * criterion_scale:
        stability = NOT_AN_EQUILIBRIUM
    elif q == 2.0:
        stability = (NEUTRAL if abs(margin) <= tolerance * criterion_scale**2
                     else STABLE if margin > 0 else UNSTABLE)
    else:
        margin = math.nan
        stability = (NEUTRAL if abs(share) <= tolerance and name != 'side vertices'
                     else STABLE if a > 0 else UNSTABLE)
    leading = a / rate**q if q < 2.0 else 0.5 * curvature
    well = _well(a, b, q)
    return SymmetricEquilibrium(
        name=name, contact=contact, coordinate=coordinate, theta=angles[0], psi=angles[1],
        height=height, vertex=vertex, load_share=share, lever=lever, slope=slope, rate=rate,
        order=q, coefficients=(a, b), leading=leading, curvature=curvature, margin=margin,
        well=well, stability=stability,
        verdict=_verdict(name, stability, q, leading, curvature, margin, well, rate))


def _tip(body, name, vertex, lever, other_y, angles_of, contact, coordinate, tolerance):
    """A tip equilibrium: ``vertex`` rests on the ground, which is the tangent from it to the
    other disk; ``other_y`` is the tip's y in that disk's lamina coordinates."""
    point = _tangent_from_axis(body.lamina, other_y)
    chord = math.hypot(point[0], point[1] - other_y)          # λ = |AB|
    cos_beta, sin_beta = abs(point[1] - other_y) / chord, abs(point[0]) / chord
    height = lever * sin_beta                                   # z* = ℓ sin β
    share = 1.0 - lever * cos_beta / chord                      # χ = N_A / (M g)
    q, c = float(vertex.order), float(vertex.coefficient)
    coefficients = (share * c * sin_beta ** (1.0 - q), -0.5 * height)
    margin = vertex.radius * share * lever - height**2 if q == 2.0 else math.nan
    return _result(name, contact, coordinate, angles_of(point), height, vertex, share, lever,
                   0.0, 1.0, coefficients, margin, body.size, tolerance)


def symmetric_equilibria(lamina, delta, arrangement='parallel',
                         neutral_tolerance=NEUTRAL_TOLERANCE):
    """The three symmetric equilibria of two congruent laminae and their stability.

    Parameters
    ----------
    lamina : Lamina
        Shape of both disks (laminae/shapes.py), convex and symmetric about the common axis.
    delta : float
        Half the distance between the disk centres (m), as for ContactSolver.
    arrangement : str
        'parallel' (default) or 'swapped' (bodies/contact_solver.py).
    neutral_tolerance : float
        Criteria within this fraction of their scale are reported as 'neutral'
        (:data:`NEUTRAL_TOLERANCE`).

    Returns
    -------
    tuple of SymmetricEquilibrium
        ('theta=0', 'turning point', 'side vertices'), each for both branches and both signs of
        θ (the body's mirror symmetries map them onto one another).

    Raises
    ------
    ValueError
        One line, for what ContactSolver refuses, or for a vertex that is flat without a
        known order of contact.
    """
    body = ContactSolver(lamina, delta, arrangement)
    sigma, delta, g = body.sigma, body.delta, float(body.centroid[1])
    tol = float(neutral_tolerance)

    # θ = 0: disk 1's far tip (y_min), seen from disk 2 at y = −σ(a− + 2Δ) in its coordinates
    near = lamina.vertex('-y')
    first = _tip(
        body, 'theta=0', near, near.extent + delta + g, -sigma * (near.extent + 2 * delta),
        lambda p: (0.0, math.atan2(abs(p[0]), sigma * p[1])),
        "disk 1's far tip (lamina vertex -y) and disk 2", 'n1', tol)

    # turning point: disk 2's far tip, at y = a + 2Δ in disk 1's coordinates
    far = lamina.vertex('+y' if sigma > 0 else '-y')
    second = _tip(
        body, 'turning point', far, far.extent + delta - g, far.extent + 2 * delta,
        lambda p: (math.atan2(abs(p[0]), -p[1]), 0.0),
        f"disk 2's far tip (lamina vertex {far.axis}) and disk 1 at theta = theta_max", 'n3',
        tol)

    # side vertices: disk 1 at (w, y* − Δ, 0), disk 2 at (0, σy* + Δ, −w)
    side = lamina.vertex('+x')
    w, y_star = side.extent, float(side.point[1])
    spacing = delta - 0.5 * (1.0 - sigma) * y_star             # Δe
    stretch = 1.0 + 2.0 * (spacing / w) ** 2
    rate = math.sqrt(stretch)
    height = w / math.sqrt(2.0)
    q, c = float(side.order), float(side.coefficient)
    coefficients = (2.0 ** (0.5 * (q - 1.0)) * c, -0.5 * height * stretch)
    slope = (0.5 * (1.0 + sigma) * y_star - g) / rate           # G off the contacts' midpoint
    margin = 2 * w * side.radius - w * w - 2 * spacing**2 if q == 2.0 else math.nan
    third = _result('side vertices', 'the side vertices (+x) of both disks', 'n2',
                    (math.atan2(w, -y_star), math.atan2(w, sigma * y_star)), height, side, 0.5,
                    spacing, slope, rate, coefficients, margin, body.size, tol)
    return first, second, third

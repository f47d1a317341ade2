"""Two congruent laminae of any shape: the contact geometry solved from the support function.

docs/physics.md#the-contact-geometry-of-any-laminae. :class:`~twodisk_ros.physics.bodies.lamina_body.
LaminaBody` tabulates these exact solutions over the cycle; the hull (mass/hull_laminae.py) and the
drawing (model/) use them directly. :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody` stays the
exact, fast path for ellipses and is the reference the tests hold this one to.

Body frame as in bodies/ellipse.py (metres): O, the midpoint of the centres, is the origin; e2 is the
common axis. Disk 1 lies in the plane x3 = 0 and its lamina point (x, y) (laminae/shapes.py
coordinates) sits at C1 + x e1 + y e2, C1 = −Δ e2. Disk 2 lies in the plane x1 = 0 and its
lamina point (x, y) sits at C2 + x e3 + σ y e2, C2 = +Δ e2, with the arrangement σ:

* ``'parallel'`` (σ = +1, the default): disk 2 is disk 1 turned by 90° about e2 and moved
  by 2Δ; an egg points the same way on both disks, so the body differs seen from its two ends;
* ``'swapped'`` (σ = −1): disk 2 is the image of disk 1 under the disk-swap rotation
  (x1, x2, x3) ↦ (x3, −x2, x1), so the body keeps that symmetry, (θ, ψ) ↦ (−ψ, −θ).

For an ellipse both are the same body as EllipseBody(a, b, Δ). G is the centroid of the two
laminae (equal masses): G = (1 + σ) ȳ/2 e2 with ȳ the lamina's centroid (0 unless the lamina
is asymmetric along y, as the egg is). θ and ψ are the polar angles of A about C1 (from −e2
towards +e1) and of B about C2 (from +e2 towards −e3), as in bodies/ellipse.py.

The contact relation. Let m = −n be the downward unit ground normal (body frame). The body
rests on the plane when its lowest points on both laminae are equally low, i.e. when the two
support heights agree: h1(m) = −Δ m2 + h(m1, m2) = h2(m) = Δ m2 + h(m3, σ m2), with h the
lamina's support function. Writing the in-plane part of m as the outward lamina normal ν at
A, m = (ν_x, ν_y, τ)/√(1 + τ²), the condition becomes one equation in the elevation τ,
h(τ, σν_y) = A·ν − 2Δ ν_y =: L, whose left side is even and convex in τ: two roots ±|τ| (the
two branches; branch +1 has τ < 0, n·e3 > 0, as in bodies/ellipse.py) while L ≥ h(0, σν_y), none
beyond. The family ends where F = L − h(0, σν_y) vanishes: θ_max; there disk 1 stands
vertical (τ = 0). |ψ| is largest at θ = 0, where the normal lies in the plane of disk 2.

Two charts of the same family, both solved to the last bit by a bracketing root finder
(:func:`_bisect`: secant steps guarded by bisection, ending in bisection; robust for any
convex lamina, also where the superellipse's curvature vanishes): :meth:`geometry` from θ
(A's parameter by bisection on its polar angle, then |τ| from the convex equation) and
:meth:`geometry_at_tilt` from the tilt of disk 1 (|τ| = |cot tilt|, then A's parameter by
bisection on the contact equation). ψ(θ) ~ √(θ_max − |θ|) is ill-conditioned near the
turning points: there the tilt chart is the regular one.
"""

from dataclasses import dataclass
import math
import numpy as np

from ..laminae.shapes import Lamina, check_length
from .outline import ARRANGEMENTS
from .rulings import Drawable

__all__ = ['ARRANGEMENTS', 'ContactGeometry', 'ContactSolver']

#: Grid on which the turning-point function F must change sign exactly once (a larger count
#: would mean a family in several pieces, which is refused).
_CHECK_NODES = 2049
_MAX_BISECTIONS = 2200
#: Bracket width (in floats) below which :func:`_bisect` only bisects.
_FINISH_ULPS = 64
#: Smallest distance (in floats) of a secant point of :func:`_bisect` from either end.
_MIN_STEP_ULPS = 8
#: Newton steps of the convex elevation equation at most (5 to 8 needed; bisection steps of
#: the guard, if any, are among them).
_NEWTON_STEPS = 200


def _bisect(func, lo, hi, even=False):
    """Root of an increasing ``func`` on [lo, hi] per element, to adjacent floats (vectorised).

    ``lo``, ``hi`` are arrays of the same shape; func(lo) ≤ 0 ≤ func(hi) is the caller's
    promise. Returns the end of the final interval [lo, hi] (adjacent floats with func(lo) ≤ 0
    < func(hi) as evaluated, or an end where func is already 0) whose |func| is smaller: the
    contract of plain bisection, in about a fifth of its evaluations. The bracket shrinks by
    secant steps through the last two points (superlinear; Dekker's method), at least
    _MIN_STEP_ULPS floats from either end (so once a point has converged to the root, the next
    lands beyond it and closes the bracket), replaced by the bracket's midpoint where the
    secant leaves the bracket or the bracket has not halved in the last two steps (so never
    much slower than bisection), and by plain bisection once the bracket spans at most
    _FINISH_ULPS floats. ``even``: func is smooth in t² (an even function of t ≥ 0 = lo, as
    the convex elevation equation), so the secant is taken in t², exact for a root near t = 0
    where func is quadratic. Where rounding makes func change sign more than once within a
    few floats of the root, another sign change of that cluster than plain bisection's may be
    returned (the measured differences are a few ulps).
    """
    lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
    # the ends may be degenerate (the elevation equation at t = 0 and c = 0 asks a
    # superellipse for h(0, 0) = 0, whose support point 0·∞ is not used): no warnings there
    with np.errstate(divide='ignore', invalid='ignore'):
        f_lo, f_hi = np.asarray(func(lo), dtype=float), np.asarray(func(hi), dtype=float)
    # an end where func already has the root's sign (0 included) is the answer: bisection
    # would creep towards it, down to the subnormals near 0 (~1075 steps)
    at_lo = f_lo >= 0
    at_hi = (f_hi <= 0) & ~at_lo
    hi, f_hi = np.where(at_lo, lo, hi), np.where(at_lo, f_lo, f_hi)
    lo, f_lo = np.where(at_hi, hi, lo), np.where(at_hi, f_hi, f_lo)
    old, f_old, new, f_new = lo, f_lo, hi, f_hi     # the secant's two points
    steps = [np.inf, np.inf]    # the lengths of the step before the last and of the last
    for _ in range(_MAX_BISECTIONS):
        width = hi - lo
        mid = lo + 0.5 * width
        open_ = (mid > lo) & (mid < hi)
        if not np.any(open_):
            break
        with np.errstate(divide='ignore', invalid='ignore', over='ignore'):
            if even:
                secant = np.sqrt(new * new - f_new * ((new * new - old * old) / (f_new - f_old)))
            else:
                secant = new - f_new * ((new - old) / (f_new - f_old))
        ulp = np.spacing(np.maximum(np.abs(lo), np.abs(hi)))
        # Brent's guard: a secant step from the better end must be shorter than half the step
        # before the last
        best = np.where(np.abs(f_hi) < np.abs(f_lo), hi, lo)
        use = ((secant >= lo) & (secant <= hi) & (width > _FINISH_ULPS * ulp)
               & (np.abs(secant - best) < 0.5 * steps[0]))
        least = _MIN_STEP_ULPS * ulp
        x = np.where(use, np.minimum(np.maximum(secant, lo + least), hi - least), mid)
        steps = [np.where(use, steps[1], 0.5 * width), np.where(use, np.abs(x - best), 0.5 * width)]
        value = np.asarray(func(x), dtype=float)
        below = open_ & (value <= 0)
        above = open_ & (value > 0)
        zero = open_ & (value == 0)     # a root as evaluated: the answer
        lo, f_lo = np.where(below, x, lo), np.where(below, value, f_lo)
        hi, f_hi = np.where(above | zero, x, hi), np.where(above | zero, value, f_hi)
        # the secant's next two points: the last two, or after a bisection the bracket's ends
        old = np.where(open_, np.where(use, new, lo), old)
        f_old = np.where(open_, np.where(use, f_new, f_lo), f_old)
        new = np.where(open_, np.where(use, x, hi), new)
        f_new = np.where(open_, np.where(use, value, f_hi), f_new)
    take_hi = np.abs(f_hi) < np.abs(f_lo)
    return np.where(take_hi, hi, lo)


@dataclass(frozen=True)
class ContactGeometry:
    """Body-frame geometry of a resting pose (arrays broadcast together; vectors (..., 3))."""

    theta: np.ndarray           #: θ (rad), polar angle of A about C1 from −e2 towards +e1
    psi: np.ndarray             #: ψ (rad), polar angle of B about C2 from +e2 towards −e3
    branch: np.ndarray          #: +1 (n·e3 ≥ 0, the paper's half-cycle) or −1
    parameter_a: np.ndarray     #: A's lamina parameter s on disk 1 (rad)
    elevation: np.ndarray       #: τ = m3/|(m1, m2)| of the downward normal m = −n
    contact_a: np.ndarray       #: GA (m)
    contact_b: np.ndarray       #: GB (m)
    ground_normal: np.ndarray   #: n, unit, up, in the body frame
    tangent_a: np.ndarray       #: unit tangent of disk 1 at A (s increasing, θ increasing)
    height: np.ndarray          #: z_G = n·(G − A) (m), G's height above the ground
    support_height: np.ndarray  #: h1(m) = h2(m) = max of m·P over the body, P from O (m)
    tilt: np.ndarray            #: angle between the plane of disk 1 and the ground (rad)
    parameter_b: np.ndarray = None  #: B's lamina parameter on disk 2 (rad, in (−π, π])


class ContactSolver(Drawable):
    """Two congruent convex laminae in perpendicular planes, centres at ∓Δ along e2.

    Parameters
    ----------
    lamina : Lamina
        The shape of both disks (laminae/shapes.py); its origin is the disk's centre and must lie
        inside it (θ is a polar angle about it).
    delta : float
        Half the distance between the centres (m), 0 < Δ < (y_max − y_min)/2 (the laminae's
        extents along e2 overlap: a for the ellipse), and such that the family of resting
        poses is one closed cycle (else ValueError, one line).
    arrangement : str
        'parallel' (default) or 'swapped' (module docstring).
    """

    def __init__(self, lamina, delta, arrangement='parallel'):
        if not isinstance(lamina, Lamina):
            raise ValueError(f'lamina must be a Lamina (Ellipse, Superellipse, Egg, Outline), '
                             f'got {type(lamina).__name__}')
        if arrangement not in ARRANGEMENTS:
            raise ValueError(f'arrangement must be one of {sorted(ARRANGEMENTS)}, '
                             f'got {arrangement!r}')
        self.lamina, self.arrangement = lamina, arrangement
        self.sigma = ARRANGEMENTS[arrangement]
        self.x_max, self.y_min, self.y_max = lamina.extents
        if not (self.y_min < 0.0 < self.y_max):
            raise ValueError('the lamina\'s origin (the disk centre) must lie inside it, '
                             f'got y from {self.y_min!r} to {self.y_max!r} m')
        limit = 0.5 * (self.y_max - self.y_min)
        self.delta = check_length('delta', delta, f'with 0 < delta < {limit:.6g} m '
                                  '(half the lamina\'s length along the common axis)')
        if not self.delta < limit:
            raise ValueError(f'delta must be < {limit:.6g} m (half the lamina\'s length along '
                             f'the common axis: the disks must interlock), got {delta!r}')
        self.centroid = np.array([0.0, 0.5 * (1.0 + self.sigma)
                                  * float(lamina.moments.centroid[1]), 0.0])
        grid = np.linspace(0.0, np.pi, _CHECK_NODES)
        turning = self._turning(grid)
        changes = int(np.count_nonzero(np.diff(np.sign(turning)) != 0))
        if not (turning[0] > 0 and turning[-1] < 0 and changes == 1):
            raise ValueError(f'no single rolling cycle for this lamina with delta = '
                             f'{self.delta!r} m in the {arrangement} arrangement (a disk '
                             'reaches past the other\'s tip, or the family of resting poses '
                             'splits); choose a smaller delta or the other arrangement')
        j = int(np.argmax(turning < 0))
        self.s_max = float(_bisect(lambda s: -self._turning(s),
                                   np.array(grid[j - 1]), np.array(grid[j])))
        point = lamina.point(self.s_max)
        #: largest |θ| (rad): disk 1 stands vertical, B at the far tip of disk 2
        self.theta_max = float(np.arctan2(max(float(point[0]), 0.0), -float(point[1])))

    @property
    def contact_solver(self):
        """The solver itself (as a rolling body's ``contact_solver``)."""
        return self

    @property
    def origin(self):
        """The body-frame origin G from the midpoint O of the centres (m): the centroid."""
        return self.centroid

    #: The body-frame origin's offset from G along e2 (m): none (as a rolling body's).
    offset = 0.0

    def __repr__(self):
        return (f'ContactSolver({self.lamina!r}, delta={self.delta!r}, '
                f'arrangement={self.arrangement!r})')

    # -- the support function of the lamina and the contact equation --------------------------
    def _h_axis(self, c):
        """h(0, c) = max(c y_max, c y_min) (m per unit |c|): the support along the axis."""
        return np.maximum(c * self.y_max, c * self.y_min)

    def _frame_a(self, s):
        """A = r(s) (lamina coordinates), its outward normal ν, and L = A·ν − 2Δ ν_y."""
        point = self.lamina.point(s)
        nu = self.lamina.normal(s)
        big_l = np.sum(point * nu, axis=-1) - 2 * self.delta * nu[..., 1]
        return point, nu, big_l

    def _turning(self, s):
        """F(s) = L − h(0, σν_y) (m): ≥ 0 inside the family, 0 at the turning points."""
        _, nu, big_l = self._frame_a(np.asarray(s, dtype=float))
        return big_l - self._h_axis(self.sigma * nu[..., 1])

    def _h2(self, tau, c):
        """h(τ, c) of the lamina (m): disk 2's support in lamina coordinates."""
        return self.lamina.support(np.stack([tau, c], axis=-1)).height

    def _elevation(self, nu, big_l, fast=False):
        """|τ| ≥ 0 with h(|τ|, σν_y) = L (0 where L ≤ h(0, σν_y): the turning point).

        By bisection, or with ``fast`` by :meth:`_convex_newton` (the same root).
        """
        return self._convex_root(self.sigma * nu[..., 1], big_l, fast)

    def _convex_root(self, c, big_l, fast):
        """t ≥ 0 with h(t, c) = L; h is even and convex in t (0 where L ≤ h(0, c))."""
        # h(t, c) ≥ t x_max − |c| max(−y_min, y_max) bounds the root from above
        reach = max(-self.y_min, self.y_max)
        hi = np.maximum((big_l + np.abs(c) * reach) / self.x_max, 0.0) * (1 + 1e-12) + 1e-300
        inside = big_l > self._h_axis(c)
        if not fast:
            tau = _bisect(lambda t: self._h2(t, c) - big_l, np.zeros_like(hi), hi, even=True)
            return np.where(inside, tau, 0.0)
        tau = np.zeros(np.shape(hi))
        tau[inside] = self._convex_newton(c[inside], big_l[inside], hi[inside])
        return tau

    def _convex_newton(self, c, big_l, hi):
        """The root t > 0 of f(t) = h(t, c) − L, f(0) < 0 < f(hi), by Newton's method from hi
        with f′(t) = x of the support point (h's gradient): monotone for a convex f, guarded
        by the bracket (bisection where a step would leave it); stops when a step changes t
        by less than 4 ulp, or stalls at the rounding of f (a step no shorter than half the
        previous one, below 1e-8 t)."""
        lo, x = np.zeros_like(hi), hi.copy()
        previous = np.full_like(hi, np.inf)
        for _ in range(_NEWTON_STEPS):
            found = self.lamina.support(np.stack([x, c], axis=-1))
            f = found.height - big_l
            lo, hi = np.where(f <= 0, x, lo), np.where(f > 0, x, hi)
            with np.errstate(divide='ignore', invalid='ignore'):
                new = x - f / found.point[..., 0]
            new = np.where((new >= lo) & (new <= hi), new, lo + 0.5 * (hi - lo))
            step = np.abs(new - x)
            done = (step <= 4 * np.finfo(float).eps * x) | ((step >= 0.5 * previous)
                                                             & (step <= 1e-8 * x))
            x, previous = new, step
            if np.all(done):
                break
        return x

    # -- assembling a pose -------------------------------------------------------------------
    def _pose(self, s, tau_abs, branch):
        lam, sigma, delta = self.lamina, self.sigma, self.delta
        point, nu, _ = self._frame_a(s)
        tau = -branch * tau_abs
        scale = 1.0 / np.sqrt(1.0 + tau * tau)
        m = np.stack([nu[..., 0], nu[..., 1], tau], axis=-1) * scale[..., None]
        support2 = lam.support(np.stack([tau, sigma * nu[..., 1]], axis=-1))
        p2 = support2.point
        zero = np.zeros_like(tau)
        a_body = np.stack([point[..., 0], point[..., 1] - delta, zero], axis=-1)
        b_body = np.stack([zero, delta + sigma * p2[..., 1], p2[..., 0]], axis=-1)
        height1 = np.sum(m * a_body, axis=-1)
        t2 = lam.tangent(s)
        tangent = np.stack([t2[..., 0], t2[..., 1], zero], axis=-1)
        theta = np.arctan2(point[..., 0], -point[..., 1])
        psi = np.arctan2(-p2[..., 0], sigma * p2[..., 1])
        n = -m
        return ContactGeometry(
            theta=theta, psi=psi, branch=np.asarray(branch, dtype=float) + zero,
            parameter_a=np.asarray(s, dtype=float) + zero, elevation=tau,
            contact_a=a_body - self.centroid, contact_b=b_body - self.centroid,
            ground_normal=n, tangent_a=tangent, height=height1 - m @ self.centroid,
            support_height=height1, tilt=np.arctan2(np.hypot(n[..., 0], n[..., 1]), n[..., 2]),
            parameter_b=support2.parameter + zero)

    @staticmethod
    def _branch_array(branch, shape):
        branch = np.asarray(branch)
        if not np.all((branch == 1) | (branch == -1)):
            raise ValueError(f'branch must be +1 or -1, got {branch!r}')
        return np.broadcast_to(branch.astype(float), shape)

    def _theta_array(self, theta):
        theta = np.asarray(theta, dtype=float)
        if np.any(~np.isfinite(theta)) or np.any(np.abs(theta) > self.theta_max * (1 + 1e-15)):
            raise ValueError(f'theta must be finite with |theta| <= theta_max = '
                             f'{self.theta_max!r} rad')
        return np.clip(theta, -self.theta_max, self.theta_max)

    def parameter_of_theta(self, theta):
        """A's lamina parameter s (rad) at polar angle θ, to adjacent floats by :func:`_bisect`
        (s(−θ) = −s(θ))."""
        theta = self._theta_array(theta)
        target = np.abs(theta)

        def polar(s):
            point = self.lamina.point(s)
            return np.arctan2(np.maximum(point[..., 0], 0.0), -point[..., 1]) - target
        s = _bisect(polar, np.zeros_like(target), np.full_like(target, self.s_max))
        return np.where(theta < 0, -s, s)

    # -- the θ chart (bodies/ellipse.py's names) -------------------------------------------------------
    def geometry(self, theta, branch=1):
        """:class:`ContactGeometry` at contact angle θ (rad) on a branch (±1)."""
        theta = self._theta_array(theta)
        branch = self._branch_array(branch, theta.shape)
        s = self.parameter_of_theta(theta)
        _, nu, big_l = self._frame_a(s)
        return self._pose(s, self._elevation(nu, big_l), branch)

    def contact_angle_psi(self, theta, branch=1):
        """ψ(θ) (rad) on a branch."""
        return self.geometry(theta, branch).psi

    def contact_vector_a(self, theta):
        """GA (m, body frame)."""
        return self.geometry(theta).contact_a

    def contact_vector_b(self, theta, branch=1):
        """GB (m, body frame)."""
        return self.geometry(theta, branch).contact_b

    def ground_normal(self, theta, branch=1):
        """Unit normal n of the ground, pointing up, in the body frame."""
        return self.geometry(theta, branch).ground_normal

    def tilt(self, theta, branch=1):
        """Angle (rad) between the plane of disk 1 and the ground, cos = n·e3."""
        return self.geometry(theta, branch).tilt

    def height(self, theta):
        """z_G (m): G's height above the ground, the same on both branches."""
        return self.geometry(theta).height

    @property
    def psi_max(self):
        """Largest |ψ| (rad): at θ = 0, where the ground normal lies in the plane of disk 2."""
        return float(abs(self.contact_angle_psi(0.0)))

    # -- the tilt chart (regular at the turning points) --------------------------------------
    @property
    def steepest(self):
        """(s, |τ|) where |τ| is largest on the family (the tilt chart's far end)."""
        from scipy.optimize import minimize_scalar
        cached = self.__dict__.get('_steepest')
        if cached is None:
            def elevation(s):
                _, nu, big_l = self._frame_a(np.asarray(s, dtype=float))
                return self._elevation(nu, big_l)
            grid = np.linspace(0.0, self.s_max, 1025)
            values = elevation(grid)
            j = int(np.argmax(values))
            step = grid[1]
            found = minimize_scalar(lambda s: -float(elevation(s)), method='bounded',
                                    bounds=(max(grid[j] - step, 0.0),
                                            min(grid[j] + step, self.s_max)),
                                    options={'xatol': 1e-13})
            s_peak = float(found.x) if -found.fun > values[j] else float(grid[j])
            cached = self.__dict__['_steepest'] = (s_peak, float(elevation(s_peak)))
        return cached

    @property
    def tilt_range(self):
        """[low, π − low] (rad): the tilts :meth:`geometry_at_tilt` accepts."""
        low = math.atan2(1.0, self.steepest[1])
        return low, math.pi - low

    def geometry_at_tilt(self, tilt, side=1):
        """:class:`ContactGeometry` at the tilt of disk 1 (rad), on the side sign θ = ±1.

        Covers the poses between the steepest one (largest |τ|, often θ = 0) and the turning
        point (tilt π/2), where this chart is well conditioned and θ is not; branch +1 for
        tilt ≤ π/2. |τ| = |cot tilt|; A's parameter solves h(|τ|, σν_y) = L by bisection.
        """
        tilt = np.asarray(tilt, dtype=float)
        side = self._branch_array(side, tilt.shape)
        low, high = self.tilt_range
        if np.any(~np.isfinite(tilt)) or np.any((tilt < low) | (tilt > high)):
            raise ValueError(f'tilt must be finite in [{low!r}, {high!r}] rad')
        branch = np.where(tilt > np.pi / 2, -1.0, 1.0)
        tau_abs = np.abs(np.cos(tilt) / np.sin(tilt))

        def residual(s):
            _, nu, big_l = self._frame_a(s)
            return self._h2(tau_abs, self.sigma * nu[..., 1]) - big_l
        s = _bisect(residual, np.full_like(tau_abs, self.steepest[0]),
                    np.full_like(tau_abs, self.s_max))
        return self._pose(side * s, tau_abs, branch)

    # -- the charts of the regular phase (bodies/regular_phase.py) ------------------------------------
    @property
    def far_tip(self):
        """Disk 2's lamina parameter (0 or π) of the tip B touches at the turning points."""
        _, nu, _ = self._frame_a(np.asarray(self.s_max))
        return 0.0 if self.sigma * float(nu[..., 1]) < 0 else math.pi

    def elevation_of_parameter(self, s):
        """|τ| (≥ 0) of the resting pose whose contact A has lamina parameter s (rad)."""
        _, nu, big_l = self._frame_a(np.asarray(s, dtype=float))
        return self._elevation(nu, big_l, fast=True)

    def geometry_at_parameter(self, s, tau_abs, branch=1):
        """:class:`ContactGeometry` from A's lamina parameter s (rad, its sign is θ's) and
        the elevation |τ| (from either chart), on a branch (±1)."""
        s = np.asarray(s, dtype=float)
        return self._pose(s, np.asarray(tau_abs, dtype=float),
                          self._branch_array(branch, s.shape))

    def chart_from_b(self, s_b):
        """(s, |τ|): A's lamina parameter (≥ 0, the side θ ≥ 0) and the elevation of the
        resting pose whose contact B on disk 2 has lamina parameter ``s_b`` (rad).

        The mirror of :meth:`geometry` with the disks' roles swapped: the in-plane part of
        the downward normal m is B's outward lamina normal ν_B, so m ∝ (μ, σν_By, ν_Bx) with
        μ ≥ 0 the elevation out of disk 2's plane, the root of the convex equation
        h(μ, σν_By) = 2Δσν_By + B·ν_B (bisection); A is disk 1's support point in direction
        (μ, σν_By). Well conditioned where A is away from disk 1's far tip (μ > 0), i.e. near
        the turning points, where :meth:`geometry`'s ψ(θ) is not.
        """
        lam, sigma = self.lamina, self.sigma
        s_b = np.asarray(s_b, dtype=float)
        point = lam.point(s_b)
        nu = lam.normal(s_b)
        c = sigma * nu[..., 1]
        big_l = 2 * self.delta * c + np.sum(point * nu, axis=-1)
        mu = self._convex_root(c, big_l, fast=True)
        s_a = lam.support(np.stack([mu, c], axis=-1)).parameter
        return np.abs(s_a), np.abs(nu[..., 0]) / np.hypot(mu, c)

    # -- scale -------------------------------------------------------------------------------
    @property
    def size(self):
        """Largest distance (m) of a disk point from G (relative errors are quoted to it)."""
        cached = self.__dict__.get('_size')
        if cached is None:
            cached = self.__dict__['_size'] = self.size_about(float(self.centroid[1]))
        return cached

    def size_about(self, g):
        """Largest distance (m) of a disk point from the point g e2 (g in m, from O)."""
        from scipy.optimize import minimize_scalar
        best = 0.0
        # disk 1: |(x, y − Δ − g)|; disk 2: |(x, σy + Δ − g)| = |(x, y + σ(Δ − g))|
        for offset in (-self.delta - g, self.sigma * (self.delta - g)):
            def dist(s, offset=offset):
                p = self.lamina.point(s)
                return np.hypot(p[..., 0], p[..., 1] + offset)
            grid = np.linspace(0.0, np.pi, 2049)
            values = dist(grid)
            j = int(np.argmax(values))
            found = minimize_scalar(lambda s: -float(dist(s)),
                                    bounds=(grid[max(j - 1, 0)], grid[min(j + 1, 2048)]),
                                    method='bounded', options={'xatol': 1e-12})
            best = max(best, float(values[j]), -float(found.fun))
        return best

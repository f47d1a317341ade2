"""The two-disk body: its parameters and the closed forms of the paper, in the body frame.

Body frame ``G e1 e2 e3`` (metres): G is the midpoint of the disk centres (the centre of
mass of two equal laminae). Disk 1 lies in the plane x3 = 0 with centre ``-Δ e2``, disk 2 in
the plane x1 = 0 with centre ``+Δ e2``; ``a`` is the semi-axis along the common axis e2,
``b`` the other one. θ locates the contact point A on disk 1, ψ the contact point B on
disk 2 (paper, section 2).

Two ways to name a configuration are offered:

* the paper's ``(theta, branch)``: ``branch = +1`` is the paper's half-cycle (B below the
  plane of disk 1, sin ψ > 0), ``branch = -1`` its mirror image in that plane;
* the regular cycle parameter ``u`` (``phase``, rad): the eccentric anomaly of A is
  η = η_max sin u (tan θ = (b/a) tan η) and ``branch = sign(cos u)``. Every quantity below
  is a smooth, 2π-periodic function of u, also through the turning points θ = ±θ_max where
  θ turns back (docs/physics.md#the-regular-phase-u). Sweeping η rather than
  θ = θ_max sin u keeps the sharp features of thin disks (b/a → 0 or ∞) at width
  ~min(a,b)/max(a,b) in u rather than its square, so far fewer table nodes are needed.

Accuracy (measured by the tests against independent constructions).

* ``σ√Q`` is computed from the exact factorisation Q = F1·F2 with
  F1 = (cos θ − cos θ_max)·L, so it keeps full relative precision as u → ±π/2; θ_max is
  taken as atan2(2b√(Δ(a+Δ)), −a²) (full precision for thin disks). All closed forms are
  analytic in u, so derivatives in u are taken by complex step (exact to rounding).
* b/a ∈ [0.05, 20], Δ/a ∈ [0.01, 0.99]: ψ, n agree with the triple-product construction to
  ≤ 3e-13 rad, lengths to ≤ 2e-14 of the size; no slip at A and B holds to the finite-
  difference limit (~1e-10 of |ω|·size).
* Extremes b/a ∈ {0.01, 100}, Δ/a ∈ {1e-3, 1 − 1e-6}: finite everywhere, also exactly at
  the turning points; unit vectors and ψ to ≤ 3e-12, lengths to ≤ 2e-13 of the size.
  ψ(θ) itself is ill-conditioned near the turning points (ψ ~ √(θ_max − θ)): use the
  phase u there, in which everything is regular.
* Δ → 0 is singular (Q(0) = 4b²Δ(a + Δ) → 0; at Δ = 0 both contacts meet on the axis):
  the functions of u vary on a scale ~2√(Δ/a) near θ = 0, so cycle tables need more nodes
  (4096 at Δ/a = 1e-3, resolved automatically); below Δ/a ≈ 1e-6 expect degraded accuracy.
"""

import math

import numpy as np

from ..numerics.analytic import COMPLEX_STEP, complex_step, complex_step_jet
from ..laminae.shapes import Ellipse
from .ellipse_phase import phase_angles
from .protocol import PhaseGeometry, RollingBody
from .rulings import convex_surface
from ..numerics.vectors import cross, vector

__all__ = ['LENGTH_RANGE', 'EllipseForms', 'EllipseBody', 'PhaseGeometry']

#: Allowed a, b and Δ (m). Every result is scale-invariant (θ_max, z_G / a, S / a, periods
#: × √(g/a) agree with the unit body's to ≤ 3e-13 from 1e-35 to 1e35 m, tests/
#: test_extreme_bodies.py), but the closed forms hold a⁴, N³ ~ a⁶ and M a², which overflow
#: or underflow float64 outside ~[1e-70, 1e70] (geometry) and ~[1e-40, 1e40] (dynamics:
#: the equilibria were misclassified at 1e-40). The range keeps a margin of 1e5 below both.
LENGTH_RANGE = (1e-30, 1e30)


def _check_parameter(name, value, low, high, rule):
    if isinstance(value, (str, bytes)):
        raise ValueError(f'{name} must be a real number {rule}, got {value!r}')
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f'{name} must be a real number {rule}, got {value!r}') from None
    if not (math.isfinite(value) and low < value < high):
        raise ValueError(f'{name} must be finite and {rule}, got {value!r}')
    return value


class EllipseForms:
    """The closed forms of the body in the cycle phase u, for one body or for a batch.

    The methods read the parameters ``a``, ``b``, ``delta`` (m), ``theta_max`` (rad) and the
    constants derived from them in the constructor of a subclass (``_cos_theta_max``,
    ``_sin_theta_max``, ``_d_max``, ``_eta_max``, ``_cos_eta_max``, ``_sin_eta_max``,
    ``_e_max``): floats in :class:`EllipseBody` (one body), arrays of shape (B,) in
    :class:`~twodisk_ros.physics.bodies.ellipse_batch.EllipseBodies` (B bodies at once; phases of shape
    (..., B) or (..., 1) then broadcast against them). The formulas are the same for both.
    """

    @property
    def stability_margin(self):
        """b² − 2a² + 2Δ² (m²): > 0 → θ = 0 family stable, < 0 → θ = ±π/2 stable, 0 neutral."""
        return self.b**2 - 2 * self.a**2 + 2 * self.delta**2

    @property
    def eta_max(self):
        """η at the turning point θ = θ_max (rad)."""
        return self._eta_max

    # -- shared pieces of the closed forms ---------------------------------------------------
    def _ellipse_terms(self, cos_t, sin_t):
        """D = √(a² sin²θ + b² cos²θ) (m), the denominator of the polar ellipse ρ = ab/D."""
        a, b = self.a, self.b
        return np.sqrt(a * a * sin_t * sin_t + b * b * cos_t * cos_t)

    def _q_cofactor(self, cos_t, d):
        """L·F2 where Q = (cos θ − cos θ_max)·L·F2 (exact factorisation, see module doc)."""
        a, b, delta = self.a, self.b, self.delta
        big_l = b * (2 * delta + a) - a * (a * a - b * b) * (self._cos_theta_max + cos_t) / (
            d + self._d_max)
        f2 = a * d + b * cos_t * (2 * delta - a)
        return big_l * f2

    def _geometry(self, theta, cos_t, sin_t, sq, d=None):
        """Closed forms from θ and σ√Q (works for complex arguments)."""
        r1, r2, n, t1, height, planar, norm_n = self._geometry_components(cos_t, sin_t, sq, d)
        return tuple(vector(*v) for v in (r1, r2, n, t1)) + (height, planar, norm_n)

    def _geometry_components(self, cos_t, sin_t, sq, d=None):
        """:meth:`_geometry` with r1, r2, n and t1 as lists of their three components
        (``d``: :meth:`_ellipse_terms` of the angles if already evaluated)."""
        a, b, delta = self.a, self.b, self.delta
        d = self._ellipse_terms(cos_t, sin_t) if d is None else d
        r1 = self._contact_a(cos_t, sin_t, d)
        zero = r1[2]
        e = a * d + 2 * b * delta * cos_t  # > 0 over the whole range
        r2 = [zero, delta - a * a * b * cos_t / e, -b * sq / e]
        n, t1, planar, norm_n = self._frame(cos_t, sin_t, sq)
        return r1, r2, n, t1 + [zero / planar], self._height(cos_t, d, norm_n), planar, norm_n

    def _height(self, cos_t, d, norm_n):
        """z_G = b (a D + Δ b cos θ) / |N| (m) from θ, D and |N| (:meth:`_frame`)."""
        return self.b * (self.a * d + self.delta * self.b * cos_t) / norm_n

    def _planar2(self, cos_t, sin_t):
        """a⁴ sin²θ + b⁴ cos²θ (m⁸): the squared norm of N's first two components."""
        return self.a**4 * sin_t * sin_t + self.b**4 * cos_t * cos_t

    def _contact_a(self, cos_t, sin_t, d):
        """The components of r1 = GA (m) from θ and D = :meth:`_ellipse_terms` (ρ = ab/D)."""
        rho = self.a * self.b / d
        return [rho * sin_t, -(self.delta + rho * cos_t), np.zeros_like(rho)]

    def _frame(self, cos_t, sin_t, sq):
        """The components of n (three) and of t1 (the first two; the third is 0), the planar
        norm and |N|, from θ and σ√Q (complex-safe)."""
        a, b = self.a, self.b
        planar2 = self._planar2(cos_t, sin_t)
        norm_n = np.sqrt(planar2 + sq * sq)
        b2_cos = b * b * cos_t
        n = [-a * a * sin_t / norm_n, b2_cos / norm_n, sq / norm_n]
        planar = np.sqrt(planar2)
        return n, [b2_cos / planar, a * a * sin_t / planar], planar, norm_n

    def _theta_array(self, theta):
        theta = np.asarray(theta, dtype=float)
        if np.any(~np.isfinite(theta)) or np.any(np.abs(theta) > self.theta_max * (1 + 1e-15)):
            raise ValueError(f'theta must be finite with |theta| <= theta_max = '
                             f'{self.theta_max!r} rad')
        return np.clip(theta, -self.theta_max, self.theta_max)

    def height_second_derivative(self, theta):
        """d²z_G/dθ² (m/rad²), by complex step of the paper's V′ (exact to rounding)."""
        theta = self._theta_array(theta)
        a, b, delta = self.a, self.b, self.delta

        def first(t):
            s, c = np.sin(t), np.cos(t)
            d = np.sqrt(a * a * s * s + b * b * c * c)
            norm2 = (2 * a**4 * s * s + b**4 * c * c + 4 * a * b * delta * c * d
                     + 4 * b * b * delta * delta * c * c)
            return a**3 * b**3 * s * c * self.stability_margin / (d * norm2**1.5)
        return complex_step(first, theta)

    # -- the regular cycle parameter u -------------------------------------------------------
    # u sweeps the eccentric anomaly η of A on disk 1 sinusoidally: η = η_max sin u, with A at
    # (b sin η, −a cos η) from the centre of disk 1, so tan θ = (b/a) tan η. Sharp features of
    # thin ellipses (b/a → 0 or ∞) then have width ~min(a, b)/max(a, b) in u, not its square.
    def phase_angles(self, u):
        """(θ, cos θ, sin θ, j) at phase u (rad), with cos θ − cos θ_max = j cos²u.

        Analytic in u (complex-step safe); exact near the turning points u = ±π/2
        (:func:`.ellipse_phase.phase_angles`)."""
        return phase_angles(u, (self.a, self.b, self._eta_max, self.theta_max,
                                self._cos_eta_max, self._sin_eta_max, self._e_max))

    def phase_theta(self, u):
        """θ(u) (rad): tan θ = (b/a) tan η with η = η_max sin u; θ(±π/2) = ±θ_max."""
        return self.phase_angles(u)[0]

    def phase_signed_sqrt_q(self, u):
        """σ√Q as a smooth function of u: cos u · √(j L F2), with cos θ − cos θ_max = j cos²u.

        Analytic in u (complex-step safe) and exact near the turning points u = ±π/2.
        """
        _, cos_t, sin_t, j = self.phase_angles(u)
        return self._phase_sqrt_q(u, cos_t, sin_t, j)

    def _phase_sqrt_q(self, u, cos_t, sin_t, j, d=None):
        """σ√Q = cos u · √(j L F2) from the angles of :meth:`phase_angles` (complex-safe;
        ``d``: :meth:`_ellipse_terms` of the angles if already evaluated)."""
        d = self._ellipse_terms(cos_t, sin_t) if d is None else d
        return np.cos(u) * np.sqrt(j * self._q_cofactor(cos_t, d))

    def phase_vectors(self, u):
        """(r1, r2, n, t1, z_G, planar, |N|, θ, σ√Q) at phase u, body frame (complex-safe).

        r1, r2 (m), the unit ground normal n and the unit tangent t1 of disk 1 at A, the height
        z_G (m) and the unnormalised lengths of the normal; for complex-step derivatives.
        """
        theta, cos_t, sin_t, j = self.phase_angles(u)
        d = self._ellipse_terms(cos_t, sin_t)
        sq = self._phase_sqrt_q(u, cos_t, sin_t, j, d)
        return self._geometry(theta, cos_t, sin_t, sq, d) + (theta, sq)

    def phase_geometry(self, u):
        """Body-frame geometry at cycle phase(s) ``u`` (rad), any real value."""
        u = np.asarray(u, dtype=float)
        theta, cos_t, sin_t, j = self.phase_angles(u)
        d = self._ellipse_terms(cos_t, sin_t)
        sq = self._phase_sqrt_q(u, cos_t, sin_t, j, d)
        branch = np.where(np.cos(u) < 0, -1.0, 1.0)
        return self._phase_geometry_from(u, theta, cos_t, sin_t, sq, branch, d)

    def _phase_geometry_from(self, u, theta, cos_t, sin_t, sq, branch, d=None):
        r1, r2, n, t1, height, planar, norm_n = self._geometry(theta, cos_t, sin_t, sq, d)
        psi = np.arctan2(sq, -self.a**2 * cos_t)
        tilt = np.arctan2(planar, sq)
        return PhaseGeometry(phase=u, theta=theta, psi=psi, branch=branch, signed_sqrt_q=sq,
                             contact_a=r1, contact_b=r2, ground_normal=n, tangent_a=t1,
                             height=height, tilt=tilt)

    def phase_height(self, u):
        """z_G(u) (m), analytic in u (the height of :meth:`phase_vectors`, alone)."""
        _, cos_t, sin_t, j = self.phase_angles(u)
        d = self._ellipse_terms(cos_t, sin_t)
        sq = self._phase_sqrt_q(u, cos_t, sin_t, j, d)
        return self._height(cos_t, d, np.sqrt(self._planar2(cos_t, sin_t) + sq * sq))

    def _psi_half_angle(self, u):
        """ψ(u) = 2 arctan(sin ψ / (1 + cos ψ)), analytic in u (|ψ| < π over the cycle)."""
        _, cos_t, _, _ = self.phase_angles(u)
        sq = self.phase_signed_sqrt_q(u)
        norm = np.sqrt(sq * sq + self.a**4 * cos_t * cos_t)
        return 2 * np.arctan(sq / (norm - self.a * self.a * cos_t))

    def phase_angles_with_rates(self, u):
        """(θ, ψ, dθ/du, dψ/du) at phase u (rad and rad per rad), one complex step each."""
        uc = np.asarray(u, dtype=float) + 1j * COMPLEX_STEP
        (theta, dtheta), (psi, dpsi) = complex_step_jet(
            (self.phase_theta(uc), self._psi_half_angle(uc)))
        return theta, psi, dtheta, dpsi

    def phase_angle_rates(self, u):
        """(dθ/du, dψ/du) at phase u, by complex step (ψ = 2 arctan(sin ψ / (1 + cos ψ)))."""
        return self.phase_angles_with_rates(u)[2:]

    def phase_rates(self, u):
        """Rates per unit u̇ at phase u: returns (ds/du, dα/du) of the trace of A.

        ds/du = (ds/dη)(dη/du) may be negative (A moves back along disk 1); dα/du = K ds/du
        ≥ 0 (paper eqs. (3)-(6): K = k cos φ, by the chain rule dη/du = η_max cos u).
        """
        _, cos_t, sin_t, j = self.phase_angles(u)
        return self._rates(u, cos_t, sin_t, self._phase_sqrt_q(u, cos_t, sin_t, j))

    def _rates(self, u, cos_t, sin_t, sq):
        """(ds/du, dα/du) of :meth:`phase_rates` from the angles at u and σ√Q."""
        a, b = self.a, self.b
        eta = self._eta_max * np.sin(u)
        speed2 = b * b * np.cos(eta) ** 2 + a * a * np.sin(eta) ** 2   # (ds/dη)²
        ds_du = np.sqrt(speed2) * self._eta_max * np.cos(u)
        k = a * b / speed2**1.5
        cos_phi = sq / np.sqrt(self._planar2(cos_t, sin_t) + sq * sq)
        return ds_du, k * cos_phi * ds_du

    def phase_angular_velocity(self, u):
        """ω_u (rad per unit u, body frame, shape u.shape + (3,)): angular velocity per u̇.

        With the contact frame (t1, n × t1, n) ↦ (c_α, c_α⊥, e_z) in the world,
        ω_u = α′ n − ½ Σ b_i × b_i′ (derivatives in u, by complex step).
        """
        u = np.asarray(u, dtype=float)
        return self._angular_velocity(u, self.phase_rates(u)[1])

    def phase_angular_velocity_and_contact(self, u):
        """(ω_u, r1): :meth:`phase_angular_velocity` and ``phase_geometry(u).contact_a`` at real
        phase(s) u (RollingBody), from one evaluation of the real closed forms."""
        u = np.asarray(u, dtype=float)
        _, cos_t, sin_t, j = self.phase_angles(u)
        d = self._ellipse_terms(cos_t, sin_t)
        dalpha = self._rates(u, cos_t, sin_t, self._phase_sqrt_q(u, cos_t, sin_t, j, d))[1]
        return self._angular_velocity(u, dalpha), vector(*self._contact_a(cos_t, sin_t, d))

    def _angular_velocity(self, u, dalpha):
        """ω_u at real u from n and t1 at u + ih (:data:`COMPLEX_STEP`) and dα/du at u."""
        uc = u + 1j * COMPLEX_STEP
        _, cos_t, sin_t, j = self.phase_angles(uc)
        n, t1, planar, _ = self._frame(cos_t, sin_t, self._phase_sqrt_q(uc, cos_t, sin_t, j))
        n, t1 = vector(*n), vector(*t1, np.zeros_like(planar) / planar)  # as phase_vectors
        m = cross(n, t1)
        n_re, t1_re, m_re = n.real, t1.real, m.real
        dn, dt1, dm = (x.imag / COMPLEX_STEP for x in (n, t1, m))
        frame_rate = 0.5 * (cross(n_re, dn) + cross(t1_re, dt1) + cross(m_re, dm))
        return dalpha[..., None] * n_re - frame_rate


class EllipseBody(EllipseForms, RollingBody):
    """Two identical elliptic disks in perpendicular planes, joined along their axis ``a``.

    Parameters
    ----------
    a : float
        Semi-axis along the common axis e2 (m), finite and > 0.
    b : float
        The other semi-axis (m), finite and > 0 (b > a is allowed).
    delta : float
        Half the distance between the disk centres (m), 0 < delta < a.

    Examples
    --------
    >>> oloid = EllipseBody(1.0, 1.0, 0.5)
    >>> round(float(oloid.height(0.0)), 12)   # z_G at θ = 0 (m)
    0.75
    """

    turns_everywhere = True     #: RollingBody: |ω_u| > 0 everywhere (no flat vertex)

    def solve_equilibria(self, search, closed_forms):
        """RollingBody: eight equilibria at fixed angles (θ = 0, ±π/2, ±θ_max), closed forms."""
        return closed_forms(self)

    def __init__(self, a, b, delta):
        a = _check_parameter('a', a, 0.0, math.inf, '> 0 (metres)')
        b = _check_parameter('b', b, 0.0, math.inf, '> 0 (metres)')
        delta = _check_parameter('delta', delta, 0.0, a, f'with 0 < delta < a = {a!r} (metres)')
        low, high = LENGTH_RANGE
        for name, value in (('a', a), ('b', b), ('delta', delta)):
            if not low <= value <= high:
                raise ValueError(f'{name} must be in [{low:g}, {high:g}] m (the closed forms '
                                 f'hold fourth and sixth powers of the lengths, which leave '
                                 f'the float range beyond), got {value!r}')
        self.a, self.b, self.delta = a, b, delta
        self.lamina = Ellipse(a, b)     # RollingBody: the shape (a along e2, b along e1)
        # RollingBody: the width in u of the sharpest feature (module docstring)
        self.feature_width = min(1.0, b / a, a / b, 2 * math.sqrt(delta / a))
        # Paper, after eq. (2): the range of θ (and ψ), cos θ_max = −a²/√(a⁴ + 4aΔb² + 4Δ²b²),
        # written as atan2 (acos of ≈ −1 would lose digits for thin disks and small Δ).
        root = math.sqrt(a**4 + 4 * a * delta * b * b + 4 * delta * delta * b * b)
        self._cos_theta_max = -a * a / root
        self.theta_max = math.atan2(2 * b * math.sqrt(delta * (a + delta)), -a * a)
        self._sin_theta_max = math.sin(self.theta_max)
        self._d_max = math.hypot(a * self._sin_theta_max, b * self._cos_theta_max)
        # η_max, its cosine and sine, and E(η_max) (phase_angles)
        self._eta_max = math.atan2(a * self._sin_theta_max, b * self._cos_theta_max)
        self._cos_eta_max = math.cos(self._eta_max)
        self._sin_eta_max = math.sin(self._eta_max)
        self._e_max = math.hypot(a * self._cos_eta_max, b * self._sin_eta_max)

    def __repr__(self):
        return f'EllipseBody(a={self.a!r}, b={self.b!r}, delta={self.delta!r})'

    def describe(self):
        return f'a = {self.a:.4g} m, b = {self.b:.4g} m, Δ = {self.delta:.4g} m'

    @property
    def origin(self):
        return np.zeros(3)      # G is the midpoint of the centres (the ellipses' symmetry)

    def resolution_cause(self):
        """Its two ratios: b/a and Δ/a set the sharpest feature of the closed forms."""
        return f'b/a = {self.b / self.a:.6g}, delta/a = {self.delta / self.a:.6g}'

    # -- named bodies ------------------------------------------------------------------------
    @classmethod
    def oloid(cls, radius=1.0):
        """The Oloid: two circles of ``radius`` whose centres are one radius apart."""
        return cls(radius, radius, radius / 2)

    @classmethod
    def two_circle_roller(cls, radius=1.0):
        """The Two-Circle-Roller: centres √2 radius apart (centre of mass at constant height)."""
        return cls(radius, radius, radius / math.sqrt(2))

    # -- scalar properties -------------------------------------------------------------------
    #: The ellipse body has the disk-swap symmetry; 'parallel' and 'swapped' are the same body.
    arrangement = 'parallel'

    @property
    def psi_max(self):
        """Largest |ψ| (rad); equal to θ_max (paper, after eq. (2))."""
        return self.theta_max

    @property
    def size(self):
        """A length scale of the body (m): the largest distance of a disk point from G.

        |G − P|² = (a² − b²)c² + 2aΔc + b² + Δ² over c = cos s ∈ [−1, 1] for P on a disk.
        """
        a, b, d = self.a, self.b, self.delta
        if a >= b or a * d >= b * b - a * a:
            return a + d
        return math.sqrt(b * b + d * d + (a * d) ** 2 / (b * b - a * a))

    # -- drawing (model/mesh.py): closed forms -----------------------------------------------
    def plate_rims(self, resolution):
        """Both rims at the eccentric anomalies 2πk/n, (a cos, b sin), exact on the axes."""
        a, b, angle = self.a, self.b, 2 * np.pi * np.arange(resolution) / resolution
        rim = np.stack([a * np.cos(angle), b * np.sin(angle)], axis=-1)
        rim[np.arange(0, resolution, resolution // 4)] = [[a, 0.0], [0.0, b], [-a, 0.0], [0.0, -b]]
        return rim, rim

    def hull_surface(self, resolution):
        """The convex hull of A and B at n equal steps of u: the ends of the hull's rulings."""
        u = 2 * np.pi * np.arange(resolution) / resolution
        # A sweeps its whole arc while cos u ≥ 0, B while sin u ≥ 0 (the grid holds 0, ±π/2, π)
        return convex_surface(np.concatenate([
            self.phase_geometry(u[(u <= np.pi / 2) | (u >= 3 * np.pi / 2)]).contact_a,
            self.phase_geometry(u[u <= np.pi]).contact_b]))

    # -- the paper's θ form ------------------------------------------------------------------
    @staticmethod
    def _branch_array(branch):
        branch = np.asarray(branch)
        if not np.all((branch == 1) | (branch == -1)):
            raise ValueError(f'branch must be +1 or -1, got {branch!r}')
        return branch.astype(float)

    def signed_sqrt_q(self, theta, branch=1):
        """σ√Q(θ) (m⁴), Q = a⁴sin²θ + 4abΔ cosθ √(a²sin²θ + b²cos²θ) + 4b²Δ²cos²θ."""
        theta = self._theta_array(theta)
        branch = self._branch_array(branch)
        abs_t = np.abs(theta)
        # cos θ − cos θ_max without cancellation near the turning points
        gap = 2 * np.sin((self.theta_max + abs_t) / 2) * np.sin((self.theta_max - abs_t) / 2)
        cos_t = np.cos(theta)
        d = self._ellipse_terms(cos_t, np.sin(theta))
        return branch * np.sqrt(np.maximum(gap * self._q_cofactor(cos_t, d), 0.0))

    def geometry(self, theta, branch=1):
        """Body-frame geometry at contact angle θ on the given branch (paper, sections 2-4)."""
        theta = self._theta_array(theta)
        branch = np.broadcast_to(self._branch_array(branch), theta.shape)
        sq = self.signed_sqrt_q(theta, branch)
        u = self.phase_from_theta(theta, branch)
        return self._phase_geometry_from(u, theta, np.cos(theta), np.sin(theta), sq, branch)

    def contact_angle_psi(self, theta, branch=1):
        """ψ(θ) (rad): cos ψ = −a² cos θ / √(Q + a⁴cos²θ), sign of sin ψ = branch."""
        theta = self._theta_array(theta)
        sq = self.signed_sqrt_q(theta, branch)
        return np.arctan2(sq, -self.a**2 * np.cos(theta))

    def contact_vector_a(self, theta):
        """r1 = GA (m, body frame), paper section 2."""
        return self.geometry(theta).contact_a

    def contact_vector_b(self, theta, branch=1):
        """r2 = GB (m, body frame), paper eq. (2)."""
        return self.geometry(theta, branch).contact_b

    def ground_normal(self, theta, branch=1):
        """Unit normal n of the ground, pointing up, in the body frame (paper, section 3)."""
        return self.geometry(theta, branch).ground_normal

    def tilt(self, theta, branch=1):
        """φ (rad): angle between the plane of disk 1 and the ground, cos φ = n·e3."""
        return self.geometry(theta, branch).tilt

    def disk_curvature(self, theta):
        """k (1/m): curvature of the bounding ellipse of disk 1 at θ (paper, section 3)."""
        theta = self._theta_array(theta)
        a, b = self.a, self.b
        s, c = np.sin(theta), np.cos(theta)
        return a * b * (a * a * s * s + b * b * c * c) ** 1.5 / (
            a**4 * s * s + b**4 * c * c) ** 1.5

    def trace_curvature(self, theta, branch=1):
        """K = k cos φ (1/m): signed curvature of the trace of A on the ground."""
        return self.disk_curvature(theta) * np.cos(self.tilt(theta, branch))

    def arc_length_rate(self, theta):
        """ds/dθ (m/rad) along the boundary of disk 1, paper eq. (1)."""
        theta = self._theta_array(theta)
        a, b = self.a, self.b
        s, c = np.sin(theta), np.cos(theta)
        d2 = a * a * s * s + b * b * c * c
        return a * b * np.sqrt(a**4 * s * s + b**4 * c * c) / d2**1.5

    def height(self, theta):
        """z_G = V/(M g) (m), the same on both branches (paper, section 4)."""
        theta = self._theta_array(theta)
        return self._height_theta(theta)

    def _height_theta(self, theta):
        a, b, delta = self.a, self.b, self.delta
        s, c = np.sin(theta), np.cos(theta)
        d = np.sqrt(a * a * s * s + b * b * c * c)
        norm2 = (2 * a**4 * s * s + b**4 * c * c + 4 * a * b * delta * c * d
                 + 4 * b * b * delta * delta * c * c)
        return b * (delta * b * c + a * d) / np.sqrt(norm2)

    def height_derivative(self, theta):
        """dz_G/dθ (m/rad), the paper's V′_θ / (M g)."""
        theta = self._theta_array(theta)
        a, b, delta = self.a, self.b, self.delta
        s, c = np.sin(theta), np.cos(theta)
        d = np.sqrt(a * a * s * s + b * b * c * c)
        norm2 = (2 * a**4 * s * s + b**4 * c * c + 4 * a * b * delta * c * d
                 + 4 * b * b * delta * delta * c * c)
        return a**3 * b**3 * s * c * self.stability_margin / (d * norm2**1.5)

    def phase_from_theta(self, theta, branch=1):
        """The phase u ∈ [−π/2, 3π/2) of contact angle θ on a branch (inverse of θ(u)).

        Exact at the turning points: with v = η_max − |η| (computed as one angle) and
        1 − sin|u| = v/η_max, |u| = π/2 − 2 arcsin √(v / 2η_max).
        """
        theta = self._theta_array(theta)
        branch = self._branch_array(branch)
        a, b, tm = self.a, self.b, self.theta_max
        abs_t = np.abs(theta)
        # tan(η_max − |η|) = a b sin(θ_max − |θ|) / (b² cos θ_max cos θ + a² sin θ_max sin θ)
        v = np.arctan2(a * b * np.sin(tm - abs_t), b * b * math.cos(tm) * np.cos(abs_t)
                       + a * a * math.sin(tm) * np.sin(abs_t))
        base = np.pi / 2 - 2 * np.arcsin(np.sqrt(np.clip(v / (2 * self.eta_max), 0.0, 0.5)))
        base = np.where(theta < 0, -base, base)
        return np.where(branch > 0, base, np.pi - base)

"""Ground contact forces of the rolling two-disk body, and where the rolling model holds.

Frames and units: world frame with z up (the ground is z = 0); body frame ``G e1 e2 e3`` as in
:mod:`twodisk_ros.body`. Forces in N, moments in N m, speeds in rad/s. The derivation is in
docs/physics.md, section "Contact forces".

Newton-Euler with both contacts at rest (no slip), in the body frame, per unit of the phase u:
ω = ω_u u̇, ω̇ = ω_u′ u̇² + ω_u ü, v_G = u̇ c with c = −ω_u × r1, hence

    a_G = u̇² (ω_u × c + c′) + ü c,          (c′ = dc/du: A moves along the boundary)
    F_A + F_B = M a_G + M g n,                L_G = u̇² (I ω_u′ + ω_u × I ω_u) + ü I ω_u,

n the ground normal, r1 = GA, r2 = GB (paper eq. (2)), d = r2 − r1 = |AB| ê. Moments about A:
d × F_B + τ ê = L_G − r1 × (F_A + F_B) =: L_A, so F_B⊥ = (L_A × d)/|d|² and τ = ê·L_A (the
drive torque; zero along a free motion, where it is the residual of m ü + ½ m′ u̇² + V′ = 0).
Only the sum S of the components along ê is determined (the squeeze). Every output is linear
in (1, u̇², ü) with coefficients that depend on u only: they are tabulated once per cycle.
"""

from dataclasses import dataclass
import math

import numpy as np
from scipy.optimize import minimize_scalar

from twodisk_ros.body import complex_step
from twodisk_ros.cycle import TWO_PI
from twodisk_ros.dynamics import RollingDynamics
from twodisk_ros.tables import HermiteTable, spectral_tail

__all__ = ['ContactForceModel', 'ContactForces', 'ValidityReport', 'squeeze_split',
           'check_validity', 'motion_validity', 'QUANTITIES']

#: the scalar outputs, in the order of the tables' columns
QUANTITIES = ('normal_a', 'normal_b', 'tangential_a', 'tangential_b', 'along_ab',
              'drive_torque')
_K = len(QUANTITIES)
BLOCK = 65536


def _spectral_derivative(samples):
    n = samples.shape[0]
    k = np.fft.fftfreq(n, d=1.0 / n).reshape((n,) + (1,) * (samples.ndim - 1))
    k[n // 2] = 0.0
    return np.real(np.fft.ifft(1j * k * np.fft.fft(samples, axis=0), axis=0))


def _dot(x, y):
    return np.sum(x * y, axis=-1)


def squeeze_split(normal_a, normal_b, tangential_a, tangential_b, along_ab):
    """The split of the total along AB that needs the least friction coefficient.

    With x the component along ê taken by A (B takes S − x), the friction ratios are
    f_A(x) = √(T_A² + x²)/N_A and f_B(x) = √(T_B² + (S − x)²)/N_B, both convex, with minima at
    x = 0 and x = S. μ_required = min_x max(f_A, f_B) is reached at x = 0 if f_A(0) ≥ f_B(0),
    at x = S if f_B(S) ≥ f_A(S), else at the unique root of f_A² = f_B² between 0 and S (a
    quadratic, solved in cancellation-free form). The minimiser is unique (f_A, f_B are
    strictly increasing in |x| and |S − x|). Where N_A ≤ 0 or N_B ≤ 0 (lift-off) the split is
    x = S/2, the ratio of a lifted contact is inf and μ_required is inf.

    Parameters
    ----------
    normal_a, normal_b, tangential_a, tangential_b, along_ab : ndarray
        N_A, N_B, T_A, T_B, S (N), broadcast together.

    Returns
    -------
    along_a, ratio_a, ratio_b, mu_required : ndarray
        x (N), f_A(x), f_B(x) and max(f_A, f_B) at the split.
    """
    n_a, n_b, t_a, t_b, s = np.broadcast_arrays(normal_a, normal_b, tangential_a,
                                                tangential_b, along_ab)
    contact = (n_a > 0) & (n_b > 0)
    na2, nb2 = n_a * n_a, n_b * n_b
    alpha = nb2 - na2
    beta = na2 * s
    gamma = nb2 * t_a * t_a - na2 * (t_b * t_b + s * s)
    root = np.sqrt(np.maximum(beta * beta - alpha * gamma, 0.0))
    q = -(beta + np.copysign(root, beta))
    low, high = np.minimum(s, 0.0), np.maximum(s, 0.0)
    safe_na = np.where(contact, n_a, 1.0)
    safe_nb = np.where(contact, n_b, 1.0)
    with np.errstate(divide='ignore', invalid='ignore'):
        candidates = [np.zeros_like(s), s, gamma / q, q / alpha]
    best_x, best_mu = None, None
    for x in candidates:
        x = np.clip(np.where(np.isfinite(x), x, 0.0), low, high)
        mu = np.maximum(np.hypot(t_a, x) / safe_na, np.hypot(t_b, s - x) / safe_nb)
        if best_mu is None:
            best_x, best_mu = x, mu
        else:
            better = mu < best_mu
            best_x, best_mu = np.where(better, x, best_x), np.minimum(mu, best_mu)
    x = np.where(contact, best_x, 0.5 * s)
    inf = np.inf
    ratio_a = np.where(n_a > 0, np.hypot(t_a, x) / np.where(n_a > 0, n_a, 1.0), inf)
    ratio_b = np.where(n_b > 0, np.hypot(t_b, s - x) / np.where(n_b > 0, n_b, 1.0), inf)
    return x, ratio_a, ratio_b, np.where(contact, best_mu, inf)


@dataclass
class ContactForces:
    """Ground forces on the body at A and at B, arrays over states (world frame, N).

    ê is the horizontal unit vector from A to B, p = e_z × ê; the split of the total along ê
    is the one needing the least friction (:func:`squeeze_split`).
    """

    phase: np.ndarray           #: u (rad)
    phase_rate: np.ndarray      #: u̇ (rad/s)
    phase_acceleration: np.ndarray  #: ü (rad/s²)
    force_a: np.ndarray         #: F_A (N, world frame), shape (..., 3)
    force_b: np.ndarray         #: F_B (N, world frame), shape (..., 3)
    direction_ab: np.ndarray    #: ê (unit, world frame), shape (..., 3)
    normal_a: np.ndarray        #: N_A = F_A·e_z (N)
    normal_b: np.ndarray        #: N_B = F_B·e_z (N)
    tangential_a: np.ndarray    #: T_A = F_A·p (N), determinate
    tangential_b: np.ndarray    #: T_B = F_B·p (N), determinate
    along_ab: np.ndarray        #: S = (F_A + F_B)·ê (N), determinate
    along_a: np.ndarray         #: F_A·ê (N) of the chosen split (F_B·ê = S − F_A·ê)
    ratio_a: np.ndarray         #: |F_A,tangential|/N_A at the split (inf if N_A ≤ 0)
    ratio_b: np.ndarray         #: |F_B,tangential|/N_B at the split (inf if N_B ≤ 0)
    mu_required: np.ndarray     #: least friction coefficient for rolling (inf on lift-off)
    drive_torque: np.ndarray    #: τ (N m): external moment τ ê on the body (0 if free)
    weight: float               #: M g (N)

    @property
    def along_b(self):
        """F_B·ê (N) of the chosen split."""
        return self.along_ab - self.along_a

    @property
    def normal_a_per_weight(self):
        """N_A / (M g)."""
        return self.normal_a / self.weight

    @property
    def normal_b_per_weight(self):
        """N_B / (M g)."""
        return self.normal_b / self.weight

    @property
    def lift_off(self):
        """True where a contact would need the ground to pull (N_A < 0 or N_B < 0)."""
        return (self.normal_a < 0) | (self.normal_b < 0)


class ContactForceModel:
    """Contact forces of one body with one mass model, from per-cycle tables.

    Parameters
    ----------
    dynamics : RollingDynamics
        Body, mass properties (kg, kg m² about G in the body frame), gravity (m/s²) and the
        cycle (world poses).
    nodes : int, optional
        Table nodes per cycle (default: 4 × the cycle's resolution).

    Attributes
    ----------
    spectral_tail : float
        Relative size of the unresolved spectrum of the coefficient tables (~1e-13 or less
        when resolved).
    """

    def __init__(self, dynamics, nodes=None):
        if not isinstance(dynamics, RollingDynamics):
            raise TypeError(f'dynamics must be a RollingDynamics, got {type(dynamics).__name__}')
        self.dynamics = dynamics
        self.body, self.cycle = dynamics.body, dynamics.cycle
        self.mass = dynamics.mass.mass
        self.weight = self.mass * dynamics.gravity
        n = int(nodes) if nodes is not None else 4 * self.cycle.resolution
        self._build(n)

    # -- tables ------------------------------------------------------------------------------
    def _build(self, n):
        u = TWO_PI * np.arange(n) / n
        geo = self.body.phase_geometry(u)
        r1, r2, normal, t1 = geo.contact_a, geo.contact_b, geo.ground_normal, geo.tangent_a
        inertia, mass, g = self.dynamics.mass.inertia, self.mass, self.dynamics.gravity
        w = self.body.phase_angular_velocity(u)                  # ω_u, body frame
        dw = _spectral_derivative(w)
        c = -np.cross(w, r1)                                     # dG/du, body frame
        k = np.cross(w, c) + _spectral_derivative(c)             # a_G per u̇²
        iw = w @ inertia
        d = r2 - r1
        length2 = _dot(d, d)
        e = d / np.sqrt(length2)[:, None]
        p = np.cross(normal, e)
        # coefficient sets (gravity, u̇², ü): total force and moment about G
        force = (mass * g * normal, mass * k, mass * c)
        moment = (np.zeros_like(w), dw @ inertia + np.cross(w, iw), iw)
        coef = np.empty((n, 3, _K))
        for j, (f, m) in enumerate(zip(force, moment)):
            moment_a = m - np.cross(r1, f)
            f_b = np.cross(moment_a, d) / length2[:, None]
            coef[:, j] = np.stack([_dot(f, normal) - _dot(f_b, normal), _dot(f_b, normal),
                                   _dot(f, p) - _dot(f_b, p), _dot(f_b, p), _dot(f, e),
                                   _dot(moment_a, e)], axis=-1)
        # world direction of ê: heading of t1 (paper eqs. (4)-(6)) plus the angle of ê from t1;
        # stored as a periodic part plus slope·u (slope: the cycle's turn, plus any winding)
        m_axis = np.cross(normal, t1)
        gamma = np.unwrap(np.arctan2(_dot(e, m_axis), _dot(e, t1)))
        slope = self.cycle.displacement.turn / TWO_PI
        periodic = self.cycle.heading(u) + gamma - slope * u
        winding = round((2 * periodic[-1] - periodic[-2] - periodic[0]) / TWO_PI)
        self._turn = self.cycle.displacement.turn
        self._slope = slope + winding
        periodic = periodic - winding * u
        # second derivatives are spectral; the mass-matrix pieces give the mode tables
        m_u = _dot(w, iw) + mass * _dot(c, c)
        speed = np.linalg.norm(w, axis=-1)
        dv = mass * g * complex_step(self.body.phase_height, u)
        self._columns = dict(
            general=coef.reshape(n, 3 * _K),
            dynamic=np.concatenate([coef[:, 0] - (dv / m_u)[:, None] * coef[:, 2],
                                    coef[:, 1] - (0.5 * _spectral_derivative(m_u) / m_u)[:, None]
                                    * coef[:, 2]], axis=1),
            kinematic=np.concatenate([coef[:, 0], (coef[:, 1] - (_spectral_derivative(speed)
                                                                 / speed)[:, None] * coef[:, 2])
                                      / (speed * speed)[:, None]], axis=1))
        self._periodic_heading = periodic
        self._tables = {}
        self.spectral_tail = max(spectral_tail(x) for x in self._columns.values())
        self.nodes = n

    def _table(self, kind):
        if kind not in self._tables:
            periodic = self._periodic_heading
            values = np.column_stack([self._columns[kind], periodic])
            first = _spectral_derivative(values)
            second = _spectral_derivative(first)
            close = np.concatenate
            values, first, second = (close([x, x[:1]]) for x in (values, first, second))
            step = TWO_PI / len(periodic)
            self._tables[kind] = HermiteTable(0.0, step, values, first, second)
        return self._tables[kind]

    def coefficients(self, u, kind='kinematic'):
        """The tabulated coefficients at phase(s) u, shape u.shape + (columns,).

        ``'kinematic'``: (Q0, Q2) with Q = Q0 + Ω² Q2 for each of :data:`QUANTITIES`;
        ``'dynamic'``: (Q0, Q2) with Q = Q0 + u̇² Q2 along a free motion; ``'general'``:
        (Q_g, Q_u̇², Q_ü) for a given ü. The last column is the periodic part of ê's heading.
        """
        u = np.asarray(u, dtype=float)
        return self._table(kind)(np.mod(u, TWO_PI))

    # -- forces ------------------------------------------------------------------------------
    def _evaluate(self, kind, u, a, b=None):
        u = np.asarray(u, dtype=float)
        shape = np.broadcast_shapes(u.shape, np.shape(a), np.shape(b) if b is not None else ())
        u = np.broadcast_to(u, shape).ravel()
        a = np.broadcast_to(np.asarray(a, dtype=float), shape).ravel()
        b = None if b is None else np.broadcast_to(np.asarray(b, dtype=float), shape).ravel()
        out = {name: np.empty(u.size) for name in QUANTITIES + ('along_a', 'ratio_a', 'ratio_b',
                                                                'mu_required', 'heading')}
        table = self._table(kind)
        for start in range(0, u.size, BLOCK):
            part = slice(start, start + BLOCK)
            cycles = np.floor(u[part] / TWO_PI)
            f = table(u[part] - TWO_PI * cycles)
            values = f[:, :_K] + a[part, None] * f[:, _K:2 * _K]
            if b is not None:
                values += b[part, None] * f[:, 2 * _K:3 * _K]
            for j, name in enumerate(QUANTITIES):
                out[name][part] = values[:, j]
            split = squeeze_split(*values[:, :5].T)
            for name, x in zip(('along_a', 'ratio_a', 'ratio_b', 'mu_required'), split):
                out[name][part] = x
            rest = u[part] - TWO_PI * cycles
            out['heading'][part] = f[:, -1] + self._slope * rest + cycles * self._turn
        out['phase'] = u
        return shape, out

    def _result(self, shape, out, u_dot, u_ddot):
        cos_h, sin_h = np.cos(out['heading']), np.sin(out['heading'])
        zero = np.zeros_like(cos_h)
        e = np.stack([cos_h, sin_h, zero], axis=-1)
        p = np.stack([-sin_h, cos_h, zero], axis=-1)
        x_a, s = out['along_a'], out['along_ab']

        def vector(along, tangential, normal):
            v = along[:, None] * e + tangential[:, None] * p
            v[:, 2] = normal
            return v.reshape(shape + (3,))
        scalars = {name: out[name].reshape(shape) for name in QUANTITIES
                   + ('along_a', 'ratio_a', 'ratio_b', 'mu_required')}
        return ContactForces(
            phase=out['phase'].reshape(shape), phase_rate=np.broadcast_to(u_dot, shape),
            phase_acceleration=np.broadcast_to(u_ddot, shape),
            force_a=vector(x_a, out['tangential_a'], out['normal_a']),
            force_b=vector(s - x_a, out['tangential_b'], out['normal_b']),
            direction_ab=e.reshape(shape + (3,)), weight=self.weight, **scalars)

    def forces(self, u, u_dot, u_ddot):
        """Contact forces for given u (rad), u̇ (rad/s) and ü (rad/s²), arrays broadcast.

        The drive torque τ (N m) is the external pure moment τ ê the body needs for this ü;
        ê points from A to B and τ > 0 turns the body positively about ê (power τ ê·ω).
        """
        u_dot, u_ddot = np.asarray(u_dot, float), np.asarray(u_ddot, float)
        shape, out = self._evaluate('general', u, u_dot**2, u_ddot)
        return self._result(shape, out, u_dot, u_ddot)

    def dynamic(self, u, u_dot):
        """Forces along a free motion (gravity only): ü = −(V′ + ½ m′ u̇²)/m, τ ≈ 0."""
        u, u_dot = np.broadcast_arrays(np.asarray(u, float), np.asarray(u_dot, float))
        shape, out = self._evaluate('dynamic', u, u_dot**2)
        f = self.dynamics.tabulated(u)
        df = self.dynamics.tabulated(u, derivative=1)
        u_ddot = -(df[..., 1] + 0.5 * df[..., 0] * u_dot**2) / f[..., 0]
        return self._result(shape, out, u_dot, u_ddot)

    def kinematic(self, u, omega):
        """Forces when a drive holds |ω| = Ω (rad/s): u̇ = Ω/|ω_u|, ü = −Ω² |ω_u|′/|ω_u|³.

        Forces are N0(u) + Ω² N2(u); τ (N m) is the drive's moment τ ê about AB (see
        :meth:`forces`). u̇ is reported ≥ 0; reversing the motion changes no force.
        """
        u, omega = np.broadcast_arrays(np.asarray(u, float), np.asarray(omega, float))
        shape, out = self._evaluate('kinematic', u, omega**2)
        w = self.dynamics.tabulated(u)[..., 2]
        dw = self.dynamics.tabulated(u, derivative=1)[..., 2]
        return self._result(shape, out, np.abs(omega) / w, -omega**2 * dw / w**3)

    def along(self, motion):
        """Forces at the samples of a :class:`~twodisk_ros.dynamics.RollingMotion`."""
        if motion.mode == 'dynamic':
            return self.dynamic(motion.phase, motion.phase_rate)
        omega = abs(motion.phase_rate[0]) * float(self.dynamics.tabulated(motion.phase[0])[2])
        return self.kinematic(motion.phase, omega)

    # -- per body ----------------------------------------------------------------------------
    def liftoff_speed(self):
        """Critical |ω| (rad/s) above which a contact lifts off in kinematic motion.

        Exact from N(u; Ω) = N0(u) + Ω² N2(u): Ω_c² = min over u and both contacts of
        −N0/N2 where N2 < 0 (0 where N0 ≤ 0 already), minimised on the nodes and refined by
        bounded Brent on the tables. Returns (Ω_c, u_c, contact 'A' or 'B'); Ω_c = inf if no
        speed lifts a contact off.
        """
        cols = self._columns['kinematic']
        best = (math.inf, math.nan, '')
        step = TWO_PI / self.nodes
        for j, name in ((0, 'A'), (1, 'B')):
            n0, n2 = cols[:, j], cols[:, _K + j]
            if np.any(n0 <= 0):
                i = int(np.argmin(n0))
                return 0.0, float(TWO_PI * i / self.nodes), name
            ratio = np.where(n2 < 0, -n0 / np.where(n2 < 0, n2, -1.0), np.inf)
            i = int(np.argmin(ratio))
            if not np.isfinite(ratio[i]):
                continue

            def square(x, j=j):
                c = self.coefficients(x)
                return -c[j] / c[_K + j] if c[_K + j] < 0 else np.inf
            res = minimize_scalar(square, bounds=(step * (i - 1), step * (i + 1)),
                                  method='bounded', options={'xatol': 1e-12})
            value = min(float(res.fun), float(ratio[i]))
            u_c = float(res.x) if res.fun <= ratio[i] else step * i
            if value < best[0] ** 2:
                best = (math.sqrt(value), u_c % TWO_PI, name)
        return best

    def mu_required_kinematic(self, omega, samples=2048):
        """max over one cycle of μ_required at each speed Ω (rad/s, array): inf past lift-off."""
        omega = np.asarray(omega, float)
        u = TWO_PI * np.arange(samples) / samples
        return self.kinematic(u, omega[..., None]).mu_required.max(axis=-1)

    def mu_required_dynamic(self, energy, u0=None, samples=2048):
        """max of μ_required over the phases a free motion of energy E (J) reaches.

        Rolling over (E above every maximum of V) reaches the whole cycle; otherwise the
        well of V holding ``u0`` (rad) if given, else every u with V(u) ≤ E.
        Returns (max μ_required, u (rad), μ_required(u) with nan where not reached).
        """
        u = TWO_PI * np.arange(samples) / samples
        if u0 is not None and energy < self.dynamics.potential_range[1]:
            _, low, high = self.dynamics.well(float(u0))
            u = low + (high - low) * (np.arange(samples) + 0.5) / samples
        f = self.dynamics.tabulated(u)
        rate2 = 2 * (energy - f[..., 1]) / f[..., 0]
        reached = rate2 >= 0
        mu = self.dynamic(u, np.sqrt(np.maximum(rate2, 0.0))).mu_required
        mu = np.where(reached, mu, np.nan)
        return float(np.nanmax(mu)) if np.any(reached) else math.nan, u, mu


@dataclass(frozen=True)
class ValidityReport:
    """Where the rolling model first fails along a motion (or that it never does)."""

    valid: bool
    time: float       #: first sample time of failure (s); nan if valid
    index: int        #: its sample index; −1 if valid
    kind: str         #: 'lift-off A', 'lift-off B', 'slip' or ''
    reason: str       #: human-readable sentence


def check_validity(times, forces, mu=math.inf):
    """First sample at which a contact lifts off (N < 0) or slips (μ_required > μ).

    Parameters
    ----------
    times : array_like
        Sample times (s), one per state of ``forces``.
    forces : ContactForces
    mu : float
        Friction coefficient of the ground (inf: no slip ever).

    Returns
    -------
    ValidityReport
        Resolution is the sampling: the reported time is that of the first bad sample.
    """
    t = np.asarray(times, float).ravel()
    n_a, n_b = forces.normal_a.ravel(), forces.normal_b.ravel()
    need = forces.mu_required.ravel()
    bad = (n_a < 0) | (n_b < 0) | (need > mu)
    if not np.any(bad):
        return ValidityReport(True, math.nan, -1, '', f'rolling is valid for t in '
                              f'[{t[0]:.6g}, {t[-1]:.6g}] s (mu = {mu:g})')
    i = int(np.argmax(bad))
    if n_a[i] < 0 or n_b[i] < 0:
        name, value = ('A', n_a[i]) if n_a[i] <= n_b[i] else ('B', n_b[i])
        return ValidityReport(False, float(t[i]), i, f'lift-off {name}',
                              f'contact {name} would lift off at t = {t[i]:.6g} s: '
                              f'N_{name} = {value:.4g} N')
    return ValidityReport(False, float(t[i]), i, 'slip',
                          f'the body would slip at t = {t[i]:.6g} s: mu_required = '
                          f'{need[i]:.4g} > mu = {mu:g}')


def motion_validity(model, motion, mu=math.inf):
    """:func:`check_validity` along a simulated motion; returns (report, forces)."""
    forces = model.along(motion)
    return check_validity(motion.t, forces, mu), forces

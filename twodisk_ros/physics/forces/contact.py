"""Ground contact forces of the rolling two-disk body, and where the rolling model holds.

Frames and units: world frame with z up (the ground is z = 0); body frame ``G e1 e2 e3`` as in
:mod:`twodisk_ros.body`. Forces in N, moments in N m, speeds in rad/s. The derivation is in
docs/physics.md, section "Contact forces".

Newton–Euler with both contacts at rest (no slip), moments about A (d = r2 − r1 = |AB| ê):
d × F_B + τ ê = L_G − r1 × (F_A + F_B) =: L_A, so F_B⊥ = (L_A × d)/|d|² and τ = ê·L_A (the
drive torque; zero along a free motion). Only the sum S along ê is determined (the squeeze,
resolved by :func:`squeeze_split`). The coefficients, per unit of the body's turn γ for any
RollingBody, are built in :mod:`~twodisk_ros.physics.forces.terms` and tabulated once per
cycle (quintic Hermite, spectral derivatives): 10⁶ states take ~0.4 s
(benchmarks/contact_forces_rate.py). The heading of the trace of A, which orients ê in the
world, solves the paper's eqs. (4)-(6).

Public API: :class:`ContactForceModel` (``forces``, ``dynamic``, ``kinematic``, ``along``,
``coefficients``), :class:`ContactForces`, :func:`squeeze_split`. Validity checks and
speed sweeps are in :mod:`forces.validity` (same folder).
"""

from dataclasses import dataclass
import functools

import numpy as np

from ..bodies.ellipse_batch import cross, dot
from ..bodies.cycle import TWO_PI
from ..motion.dynamics import RollingDynamics
from .terms import ForceTerms
from ..numerics.spectral import real_spectral_derivative, spectral_derivative, spectral_tail
from ..numerics.tables import HermiteTable

__all__ = ['ContactForceModel', 'ContactForces', 'squeeze_split', 'kinematic_coefficients',
           'QUANTITIES']

#: the determinate scalar outputs (N, N, N, N, N, N m), in the order of the tables' columns
QUANTITIES = ('normal_a', 'normal_b', 'tangential_a', 'tangential_b', 'along_ab',
              'drive_torque')
_K = len(QUANTITIES)
_SPLIT = ('along_a', 'ratio_a', 'ratio_b', 'mu_required')
BLOCK = 8192   # states per block (keeps the temporaries in cache)


def _dot(x, y):
    return np.sum(x * y, axis=-1)


def squeeze_split(normal_a, normal_b, tangential_a, tangential_b, along_ab):
    """The split of the total along AB that needs the least friction coefficient.

    With x the component along ê taken by A (B takes S − x), the friction ratios are
    f_A(x) = √(T_A² + x²)/N_A and f_B(x) = √(T_B² + (S − x)²)/N_B, convex with minima at x = 0
    and x = S. μ_required = min_x max(f_A, f_B) is reached at x = 0 if f_A(0) ≥ f_B(0), at
    x = S if f_B(S) ≥ f_A(S), else at the one root of f_A² = f_B² between 0 and S (a quadratic,
    solved in cancellation-free form). The minimiser is unique. Where N_A ≤ 0 or N_B ≤ 0
    (lift-off) the split is x = S/2, a lifted contact's ratio is inf and μ_required is inf.

    Parameters
    ----------
    normal_a, normal_b, tangential_a, tangential_b, along_ab : array_like
        N_A, N_B, T_A, T_B, S (N), broadcast together.

    Returns
    -------
    along_a, ratio_a, ratio_b, mu_required : ndarray
        x (N), f_A(x), f_B(x) and max(f_A, f_B) = μ_required at the split.
    """
    n_a, n_b, t_a, t_b, s = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (
        normal_a, normal_b, tangential_a, tangential_b, along_ab)))
    contact = (n_a > 0) & (n_b > 0)
    inv_a = 1.0 / np.where(n_a > 0, n_a, np.nan)
    inv_b = 1.0 / np.where(n_b > 0, n_b, np.nan)
    ta2, tb2, s2 = t_a * t_a, t_b * t_b, s * s
    # f_A² = f_B² ⇔ α x² + 2β x + γ = 0; q = −(β + sign β √(β² − αγ)), roots γ/q and q/α.
    # β² − αγ = N_A²N_B²S² − α(N_B²T_A² − N_A²T_B²): the N_A⁴S² terms cancel exactly, which
    # formed as β² − αγ would cost (N_A/N_B)² ulps (1e-9 relative in μ at N_A/N_B = 2000)
    na2, nb2 = n_a * n_a, n_b * n_b
    alpha, beta = nb2 - na2, na2 * s
    gamma = nb2 * ta2 - na2 * (tb2 + s2)
    discriminant = na2 * nb2 * s2 - alpha * (nb2 * ta2 - na2 * tb2)
    q = -(beta + np.copysign(np.sqrt(np.maximum(discriminant, 0.0)), beta))
    low, high = np.minimum(s, 0.0), np.maximum(s, 0.0)
    with np.errstate(divide='ignore', invalid='ignore'):
        root = gamma / q
        root = np.where((root >= low) & (root <= high), root, q / alpha)
        root = np.clip(np.where(np.isfinite(root), root, 0.0), low, high)
        at_a = np.sqrt(ta2) * inv_a >= np.sqrt(tb2 + s2) * inv_b      # f_A(0) ≥ f_B(0)
        at_b = np.sqrt(tb2) * inv_b >= np.sqrt(ta2 + s2) * inv_a      # f_B(S) ≥ f_A(S)
    x = np.where(contact, np.where(at_a, 0.0, np.where(at_b, s, root)), 0.5 * s)
    y = s - x
    ratio_a = np.where(n_a > 0, np.sqrt(ta2 + x * x) * inv_a, np.inf)
    ratio_b = np.where(n_b > 0, np.sqrt(tb2 + y * y) * inv_b, np.inf)
    return x, ratio_a, ratio_b, np.maximum(ratio_a, ratio_b)


def kinematic_coefficients(samples, inertia, mass, gravity):
    """The kinematic columns of :class:`ContactForceModel` at one cycle's nodes, for a batch.

    Ellipses only (EllipseBodies, which turn at every u: |ω_u| > 0); the same construction
    as the model's tables in u (Newton-Euler per unit u, moments about A,
    spectral u-derivatives of dG/du, ω_u and |ω_u|), for B bodies at once and component by
    component, without the heading and the drive torque, which the lift-off speed and
    μ_required do not need.

    Parameters
    ----------
    samples : CycleSamples
        The bodies' closed forms at u_j = 2πj/N (:meth:`EllipseBodies.cycle_samples
        <twodisk_ros.physics.bodies.ellipse_batch.EllipseBodies.cycle_samples>`): vectors (3, N, B).
    inertia : ndarray, shape (B, 3, 3)
        Inertia about G (kg m², body frame).
    mass, gravity : float or ndarray of shape (B,)
        M (kg) and g (m/s²).

    Returns
    -------
    q0, q2 : ndarray, shape (5, N, B)
        N_A, N_B, T_A, T_B, S (N, the first five :data:`QUANTITIES`) when a drive holds
        |ω| = Ω: Q = Q0 + Ω² Q2 (the model's ``'kinematic'`` coefficients at the nodes).
    """
    r1, r2, normal = samples.contact_a, samples.contact_b, samples.ground_normal
    w = samples.angular_velocity
    inertia = np.asarray(inertia, dtype=float)

    def times_inertia(x):                                   # (x^T I)_j, x (3, N, B)
        out = np.empty(x.shape)
        for j in range(3):
            np.multiply(x[0], inertia[:, 0, j], out=out[j])
            out[j] += x[1] * inertia[:, 1, j]
            out[j] += x[2] * inertia[:, 2, j]
        return out

    c = -cross(w, r1)                                       # dG/du, body frame
    dc, dw = np.split(real_spectral_derivative(np.concatenate([c, w]), axis=1), 2)
    k = cross(w, c) + dc                                    # a_G per u̇² (body frame)
    iw = times_inertia(w)
    d = r2 - r1
    length2 = dot(d, d)
    e = d / np.sqrt(length2)
    p = cross(normal, e)
    force = (mass * gravity * normal, mass * k, mass * c)
    moment = (None, times_inertia(dw) + cross(w, iw), iw)
    coef = np.empty((3, 5) + length2.shape)
    for out, f, m in zip(coef, force, moment):
        moment_a = cross(r1, f)
        moment_a = np.negative(moment_a, out=moment_a) if m is None else m - moment_a
        f_b = cross(moment_a, d)
        f_b /= length2
        out[1], out[3], out[4] = dot(f_b, normal), dot(f_b, p), dot(f, e)
        np.subtract(dot(f, normal), out[1], out=out[0])
        np.subtract(dot(f, p), out[3], out=out[2])
    speed = np.sqrt(dot(w, w))
    kin2 = -real_spectral_derivative(speed) / speed**3
    return coef[0], coef[1] / speed**2 + kin2 * coef[2]


@dataclass
class ContactForces:
    """Ground forces on the body at A and at B, arrays over states (world frame, N).

    ê is the horizontal unit vector from A to B, p = e_z × ê; the split of the total along ê
    is the one needing the least friction (:func:`squeeze_split`). Where the body stops
    turning while a contact sweeps a flat vertex (docs/physics.md#contact-forces) a force
    component is ±inf for that instant (0 if its singular part vanishes), μ_required and the
    ratios are their limits there, u̇ = inf and ü = nan (u is no coordinate at that instant).
    """

    phase: np.ndarray               #: u (rad)
    phase_rate: np.ndarray          #: u̇ (rad/s)
    phase_acceleration: np.ndarray  #: ü (rad/s²)
    force_a: np.ndarray             #: F_A (N, world frame), shape (..., 3)
    force_b: np.ndarray             #: F_B (N, world frame), shape (..., 3)
    direction_ab: np.ndarray        #: ê (unit, world frame), shape (..., 3)
    normal_a: np.ndarray            #: N_A = F_A·e_z (N)
    normal_b: np.ndarray            #: N_B = F_B·e_z (N)
    tangential_a: np.ndarray        #: T_A = F_A·p (N), determinate
    tangential_b: np.ndarray        #: T_B = F_B·p (N), determinate
    along_ab: np.ndarray            #: S = (F_A + F_B)·ê (N), determinate
    along_a: np.ndarray             #: F_A·ê (N) of the chosen split (F_B·ê = S − F_A·ê)
    ratio_a: np.ndarray             #: |F_A tangential|/N_A at the split (inf if N_A ≤ 0)
    ratio_b: np.ndarray             #: |F_B tangential|/N_B at the split (inf if N_B ≤ 0)
    mu_required: np.ndarray         #: least friction coefficient for rolling (inf on lift-off)
    drive_torque: np.ndarray        #: τ (N m): external moment τ ê on the body (≈ 0 if free)
    along_b: np.ndarray             #: F_B·ê (N) of the chosen split (S − F_A·ê)
    angular_speed: np.ndarray       #: w = |ω| (rad/s), ≥ 0, finite where u̇ is not
    angular_acceleration: np.ndarray  #: ẇ (rad/s²): the body's angular acceleration about AB
    weight: float                   #: M g (N)

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

    Any :class:`~twodisk_ros.physics.bodies.protocol.RollingBody`: the coefficients are built
    per unit of the body's turn γ (:mod:`~twodisk_ros.physics.forces.terms`), so they stay
    finite where the body stops turning in u; where it stops turning while a contact sweeps
    a flat vertex the forces are infinite for an instant (docs/physics.md#contact-forces).

    Parameters
    ----------
    dynamics : RollingDynamics
        Body, mass properties (kg, kg m² about G in the body frame), gravity (m/s²) and the
        cycle (world poses).
    nodes : int, optional
        Table nodes per cycle (default: 4 × the cycle's resolution).

    Attributes
    ----------
    weight : float
        M g (N).
    spectral_tail : float
        Relative size of the unresolved spectrum of the coefficient tables (~1e-13 or less
        when resolved).
    terms : ForceTerms
        The coefficients at the nodes of the table coordinate y (``terms.regular``: y = u).
    """

    def __init__(self, dynamics, nodes=None):
        if not isinstance(dynamics, RollingDynamics):
            raise TypeError(f'dynamics must be a RollingDynamics, got {type(dynamics).__name__}')
        self.dynamics = dynamics
        self.body, self.cycle = dynamics.body, dynamics.cycle
        self.mass = dynamics.mass.mass
        self.weight = self.mass * dynamics.gravity
        self.nodes = int(nodes) if nodes is not None else 4 * self.cycle.resolution
        self._build(self.nodes)

    # -- tables ------------------------------------------------------------------------------
    def _build(self, n):
        terms = self.terms = ForceTerms(self.body, self.dynamics.mass.inertia, self.mass,
                                        self.dynamics.gravity, n)
        self._turn = self.cycle.displacement.turn
        heading, self._slope = self._heading(terms)
        # Q = A + a C / s (a = Ω² or w²); the 7th quantity is ẇ = γ̈
        j, dj = terms.inertia_line, terms.inertia_slope
        dyn0 = -terms.potential_turn_slope() / j
        dyn2 = -0.5 * dj / j
        zero = np.zeros((n, 1))
        rates = np.column_stack([terms.s, terms.s_u, terms.ds_u, heading])
        self._columns = {
            'dynamic': np.column_stack([terms.q_g + dyn0[:, None] * terms.q_a, dyn0,
                                        terms.p + dyn2[:, None] * terms.q_a, dyn2, rates]),
            'kinematic': np.column_stack([terms.q_g, zero, terms.p, zero, rates])}
        if terms.regular:
            self._general_columns(terms, heading)
        self._tail_kinds = tuple(self._columns)       # the tables of spectral_tail
        # a singular coefficient below this is taken as zero at a flat-vertex instant
        self._singular_floor = 1e-9 * np.max(np.abs(self._columns['kinematic'][:, 7:14]),
                                             axis=0)
        self._tables = {}

    @functools.cached_property
    def spectral_tail(self):
        """Relative size of the unresolved spectrum of the coefficient tables built with the
        model (~1e-13 or less when resolved). Computed when first read: an FFT of every
        column, ~2.4 s of CPU of a 2¹⁶-node body's start-up that nothing else needs."""
        return max(spectral_tail(self._columns[kind][:, :-3]) for kind in self._tail_kinds)

    def _heading(self, terms):
        """Periodic part of the world heading of ê at the nodes (rad), and its slope per y:
        the heading α of t1 (paper eqs. (4)-(6)) plus the angle of ê from t1, as a periodic
        part plus slope·y (the cycle's turn, plus any winding)."""
        e, normal, t1, y = terms.e, terms.normal, terms.t1, terms.y
        gamma = np.unwrap(np.arctan2(_dot(e, np.cross(normal, t1)), _dot(e, t1)))
        periodic = self.cycle.heading(terms.u) + gamma - self._turn / TWO_PI * y
        winding = round((2 * periodic[-1] - periodic[-2] - periodic[0]) / TWO_PI)
        return periodic - winding * y, self._turn / TWO_PI + winding

    def _general_columns(self, terms, heading):
        """(Q_g, Q_u̇², Q_ü) on nodes of u (smooth in u for any body: no division)."""
        self._columns['general'] = np.column_stack([
            terms.q_g, terms.ratio[:, None] * terms.p + terms.ds_u[:, None] * terms.q_a,
            terms.s_u[:, None] * terms.q_a, terms.s_u, terms.ds_u, heading])

    def _table(self, kind):
        if kind == 'general' and kind not in self._columns:
            phase = ForceTerms(self.body, self.dynamics.mass.inertia, self.mass,
                               self.dynamics.gravity, self.nodes, phase_only=True)
            heading, slope = self._heading(phase)
            if slope != self._slope:
                raise RuntimeError('the heading of AB winds differently in u and in y')
            self._general_columns(phase, heading)
        if kind not in self._tables:      # quintic Hermite, spectral f′ and f″ at the nodes
            first = spectral_derivative(self._columns[kind])
            self._tables[kind] = HermiteTable.periodic(self._columns[kind], first,
                                                       spectral_derivative(first))
        return self._tables[kind]

    def coefficients(self, u, kind='kinematic'):
        """The tabulated coefficients at phase(s) u (rad), shape u.shape + (columns,).

        ``'kinematic'``: A (7 columns) then C (7) with Q = A + Ω² C / s for each of
        :data:`QUANTITIES` and γ̈ (rad/s²), then s = dγ/dy, dγ/du = |ω_u|, d²γ/du² and the
        periodic part of the heading of ê (rad), tabulated in y = ``terms.coordinate(u)``
        (u itself for EllipseBody and LaminaBody); ``'dynamic'``: the same with
        Q = A + w² C / s along a free motion of angular speed w; ``'general'``:
        (Q_g, Q_u̇², Q_ü), 6 each, then dγ/du, d²γ/du² and the heading, tabulated in u.
        """
        u = np.asarray(u, dtype=float)
        y = u if kind == 'general' else self.terms.coordinate(u)
        return self._table(kind)(np.mod(y, TWO_PI))

    # -- forces ------------------------------------------------------------------------------
    def _evaluate(self, kind, u, a, b=None, per_phase=False):
        """States in blocks: u (rad), a = u̇² (general) or Ω², w² (kinematic, dynamic), b = ü;
        ``per_phase``: a is u̇² of a free motion (w² = |ω_u|² u̇²)."""
        arrays = [np.asarray(x, dtype=float) for x in (u, a) + ((b,) if b is not None else ())]
        shape = np.broadcast_shapes(*(x.shape for x in arrays))
        u, a, *b = (np.broadcast_to(x, shape).ravel() for x in arrays)
        names = QUANTITIES + _SPLIT + ('along_b', 'phase_rate', 'phase_acceleration',
                                       'angular_speed', 'angular_acceleration')
        out = {name: np.empty(u.size) for name in names}
        for name in ('force_a', 'force_b', 'direction_ab'):
            out[name] = np.empty((u.size, 3))
        table = self._table(kind)
        for start in range(0, u.size, BLOCK):
            part = slice(start, start + BLOCK)
            y = u[part] if kind == 'general' else self.terms.coordinate(u[part])
            cycles = np.floor(y / TWO_PI)
            rest = y - TWO_PI * cycles
            f = table.combine(*table.weights(rest))
            square = a[part]
            if per_phase:
                turn = (f[:, 15] if self.terms.regular else self.terms.turn_rates(u[part])[0])
                square = square * turn * turn
            values, singular = self._values(kind, f, square, b[0][part] if b else None)
            out['phase_rate'][part] = u[part]       # (the phases, for _rates)
            self._rates(kind, f, square, b[0][part] if b else None, values, out, part)
            for j, name in enumerate(QUANTITIES):
                out[name][part] = values[:, j]
            with np.errstate(invalid='ignore'):       # ±inf at flat-vertex instants
                split = list(squeeze_split(*values[:, :5].T))
                along_b = values[:, 4] - split[0]
            if singular is not None:            # flat-vertex instants: the limits
                limit = squeeze_split(*singular[:, :5].T)
                rows = np.any(singular != 0, axis=1)
                for k in (1, 2, 3):
                    split[k] = np.where(rows, limit[k], split[k])
                split[0] = np.where(rows, _infinite(limit[0]), split[0])
                along_b = np.where(rows, _infinite(singular[:, 4] - limit[0]), along_b)
            for name, x in zip(_SPLIT, split):
                out[name][part] = x
            out['along_b'][part] = along_b
            heading = f[:, -1] + self._slope * rest + cycles * self._turn
            cos_h, sin_h = np.cos(heading), np.sin(heading)
            e = out['direction_ab'][part]
            e[:, 0], e[:, 1], e[:, 2] = cos_h, sin_h, 0.0
            along = (split[0], along_b)
            for k, (name, x, tangential) in enumerate(zip(('force_a', 'force_b'), along,
                                                          values[:, 2:4].T)):
                vector = out[name][part]
                with np.errstate(invalid='ignore'):
                    vector[:, 0] = x * cos_h - tangential * sin_h
                    vector[:, 1] = x * sin_h + tangential * cos_h
                vector[:, 2] = values[:, k]
                if singular is not None:        # the direction of the singular parts
                    x_s = limit[0] if k == 0 else singular[:, 4] - limit[0]
                    t_s = singular[:, 2 + k]
                    for j, value in ((0, x_s * cos_h - t_s * sin_h),
                                     (1, x_s * sin_h + t_s * cos_h)):
                        vector[:, j] = np.where(rows, _infinite(value), vector[:, j])
        out['phase'] = u
        return ContactForces(weight=self.weight, **{
            name: value.reshape(shape + value.shape[1:]) for name, value in out.items()})

    def _values(self, kind, f, a, b):
        """The 6 quantities and γ̈ (kinematic, dynamic) of a block; the singular parts a·C
        (None if no state of the block sits where the body does not turn)."""
        if kind == 'general':
            return f[:, :_K] + a[:, None] * f[:, _K:2 * _K] + b[:, None] * f[:, 2 * _K:3 * _K], \
                None
        s = f[:, 14]
        stopped = s <= 0.0
        with np.errstate(divide='ignore', invalid='ignore'):
            values = f[:, :7] + np.where(stopped, 0.0, a / s)[:, None] * f[:, 7:14]
        if not np.any(stopped & (a > 0)):
            return values, None
        part = np.where(np.abs(f[:, 7:14]) > self._singular_floor, f[:, 7:14], 0.0)
        singular = np.where((stopped & (a > 0))[:, None], a[:, None] * part, 0.0)
        values = np.where(singular != 0, np.copysign(np.inf, singular),
                          np.where(stopped[:, None], f[:, :7], values))
        return values, singular

    def _rates(self, kind, f, a, b, values, out, part):
        """u̇, ü, w, ẇ of a block (u̇ = inf and ü = nan where the body does not turn in u)."""
        if kind == 'general' or self.terms.regular:
            s_u, ds_u = f[:, -3], f[:, -2]
        else:                       # |ω_u| is smooth in u, not in the arc length
            s_u, ds_u = self.terms.turn_rates(out['phase_rate'][part])
        with np.errstate(divide='ignore', invalid='ignore'):
            if kind == 'general':
                u_dot = np.sqrt(a)
                w, w_dot = s_u * u_dot, s_u * b + ds_u * a
                u_ddot = b
            else:
                w, w_dot = np.sqrt(a), values[:, _K]
                u_dot = np.where(s_u > 0, w / s_u, np.inf)
                u_ddot = np.where(s_u > 0, (w_dot - ds_u * u_dot**2) / s_u, np.nan)
        out['phase_rate'][part], out['phase_acceleration'][part] = u_dot, u_ddot
        out['angular_speed'][part], out['angular_acceleration'][part] = w, w_dot

    def forces(self, u, u_dot, u_ddot):
        """Contact forces for any state (u, u̇, ü), with the drive moment that ü needs.

        Parameters
        ----------
        u, u_dot, u_ddot : array_like
            Phase (rad, any real value), its rate (rad/s) and acceleration (rad/s²),
            broadcast together (finite: where the body stops turning in u use
            :meth:`kinematic` or :meth:`dynamic` with the angular speed).

        Returns
        -------
        ContactForces
            World-frame forces (N) over the broadcast shape. ``drive_torque`` τ (N m) is the
            external pure moment τ ê the body needs for this ü: ê points from A to B and
            τ > 0 turns the body positively about ê (its power is τ ê·ω). ``phase_rate`` is
            |u̇| (no force depends on the sign of u̇).
        """
        return self._evaluate('general', u, np.square(u_dot), u_ddot)

    def dynamic(self, u, u_dot=None, *, angular_speed=None):
        """Forces along a free motion (gravity only): ẇ = −(½ J_γ w² + V_γ)/J.

        Parameters
        ----------
        u, u_dot : array_like
            Phase (rad) and its rate (rad/s, e.g. a RollingMotion's ``phase_rate``); or
        angular_speed : array_like
            instead of u̇, the angular speed w = |ω_u| u̇ (rad/s), finite where u̇ is not.

        Returns
        -------
        ContactForces
            ``drive_torque`` is the residual of the equation of motion (~1e-13 M g L).
        """
        if (u_dot is None) == (angular_speed is None):
            raise TypeError('give exactly one of u_dot and angular_speed')
        if angular_speed is None:
            forces = self._evaluate('dynamic', u, np.square(u_dot), per_phase=True)
        else:
            forces = self._evaluate('dynamic', u, np.square(angular_speed))
        if u_dot is not None:
            forces.phase_rate = np.broadcast_to(np.asarray(u_dot, dtype=float),
                                                forces.phase.shape).copy()
        return forces

    def kinematic(self, u, omega):
        """Forces when a drive holds |ω| = Ω: u̇ = Ω/|ω_u|, ẇ = 0.

        Parameters
        ----------
        u, omega : array_like
            Phase (rad) and the angular speed held Ω (rad/s), broadcast together.

        Returns
        -------
        ContactForces
            Every component is A(u) + Ω² C(u)/s(u); ``drive_torque`` τ (N m) is the drive's
            moment τ ê about AB (convention of :meth:`forces`). u̇ is reported ≥ 0:
            reversing the motion changes no force.
        """
        return self._evaluate('kinematic', u, np.square(omega))

    def along(self, motion):
        """Forces at the samples of a :class:`~twodisk_ros.dynamics.RollingMotion`."""
        if motion.sol.regular_chart:                # SundmanSolution: (u, w) directly
            speed = motion.sol.state(motion.t)[1]
        else:
            s_u = self.terms.turn_rates(motion.phase)[0]
            with np.errstate(invalid='ignore'):
                speed = s_u * motion.phase_rate
            if not np.all(np.isfinite(speed)):      # u̇ = ∞ where the body does not turn
                j = self.dynamics.tabulated_inertia(motion.phase)
                energy = motion.energy[np.isfinite(motion.energy)][0]
                free = np.sqrt(np.maximum(2 * (energy - self.dynamics.tabulated_potential(
                    motion.phase)), 0.0) / j)
                speed = np.where(np.isfinite(speed), speed, free if motion.mode == 'dynamic'
                                 else speed[np.isfinite(speed)][0])
        if motion.mode == 'dynamic':
            forces = self.dynamic(motion.phase, angular_speed=speed)
        else:
            forces = self.kinematic(motion.phase, np.abs(speed).max())
        forces.phase_rate = np.asarray(motion.phase_rate, dtype=float).copy()
        return forces


def _infinite(x):
    """±inf with the sign of x, 0 where x = 0 (the limit of x/s as s → 0⁺)."""
    return np.where(x == 0, 0.0, np.copysign(np.inf, x))

"""The whole rolling cycle: poses, contact traces and the cycle displacement in the world.

World frame (paper, section 3): origin at A when θ = 0 on branch +1 (phase u = 0), X tangent
to disk 1 there (direction of increasing θ), Z up. At phase u the body's contact frame
``(t1, n × t1, n)`` maps to ``(c_α, e_z × c_α, e_z)`` with c_α = (cos α, sin α, 0), so
``R = c_α t1ᵀ + (e_z × c_α)(n × t1)ᵀ + e_z nᵀ`` (body → world), A = (X_A, Y_A, 0),
G = A − R r1 and B = G + R r2. As a quaternion, q = q_z(α) ⊗ q_c(u), continuous in u
(:mod:`~twodisk_ros.physics.bodies.orientation`).

The heading α and the trace of A solve the paper's eqs. (4)-(6), written in u by the chain
rule. Their rates are smooth and 2π-periodic in u, so one cycle is integrated spectrally
(FFT, exact to rounding once resolved) and tabulated for quintic Hermite interpolation;
any number of cycles follows by composing the one-cycle planar displacement in closed form
(no accumulation, no drift); docs/physics.md#rolling-kinematics-and-the-contact-traces.
"""

from dataclasses import dataclass
import math

import numpy as np

from ..numerics.analytic import COMPLEX_STEP, complex_step_jet, sinc
from .orientation import contact_quaternion_samples
from .protocol import check_rolling_body
from ..numerics.spectral import (TAIL_TOLERANCE, node_sum, refine_grid, spectral_antiderivative,
                       spectral_derivative, spectral_tail, spectral_tails)
from ..numerics.tables import HermiteTable

__all__ = ['RollingCycle', 'RollingState', 'RollingPoses', 'CycleDisplacement',
           'integrate_contact_trace', 'required_resolutions', 'displacement_from_rates']

TWO_PI = 2.0 * math.pi


def _arc_rate_and_turn(body, u):
    """(ds/du, dα/du) and their u-derivatives (complex step) at real u."""
    (ds, dds), (dalpha, ddalpha) = complex_step_jet(
        body.phase_rates(np.asarray(u, dtype=float) + 1j * COMPLEX_STEP))
    return ds, dalpha, dds, ddalpha


def _turned(angle, factor, jet):
    """(g, g′, g″) of g = e^{i c α} f from the jets (α, α′, α″) and (f, f′, f″), c = factor."""
    (alpha, d_alpha, dd_alpha), (f, df, ddf) = angle, jet
    rate = 1j * factor * d_alpha
    turn = np.exp(1j * factor * alpha)
    return (turn * f, turn * (df + rate * f),
            turn * (ddf + 2.0 * rate * df + (1j * factor * dd_alpha + rate * rate) * f))


def _exp_integral(mu, u):
    """∫₀ᵘ e^{iμv} dv, robust as μ → 0."""
    x = 0.5 * mu * u
    return u * np.exp(1j * x) * sinc(x)


@dataclass(frozen=True)
class CycleDisplacement:
    """The planar rigid displacement of one full cycle (u → u + 2π), in the world frame.

    A world point p = (x, y) maps to ``rotate(turn)·p + (x_shift, y_shift)``.
    """

    turn: float      #: rotation angle (rad), the heading change of one cycle
    shift: complex   #: translation, x + i y (m)

    def power(self, cycles):
        """Closed-form ``(turn, shift)`` of ``cycles`` (integer array) cycles composed."""
        k = np.asarray(cycles, dtype=float)
        phi = math.remainder(self.turn, TWO_PI)
        half = 0.5 * phi
        # Σ_{j<k} e^{ijφ} = e^{i(k-1)φ/2} sin(kφ/2)/sin(φ/2), written with sinc: exact at φ = 0
        ratio = k * sinc(k * half) / sinc(half)
        geometric = np.exp(1j * (k - 1) * half) * ratio
        return k * self.turn, self.shift * geometric


@dataclass(frozen=True)
class RollingState:
    """State of the body at cycle phases u (arrays broadcast over u's shape).

    Positions are in the world frame (m); ``rotation`` maps body → world, shape (..., 3, 3),
    from the closed forms; ``quaternion`` is the same orientation from the cycle's tables
    (within ~1e-15), as a continuous function of u (see :meth:`RollingCycle.poses`).
    """

    phase: np.ndarray          #: u (rad)
    theta: np.ndarray          #: θ (rad)
    psi: np.ndarray            #: ψ (rad)
    branch: np.ndarray         #: sign(cos u): +1 paper's branch, −1 its mirror
    tilt: np.ndarray           #: φ (rad), angle between disk 1 and the ground
    heading: np.ndarray        #: α (rad), direction of the trace of A
    position_g: np.ndarray     #: G (m), shape (..., 3)
    contact_a: np.ndarray      #: A (m), shape (..., 3), z = 0
    contact_b: np.ndarray      #: B (m), shape (..., 3), z = 0
    rotation: np.ndarray       #: R body → world, shape (..., 3, 3)
    quaternion: np.ndarray     #: R as (x, y, z, w), body → world, continuous in u, (..., 4)


@dataclass(frozen=True)
class RollingPoses:
    """Poses at cycle phases u from the tables alone (:meth:`RollingCycle.poses`).

    Arrays have u's shape plus the trailing axis shown; world frame, Z up, metres.
    """

    position_g: np.ndarray     #: G (m), (..., 3)
    contact_a: np.ndarray      #: A (m), (..., 3), z = 0
    contact_b: np.ndarray      #: B (m), (..., 3), z = 0
    quaternion: np.ndarray     #: body → world as (x, y, z, w), unit, continuous in u, (..., 4)
    heading: np.ndarray        #: α (rad), continuous, α(0) = 0


def _cycle_tails(body, n):
    """The spectral tail of dα/du and of the trace's rate on n nodes (the resolution test)."""
    u = TWO_PI * np.arange(n) / n
    ds, dalpha = body.phase_rates(u)
    _, alpha_p = spectral_antiderivative(dalpha)
    return max(spectral_tail(dalpha), spectral_tail(ds * np.exp(1j * alpha_p)))


def required_resolutions(bodies, points=2**16):
    """:meth:`RollingCycle.required_resolution` of every body of a batch, at once.

    The same test as the scalar construction (doubling from 512 nodes until the spectral
    tails of dα/du and of the trace's rate are below ``TAIL_TOLERANCE``, at most
    :attr:`RollingCycle.MAX_RESOLUTION`), on arrays of bodies.

    Parameters
    ----------
    bodies : EllipseBodies
    points : int
        Nodes × bodies evaluated at once (bounds the memory: ~100 B per point).

    Returns
    -------
    ndarray of int, shape (B,)
    """
    resolution = np.zeros(len(bodies), dtype=int)
    active = np.arange(len(bodies))
    n = 512
    while active.size:
        u = (TWO_PI * np.arange(n) / n)[:, None]
        done = np.zeros(active.size, dtype=bool)
        step = max(1, points // n)
        for start in range(0, active.size, step):
            part = slice(start, start + step)
            ds, dalpha = bodies.subset(active[part]).phase_rates(u)
            _, alpha_p = spectral_antiderivative(dalpha)
            tails = np.maximum(spectral_tails(dalpha), spectral_tails(ds * np.exp(1j * alpha_p)))
            done[part] = (tails < TAIL_TOLERANCE) | (n >= RollingCycle.MAX_RESOLUTION)
        resolution[active[done]] = n
        active = active[~done]
        n *= 2
    return resolution


def displacement_from_rates(arc_rate, turn_rate):
    """The displacement of one cycle from ds/du and dα/du at the nodes u_j = 2πj/N.

    The spectral integration of :class:`RollingCycle` (Z_A(2π) = ∫₀^{2π} ds/du e^{iα} du,
    exact to rounding once the rates are resolved), for one body or for a batch.

    Parameters
    ----------
    arc_rate, turn_rate : ndarray, shape (N, ...)
        ds/du (m/rad) and dα/du (rad/rad) of the trace of A; axis 0 is u, any further axes
        are bodies.

    Returns
    -------
    turn : ndarray, shape (...)
        Heading change of one cycle (rad).
    shift : ndarray of complex, shape (...)
        Translation of one cycle, x + i y (m).
    """
    n = arc_rate.shape[0]
    slope, alpha_p = spectral_antiderivative(turn_rate)
    h_hat = np.fft.fft(arc_rate * np.exp(1j * alpha_p), axis=0) / n
    k = np.fft.fftfreq(n, d=1.0 / n).reshape((n,) + (1,) * (arc_rate.ndim - 1))
    mu = k + slope
    k0 = np.argmin(np.abs(mu), axis=0)
    mu0 = np.take_along_axis(mu, k0[None], axis=0)[0]
    h0 = np.take_along_axis(h_hat, k0[None], axis=0)[0]
    first = np.arange(n).reshape(k.shape) == k0
    coef = np.where(first, 0.0, h_hat / (1j * np.where(mu == 0, 1.0, mu)))
    shift = (np.exp(1j * slope * TWO_PI) - 1.0) * node_sum(coef) + h0 * _exp_integral(mu0,
                                                                                        TWO_PI)
    return slope * TWO_PI, shift


class RollingCycle:
    """Tabulated kinematics of one rolling cycle of a body, and its composition.

    Parameters
    ----------
    body : RollingBody
        EllipseBody or LaminaBody (bodies/protocol.py).
    resolution : int, optional
        Grid size of the spectral integration (power of two). By default it is doubled from
        512 until the upper half of the spectra of dα/du and of the trace's rate is below
        ``1e-13`` of their peak (at most 2¹⁷ nodes).
    oversampling : int
        The Hermite tables use ``oversampling × resolution`` nodes.

    Attributes
    ----------
    displacement : CycleDisplacement
        The planar rigid displacement of one cycle.
    resolution : int
        Nodes used for the spectral integration.
    spectral_tail : float
        Relative size of the unresolved spectrum (an error indicator; ~1e-16 when resolved).

    Notes
    -----
    Evaluation, fastest first, all vectorised over any array of phases u (rad, any real):
    :meth:`positions` (G, A, B), :meth:`poses` (also the heading and the continuous
    orientation quaternion), both from one table lookup per sample; :meth:`state` adds θ, ψ,
    φ and the rotation matrix from the closed forms (a few times slower).
    """

    MAX_RESOLUTION = 2**17
    #: Samples evaluated at once by positions and poses (the gathered coefficients, 576 B per
    #: sample, stay in cache: 2.4 MB; 4096 measured fastest among 2048 … 8192 on the 2-core
    #: benchmark machine once the work arrays are reused, 8192 before).
    BLOCK = 4096

    def __init__(self, body, resolution=None, oversampling=4):
        self.body = check_rolling_body(body)
        if resolution is None:
            resolution, tail = self._refine(body)
        else:
            tail = self._tails(resolution)
        self.resolution = int(resolution)
        self.spectral_tail = tail
        #: :meth:`_cycle_terms` of single cycles k ((k, sign of k) → its scalars), filled on use
        self._one_cycle_terms = {}
        self._build(self.resolution * int(oversampling))

    @classmethod
    def required_resolution(cls, body):
        """The grid size (nodes) the default construction picks for ``body``.

        Only the spectral test, without the tables: ~1 % of the build's cost (0.04 s for
        b/a = 0.01, Δ/a = 1e-3, which needs 65 536 nodes). The cost of everything built on
        the tables grows in proportion (see :mod:`~twodisk_ros.physics.motion.startup`).
        """
        return cls._refine(body)[0]

    @classmethod
    def _refine(cls, body):
        return refine_grid(lambda n: (_cycle_tails(body, n),) * 2, 512, cls.MAX_RESOLUTION)

    def _tails(self, n):
        return _cycle_tails(self.body, n)

    def _build(self, n):
        u = TWO_PI * np.arange(n) / n
        ds, dalpha, dds, ddalpha = _arc_rate_and_turn(self.body, u)
        slope, alpha_p = spectral_antiderivative(dalpha)
        # Z_A(u) = ∫₀ᵘ h(v) e^{iλv} dv with h = ds/du · e^{iα_p} periodic
        lam = slope
        h_hat = np.fft.fft(ds * np.exp(1j * alpha_p)) / n
        k = np.fft.fftfreq(n, d=1.0 / n)
        mu = k + lam
        k0 = int(np.argmin(np.abs(mu)))
        coef = np.where(np.arange(n) == k0, 0.0, h_hat / (1j * np.where(mu == 0, 1.0, mu)))
        z_nodes = np.exp(1j * lam * u) * (n * np.fft.ifft(coef)) - coef.sum()
        z_nodes = z_nodes + h_hat[k0] * _exp_integral(mu[k0], u)
        z_end = (np.exp(1j * lam * TWO_PI) - 1.0) * coef.sum() + h_hat[k0] * _exp_integral(
            mu[k0], TWO_PI)
        # close the tables at u = 2π
        alpha_all = np.append(slope * u + alpha_p, slope * TWO_PI)
        z_all = np.append(z_nodes, z_end)
        ds_all, dalpha_all = np.append(ds, ds[0]), np.append(dalpha, dalpha[0])
        dds_all, ddalpha_all = np.append(dds, dds[0]), np.append(ddalpha, ddalpha[0])
        r1, r2, normal, t1 = self.body.phase_vectors(u + 1j * COMPLEX_STEP)[:4]
        frame = self._frame_samples(r1, r2, normal, t1)
        # q_c(u) of the contact frame (x, y, w, z), continued to u = 2π by ε q_c(0)
        q, q_first, q_second, self._cycle_sign = contact_quaternion_samples(t1, normal)
        quaternion = [np.concatenate([x[:, [0, 1, 3, 2]], self._cycle_sign * x[:1, [0, 1, 3, 2]]])
                      for x in (q, q_first, q_second)]
        trace = (z_all, ds_all * np.exp(1j * alpha_all),
                 (dds_all + 1j * ds_all * dalpha_all) * np.exp(1j * alpha_all))
        angle = (alpha_all, dalpha_all, ddalpha_all)
        # the world within the cycle, whose rotation e^{iα} is applied here, once per node:
        # G = A − e^{iα} r1 and B = G + e^{iα} r2 (r1, r2 in the contact frame, as x + iy),
        # q = q_z(α) ⊗ q_c, with (x + iy) turned by e^{iα/2} and (z + iw) by e^{−iα/2}
        arm_a = _turned(angle, 1.0, tuple(x[:, 0] + 1j * x[:, 1] for x in frame))
        arm_b = _turned(angle, 1.0, tuple(x[:, 2] + 1j * x[:, 3] for x in frame))
        q_xy = _turned(angle, 0.5, tuple(x[:, 0] + 1j * x[:, 1] for x in quaternion))
        q_zw = _turned(angle, -0.5, tuple(x[:, 3] + 1j * x[:, 2] for x in quaternion))
        # one table (one gather per sample): columns X_A, Y_A, X_G, Y_G, X_B, Y_B (read as
        # complex Z_A, Z_G, Z_B), z_G = −r1·n, q_x, q_y, q_z, q_w (read as q_x + i q_y and
        # q_z + i q_w) and α
        columns = []
        for k in range(3):
            z_g = trace[k] - arm_a[k]
            positions = np.column_stack([trace[k], z_g, z_g + arm_b[k]]).view(float)
            attitude = np.column_stack([q_xy[k], q_zw[k]]).view(float)
            columns.append(np.column_stack([positions, -frame[k][:, 4], attitude, angle[k]]))
        self._table = HermiteTable(0.0, TWO_PI / n, *columns)
        self.nodes = np.append(u, TWO_PI)
        self.displacement = CycleDisplacement(turn=slope * TWO_PI, shift=complex(z_end))

    @staticmethod
    def _frame_samples(r1, r2, normal, t1):
        """r1·t1, r1·m, r2·t1, r2·m, r1·n at the nodes (from u + ih), closed at u = 2π."""
        m = np.cross(normal, t1)
        components = np.stack([np.sum(r1 * t1, -1), np.sum(r1 * m, -1), np.sum(r2 * t1, -1),
                               np.sum(r2 * m, -1), np.sum(r1 * normal, -1)], axis=-1)
        values, first = complex_step_jet(components)
        second = spectral_derivative(first)
        return tuple(np.concatenate([x, x[:1]]) for x in (values, first, second))

    @property
    def cycle_sign(self):
        """ε = ±1 with q_c(u + 2π) = ε q_c(u) (contact-frame quaternion, see :meth:`poses`).

        The world quaternion then obeys q(u + 2π) = −ε R_z(T − 2π)·q(u), T the turn of one
        cycle (T = 2π up to ~1e-11 for every shape: the heading turns once per cycle).
        """
        return self._cycle_sign

    def _split(self, u):
        u = np.asarray(u, dtype=float)
        cycles = np.floor(u / TWO_PI)
        return cycles, u - TWO_PI * cycles

    def _cycle_terms(self, cycles):
        """Per sample: e^{i k T}, the shift of k cycles, ε^k e^{i k T/2} and k T (k = cycles)."""
        if cycles.size == 0:
            empty = np.empty(cycles.shape, complex)
            return empty, empty, empty, cycles
        low, high = float(cycles.min()), float(cycles.max())
        if low == high:              # one cycle (most blocks): scalars, kept per cycle
            key = (low, math.copysign(1.0, low))     # −0.0 (u = −0.0) apart from 0.0
            terms = self._one_cycle_terms.get(key)
            if terms is None:
                if len(self._one_cycle_terms) >= 4096:
                    self._one_cycle_terms.clear()
                terms = tuple(x[0] for x in self._cycle_terms_of(np.array([low])))
                self._one_cycle_terms[key] = terms
            return terms
        if high - low <= 4096:       # few distinct cycles: evaluate once each, then gather
            index = (cycles - low).astype(np.intp)
            return tuple(x[index] for x in self._cycle_terms_of(np.arange(low, high + 1.0)))
        return self._cycle_terms_of(cycles)

    def _cycle_terms_of(self, cycles):
        turn, shift = self.displacement.power(cycles)
        parity = np.where(np.mod(cycles, 2.0) == 0.0, 1.0, self._cycle_sign)
        return np.exp(1j * turn), shift, parity * np.exp(0.5j * turn), turn

    # -- world positions ---------------------------------------------------------------------
    def _blocks(self, u, evaluate, trailing):
        """evaluate(flat block, outputs) fills arrays (block, *trailing[j]), blocks of BLOCK
        samples written in place into the results."""
        u = np.asarray(u, dtype=float)
        flat = u.reshape(-1)
        parts = [np.empty((flat.size,) + shape) for shape in trailing]
        size = min(flat.size, self.BLOCK)
        # work arrays shared by the blocks: the table's, then the cycles, rest and norms
        work = (self._table.scratch(size),) + tuple(np.empty(size) for _ in range(3))
        for start in range(0, flat.size, self.BLOCK):
            part = slice(start, start + self.BLOCK)
            evaluate(flat[part], [array[part] for array in parts], work)
        return tuple(x.reshape(u.shape + shape) for x, shape in zip(parts, trailing))

    def positions(self, u):
        """World positions of G, A and B at phase(s) u (m): the fast path, from tables only.

        Returns three arrays of shape u.shape + (3,). Agrees with the closed forms to the
        table's interpolation error (~1e-15 of the body size when resolved). Large inputs are
        processed in blocks of :attr:`BLOCK` samples (cache-friendly).
        """
        return self._blocks(u, self._positions, [(3,)] * 3)

    def poses(self, u):
        """Full poses at phase(s) u (rad, any real value), from the tables only: the fast path.

        Parameters
        ----------
        u : array_like
            Cycle phases (rad); negative values and many cycles ahead are fine.

        Returns
        -------
        RollingPoses
            G, A, B (world, m), the heading α (rad) and the orientation body → world as a unit
            quaternion (x, y, z, w). Positions equal :meth:`positions`; the quaternion agrees
            with the closed-form rotation of :meth:`state` to ~1e-15.

        Notes
        -----
        The quaternion q(u) = q_z(α(u)) ⊗ q_c(u) is a continuous function of u with
        w > 0 at u = 0 (:mod:`~twodisk_ros.physics.bodies.orientation`). Each sample's sign depends
        on its phase only, never on the other samples of the call, so arrays computed in
        blocks (as the node does), from any starting phase or in any order join continuously.
        Consecutive samples satisfy q_k · q_{k+1} ≥ 0 whenever the body turns by less than π
        (half a turn) between them, e.g. max |ω_u| · |Δu| < π. For coarser steps the product
        may be negative: it is then the sign of the continuous lift along the path (after
        whole cycles q(u + 2πk) = (−ε)^k q(u) up to the cycle's ~1e-11 rad excess turn about
        Z, ε = :attr:`cycle_sign`); flip signs yourself if you need the shortest arcs.
        """
        parts = self._blocks(u, self._poses, [(3,), (3,), (3,), (4,), ()])
        return RollingPoses(*parts)

    def _evaluate(self, u, work):
        """The table's rows at phases u (1-d) and the cycles' terms of :meth:`_cycle_terms`,
        in the work arrays of :meth:`_blocks` (the operations of :meth:`_split`)."""
        cycles, rest = work[1][:u.size], work[2][:u.size]
        np.divide(u, TWO_PI, out=cycles)
        np.floor(cycles, out=cycles)
        np.multiply(cycles, TWO_PI, out=rest)
        np.subtract(u, rest, out=rest)
        return (self._table.expand_into(rest, work[0]),) + self._cycle_terms(cycles)

    @staticmethod
    def _world(f, spin, shift, g, a, b):
        """G, A, B (into g, a, b) from the table's rows f and the cycles' map spin·p + shift."""
        pairs = f[:, :6].view(np.complex128)      # Z_A, Z_G, Z_B within the cycle
        for point, column in ((a, 0), (g, 1), (b, 2)):
            xy = point[:, :2].view(np.complex128)[:, 0]
            np.multiply(pairs[:, column], spin, out=xy)
            xy += shift
            point[:, 2] = 0.0
        g[:, 2] = f[:, 6]

    def _positions(self, u, out, work):
        f, spin, shift, _, _ = self._evaluate(u, work)
        self._world(f, spin, shift, *out)

    def _poses(self, u, out, work):
        f, spin, shift, half, turn = self._evaluate(u, work)
        self._world(f, spin, shift, *out[:3])
        # q_z(kT) ⊗ q(u − 2πk) (±, the cycle sign): (x + iy) turns by e^{ikT/2}, (z + iw)
        # by e^{−ikT/2}; then renormalised
        within, q, scale = f[:, 7:11], out[3], work[3][:u.size]
        np.einsum('ij,ij->i', within, within, out=scale)
        np.sqrt(scale, out=scale)
        np.divide(1.0, scale, out=scale)
        pairs, turned = within.view(np.complex128), q.view(np.complex128)
        np.multiply(pairs[:, 0], half, out=turned[:, 0])
        np.multiply(pairs[:, 1], np.conj(half), out=turned[:, 1])
        q *= scale[:, None]
        np.add(f[:, 11], turn, out=out[4])

    def heading(self, u):
        """α(u) (rad): heading of disk 1's tangent t1 at A in the world, α(0) = 0.

        On branch +1 this is the direction in which A moves on the ground; on branch −1 A
        moves the opposite way.
        """
        cycles, rest = self._split(u)
        return self._table(rest)[..., 11] + cycles * self.displacement.turn

    def trace_a(self, u):
        """World position of A at phase(s) u (m), shape u.shape + (3,)."""
        return self.positions(u)[1]

    def trace_b(self, u):
        """World position of B at phase(s) u (m), shape u.shape + (3,)."""
        return self.positions(u)[2]

    # -- poses -------------------------------------------------------------------------------
    def state(self, u):
        """The body's state at phase(s) u (rad, any real value, also many cycles ahead).

        Angles and ``rotation`` from the closed forms; positions, heading and the continuous
        ``quaternion`` as in :meth:`poses`.
        """
        u = np.asarray(u, dtype=float)
        geo = self.body.phase_geometry(u)
        poses = self.poses(u)
        rotation = self._rotation(poses.heading, geo.tangent_a, geo.ground_normal)
        return RollingState(phase=u, theta=geo.theta, psi=geo.psi, branch=geo.branch,
                            tilt=geo.tilt, heading=poses.heading, position_g=poses.position_g,
                            contact_a=poses.contact_a, contact_b=poses.contact_b,
                            rotation=rotation, quaternion=poses.quaternion)

    @staticmethod
    def _rotation(alpha, t1, n):
        c = np.stack([np.cos(alpha), np.sin(alpha), np.zeros_like(alpha)], axis=-1)
        c_perp = np.stack([-np.sin(alpha), np.cos(alpha), np.zeros_like(alpha)], axis=-1)
        ez = np.zeros_like(c)
        ez[..., 2] = 1.0
        m = np.cross(n, t1)
        return (c[..., :, None] * t1[..., None, :] + c_perp[..., :, None] * m[..., None, :]
                + ez[..., :, None] * n[..., None, :])

    def velocity_g(self, u):
        """dG/du (m per unit u, world frame): −R (ω_u × r1), from no slip at A."""
        u = np.asarray(u, dtype=float)
        geo = self.body.phase_geometry(u)
        rotation = self._rotation(self.heading(u), geo.tangent_a, geo.ground_normal)
        body_vel = -np.cross(self.body.phase_angular_velocity(u), geo.contact_a)
        return np.einsum('...ij,...j->...i', rotation, body_vel)


def integrate_contact_trace(body, u_end, rtol=1e-13, atol=None, u_eval=None):
    """Direct integration of the paper's eqs. (4)-(6) in u with DOP853 (a second method).

    ``atol`` defaults to 1e-16 × body size (m); at rtol 1e-12 with an absolute 1e-14 DOP853's
    own error reaches 2e-8 of the size for some shapes, hence the tighter defaults.
    Returns scipy's OdeResult with ``y = (α, X_A, Y_A)`` and dense output ``sol``.
    """
    from scipy.integrate import solve_ivp
    if atol is None:
        atol = 1e-16 * body.size
    def rates(u, y):
        ds, dalpha = body.phase_rates(u)
        return [dalpha, ds * math.cos(y[0]), ds * math.sin(y[0])]
    result = solve_ivp(rates, (0.0, float(u_end)), [0.0, 0.0, 0.0], method='DOP853', rtol=rtol,
                       atol=atol, t_eval=u_eval, dense_output=True)
    if not result.success:
        raise RuntimeError(f'contact trace integration failed: {result.message}')
    return result

"""An independent high-accuracy reference for the rolling two-disk body.

Nothing here calls ``twodisk_ros``: the geometry, the effective mass, the potential, the
heading and the trace of A are re-derived from scratch and differentiated by truncated
Taylor arithmetic (exact derivatives to rounding), so the reference shares no code with the
methods under test.

Geometry (body frame, G at the origin; disk 1 in x3 = 0 centred at (0, -Δ, 0), disk 2 in
x1 = 0 centred at (0, +Δ, 0)). With the eccentric anomaly η of A on disk 1,

    r1 = GA = (b sin η, -Δ - a cos η, 0),      T1 = dr1/dη = (b cos η, a sin η, 0).

The ground plane contains T1, the segment AB and the tangent of disk 2 at B. Writing
B = (0, Δ + a cos τ, b sin τ) and solving n·T1 = n·T2 = n·(B - A) = 0 gives
cos τ = -a cos η / D with D = a + 2Δ cos η, and, unnormalised and pointing up (into the
body),

    n ∝ (-a sin η, b cos η, σW),     r2 = GB = (0, Δ - a² cos η / D, -σ b W / D),

W² = D² - a² cos² η = (a + (2Δ - a) cos η)(a + 2Δ)(cos η - cos η_max), cos η_max = -a/(a+2Δ).
The phase s is regular through the turning points: η = η_max sin s, σ = sign(cos s), and
cos η - cos η_max = 2 cos² s · S(1 + sin s) S(1 - sin s) with S(x) = sin(η_max x / 2) / x, so
σW = cos s · √(...) is analytic in s.

Rolling without slip at A and B: ω ∥ AB, and n is fixed in the world so n' = -ω × n in the
body frame; hence ω_s = λ (r2 - r1) with λ = -n'·(d × n) / |d × n|², d = r2 - r1 (per unit
ṡ). Kinetic energy ½ m(s) ṡ², m = ω_sᵀ I ω_s + M |ω_s × r1|²; V = M g (-r1·n). The heading α
of the trace of A obeys α' = t1'·(n × t1) (because ω·n = 0), and the trace
Z_A' = e^{iα} (t1·r1' + i (n × t1)·r1') with Z_A(0) = 0, α(0) = 0. World poses:
R = c_α t1ᵀ + c_α⊥ (n × t1)ᵀ + e_z nᵀ, G = A - R r1, B = G + R r2.
"""

import math

import numpy as np
from scipy.integrate import solve_ivp

__all__ = ['ReferenceBody', 'ReferenceSolution', 'reference_solution', 'Jet']


# ------------------------------------------------------------------ truncated Taylor series
def _lib(x):
    return np if isinstance(x, np.ndarray) else math


class Jet:
    """Truncated Taylor series c0 + c1 h + ... + cK h^K (coefficients: floats or arrays)."""

    __slots__ = ('c',)

    def __init__(self, coefficients):
        self.c = list(coefficients)

    @property
    def order(self):
        return len(self.c) - 1

    @staticmethod
    def variable(x0, order):
        return Jet([x0] + [1.0] * min(order, 1) + [0.0] * (order - 1))

    def derivative(self, k=0):
        """The k-th derivative d^k f / ds^k at the point."""
        return math.factorial(k) * self.c[k]

    def shifted(self):
        """The series of f' (one order less)."""
        return Jet([(k + 1) * self.c[k + 1] for k in range(self.order)])

    def truncated(self, order):
        return Jet(self.c[:order + 1])

    def _coerce(self, other):
        if isinstance(other, Jet):
            return other
        return Jet([other] + [0.0] * self.order)

    def __add__(self, other):
        other = self._coerce(other)
        n = min(self.order, other.order) + 1
        return Jet([self.c[k] + other.c[k] for k in range(n)])

    __radd__ = __add__

    def __neg__(self):
        return Jet([-x for x in self.c])

    def __sub__(self, other):
        return self + (-self._coerce(other))

    def __rsub__(self, other):
        return self._coerce(other) + (-self)

    def __mul__(self, other):
        if not isinstance(other, Jet):
            return Jet([x * other for x in self.c])
        n = min(self.order, other.order) + 1
        a, b = self.c, other.c
        return Jet([sum(a[i] * b[k - i] for i in range(k + 1)) for k in range(n)])

    __rmul__ = __mul__

    def __truediv__(self, other):
        if not isinstance(other, Jet):
            return Jet([x / other for x in self.c])
        n = min(self.order, other.order) + 1
        a, b = self.c, other.c
        q = []
        for k in range(n):
            q.append((a[k] - sum(b[i] * q[k - i] for i in range(1, k + 1))) / b[0])
        return Jet(q)

    def __rtruediv__(self, other):
        return self._coerce(other) / self


def jsqrt(x):
    r0 = _lib(x.c[0]).sqrt(x.c[0])
    r = [r0]
    for k in range(1, x.order + 1):
        r.append((x.c[k] - sum(r[i] * r[k - i] for i in range(1, k))) / (2 * r0))
    return Jet(r)


def jsincos(x):
    lib = _lib(x.c[0])
    s, c = [lib.sin(x.c[0])], [lib.cos(x.c[0])]
    for k in range(1, x.order + 1):
        s.append(sum(i * x.c[i] * c[k - i] for i in range(1, k + 1)) / k)
        c.append(-sum(i * x.c[i] * s[k - i] for i in range(1, k + 1)) / k)
    return Jet(s), Jet(c)


_SINC_SERIES = [(-1) ** k / math.factorial(2 * k + 1) for k in range(10)]


def jsinc(x):
    """sin(x)/x, also at x = 0 (series for |x| < 0.5, error < 1e-22 there)."""
    x0 = x.c[0]
    x2 = x * x

    def series():
        acc = Jet([_SINC_SERIES[-1]] + [0.0] * x.order)
        for coef in reversed(_SINC_SERIES[:-1]):
            acc = acc * x2 + coef
        return acc

    if isinstance(x0, np.ndarray):
        small = np.abs(x0) < 0.5
        safe = Jet([np.where(small, 1.0, x0)] + x.c[1:])
        direct = jsincos(safe)[0] / safe
        ser = series()
        return Jet([np.where(small, ser.c[k], direct.c[k]) for k in range(x.order + 1)])
    if abs(x0) < 0.5:
        return series()
    return jsincos(x)[0] / x


def vdot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def vcross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def vsub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def vscale(s, a):
    return tuple(s * x for x in a)


def _zero_like(j):
    return Jet([0.0 * x for x in j.c])


# ------------------------------------------------------------------ the body
class ReferenceBody:
    """Closed forms of the two-disk body in the phase s, with exact derivatives.

    Parameters
    ----------
    a, b, delta : float
        The disks' semi-axes and half the distance between their centres (m).
    mass : float
        Total mass (kg); two uniform elliptic laminae of mass / 2 each.
    gravity : float
        g (m/s²).
    """

    def __init__(self, a, b, delta, mass=1.0, gravity=9.81):
        self.a, self.b, self.delta = float(a), float(b), float(delta)
        self.mass, self.gravity = float(mass), float(gravity)
        self.eta_max = math.acos(-a / (a + 2 * delta))
        # laminae: each disk is a uniform elliptic plate, mass M/2, its own centre at ∓Δ e2.
        # Disk 1 (plane x3 = 0, semi-axes b along e1, a along e2), about its centre:
        # I11 = m a²/4, I22 = m b²/4, I33 = m (a² + b²)/4; disk 2 (plane x1 = 0, a along e2,
        # b along e3): I11 = m (a² + b²)/4, I22 = m b²/4, I33 = m a²/4. Parallel axes along
        # e2 by Δ add m Δ² to I11 and I33 of each.
        half = 0.5 * self.mass
        d2 = self.delta ** 2
        i1 = np.diag([a * a / 4, b * b / 4, (a * a + b * b) / 4])
        i2 = np.diag([(a * a + b * b) / 4, b * b / 4, a * a / 4])
        shift = np.diag([d2, 0.0, d2])
        self.inertia = half * (i1 + shift) + half * (i2 + shift)

    @property
    def size(self):
        """Largest distance of a disk point from G (m)."""
        a, b, d = self.a, self.b, self.delta
        # disk 1: |(b sin η, -Δ - a cos η)|² = b² sin² η + (Δ + a cos η)², maximise over η
        eta = np.linspace(0.0, math.pi, 200001)
        return float(np.sqrt(np.max(b * b * np.sin(eta) ** 2 + (d + a * np.cos(eta)) ** 2)))

    # -- the geometry as Taylor series in s ----------------------------------------------
    def frame(self, s, order):
        """(r1, r2, n, t1) as 3-tuples of Jets of the given order at phase s."""
        a, b, dl, em = self.a, self.b, self.delta, self.eta_max
        sv = Jet.variable(s, order)
        sin_s, cos_s = jsincos(sv)
        eta = em * sin_s
        sin_e, cos_e = jsincos(eta)
        big_d = a + 2 * dl * cos_e
        half_em = 0.5 * em
        s_plus = half_em * jsinc(half_em * (1.0 + sin_s))
        s_minus = half_em * jsinc(half_em * (1.0 - sin_s))
        gap_over_c2 = 2.0 * s_plus * s_minus            # (cos η - cos η_max) / cos² s
        w_over_c = jsqrt((a + (2 * dl - a) * cos_e) * (a + 2 * dl) * gap_over_c2)
        sigma_w = cos_s * w_over_c                      # σ W, analytic in s
        zero = _zero_like(sv)
        r1 = (b * sin_e, -dl - a * cos_e, zero)
        r2 = (zero, dl - a * a * cos_e / big_d, -b * sigma_w / big_d)
        n_raw = (-a * sin_e, b * cos_e, sigma_w)
        n_norm = jsqrt(vdot(n_raw, n_raw))
        n = tuple(x / n_norm for x in n_raw)
        t_raw = (b * cos_e, a * sin_e, zero)
        t_norm = jsqrt(vdot(t_raw, t_raw))
        t1 = tuple(x / t_norm for x in t_raw)
        return r1, r2, n, t1

    def mechanics(self, s, order=1):
        """(m, V) as Jets of the given order (≤ 1 needs frame order + 1) at phase s."""
        r1, r2, n, _ = self.frame(s, order + 1)
        n_rate = tuple(x.shifted() for x in n)                  # n' (order `order`)
        r1o = tuple(x.truncated(order) for x in r1)
        r2o = tuple(x.truncated(order) for x in r2)
        no = tuple(x.truncated(order) for x in n)
        d = vsub(r2o, r1o)
        dxn = vcross(d, no)
        lam = -vdot(n_rate, dxn) / vdot(dxn, dxn)
        omega = vscale(lam, d)
        inertia = self.inertia
        i_omega = tuple(sum(inertia[i, j] * omega[j] for j in range(3) if inertia[i, j] != 0)
                        for i in range(3))
        v = vcross(omega, r1o)
        m = vdot(omega, i_omega) + self.mass * vdot(v, v)
        height = -vdot(r1o, no)
        return m, self.mass * self.gravity * height, omega

    def effective_mass(self, s):
        return self.mechanics(s, 0)[0].c[0]

    def potential(self, s):
        return self.mechanics(s, 0)[1].c[0]

    def angular_speed_per_phase(self, s):
        omega = self.mechanics(s, 0)[2]
        return (omega[0].c[0] ** 2 + omega[1].c[0] ** 2 + omega[2].c[0] ** 2) ** 0.5

    def energy(self, s, s_dot):
        m, v, _ = self.mechanics(np.asarray(s, dtype=float), 0)
        return 0.5 * m.c[0] * np.asarray(s_dot) ** 2 + v.c[0]

    def acceleration(self, s, s_dot):
        """s̈ from Lagrange's equation m s̈ + ½ m' ṡ² + V' = 0."""
        m, v, _ = self.mechanics(s, 1)
        return -(v.c[1] + 0.5 * m.c[1] * s_dot * s_dot) / m.c[0]

    def trace_rates(self, s):
        """(α', t1·r1', (n × t1)·r1') at phase s (per unit s)."""
        r1, _, n, t1 = self.frame(s, 1)
        r1d = tuple(x.c[1] for x in r1)
        nv = tuple(x.c[0] for x in n)
        tv = tuple(x.c[0] for x in t1)
        td = tuple(x.c[1] for x in t1)
        mv = vcross(nv, tv)
        return vdot(td, mv), vdot(tv, r1d), vdot(mv, r1d)

    def phase_from_theta(self, theta, branch=1):
        """Phase s of contact angle θ (tan θ = (b/a) tan η) on a branch."""
        eta = math.atan2(self.a * math.sin(theta), self.b * math.cos(theta))
        base = math.asin(max(-1.0, min(1.0, eta / self.eta_max)))
        return base if branch > 0 else math.pi - base

    # -- world poses ------------------------------------------------------------------------
    def world_positions(self, s, alpha, z_a):
        """G, A, B (world, m) at phases s with heading α and trace point Z_A = X + iY."""
        s = np.asarray(s, dtype=float)
        r1, r2, n, t1 = self.frame(s, 0)
        r1v = np.stack([x.c[0] for x in r1], -1)
        r2v = np.stack([x.c[0] for x in r2], -1)
        nv = np.stack([x.c[0] for x in n], -1)
        tv = np.stack([x.c[0] for x in t1], -1)
        mv = np.cross(nv, tv)
        c = np.exp(1j * np.asarray(alpha))

        def rotate(r):   # R r = c_α (t1·r) + i c_α (m·r) in the plane, n·r vertically
            planar = c * (np.sum(tv * r, -1) + 1j * np.sum(mv * r, -1))
            return planar, np.sum(nv * r, -1)

        p1, z1 = rotate(r1v)
        p2, z2 = rotate(r2v)
        g = z_a - p1
        b = g + p2
        zero = np.zeros_like(g.real)
        return (np.stack([g.real, g.imag, -z1], -1),
                np.stack([z_a.real, z_a.imag, zero], -1),
                np.stack([b.real, b.imag, -z1 + z2], -1))


# ------------------------------------------------------------------ integrations
class ReferenceTrace:
    """α(s) and Z_A(s) by DOP853 in the phase from s = 0, over [s_lo, s_hi]."""

    def __init__(self, body, s_lo, s_hi, rtol):
        self.body = body

        def rates(s, y):
            da, ts, ms = body.trace_rates(s)
            c, sn = math.cos(y[0]), math.sin(y[0])
            return [da, c * ts - sn * ms, sn * ts + c * ms]
        self._parts = []
        self.nfev = 0
        atol = rtol * body.size * 1e-2
        for end in (s_lo, s_hi):
            if end == 0.0:
                continue
            res = solve_ivp(rates, (0.0, float(end)), [0.0, 0.0, 0.0], method='DOP853',
                            rtol=rtol, atol=atol, dense_output=True)
            if not res.success:
                raise RuntimeError(res.message)
            self.nfev += res.nfev
            self._parts.append((min(0.0, end), max(0.0, end), res.sol))

    def __call__(self, s):
        s = np.asarray(s, dtype=float)
        out = np.zeros((3,) + s.shape)
        done = np.zeros(s.shape, dtype=bool)
        for lo, hi, sol in self._parts:
            sel = (s >= lo) & (s <= hi) & ~done
            if np.any(sel):
                out[:, sel] = sol(s[sel])
                done |= sel
        if not np.all(done | (s == 0.0)):
            raise ValueError('phase outside the integrated trace')
        return out[0], out[1] + 1j * out[2]


class ReferenceSolution:
    """s(t) (dense) and the world poses of G, A, B from the independent reference."""

    def __init__(self, body, t_end, s0, s_dot0=None, omega_speed=None, rtol=1e-13):
        """Dynamic mode if ``s_dot0`` is given, kinematic mode (|ω| = omega_speed) otherwise."""
        self.body = body
        self.rtol = rtol
        if omega_speed is None:
            def rhs(t, y):
                return [y[1], body.acceleration(y[0], y[1])]
            y0 = [s0, s_dot0]
            atol = [rtol, rtol * max(abs(s_dot0), 1.0)]
        else:
            direction = math.copysign(1.0, omega_speed)
            speed = abs(omega_speed)

            def rhs(t, y):
                return [direction * speed / body.angular_speed_per_phase(y[0])]
            y0 = [s0]
            atol = rtol
        self.kinematic = omega_speed is not None
        res = solve_ivp(rhs, (0.0, float(t_end)), y0, method='DOP853', rtol=rtol, atol=atol,
                        dense_output=True)
        if not res.success:
            raise RuntimeError(res.message)
        self.sol = res.sol
        self.nfev = res.nfev
        self.omega_speed = omega_speed
        ts = np.linspace(0.0, t_end, 20001)
        phases = res.sol(ts)[0]
        pad = 0.05
        self.trace = ReferenceTrace(body, min(0.0, phases.min() - pad), max(0.0, phases.max()
                                                                              + pad), rtol)

    def phase(self, t):
        return self.sol(np.asarray(t, dtype=float))[0]

    def phase_rate(self, t):
        y = self.sol(np.asarray(t, dtype=float))
        if not self.kinematic:
            return y[1]
        s = y[0]
        _, _, omega = self.body.mechanics(s, 0)
        speed = np.sqrt(sum(w.c[0] ** 2 for w in omega))
        return math.copysign(1.0, self.omega_speed) * abs(self.omega_speed) / speed

    def positions_at_phase(self, s):
        alpha, z_a = self.trace(s)
        return self.body.world_positions(s, alpha, z_a)

    def positions(self, t):
        return self.positions_at_phase(self.phase(t))


def reference_solution(body, t_end, s0, s_dot0=None, omega_speed=None, rtol=1e-13):
    return ReferenceSolution(body, t_end, s0, s_dot0, omega_speed, rtol)

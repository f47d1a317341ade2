"""The three targets of the benchmark issue, measured."""

from dataclasses import dataclass, asdict
import math
import re
import time
import warnings


def _parser():
    """The command line (built before the heavy imports, so that ``--help`` answers at once;
    the bodies are checked against scenarios.BODIES once that is imported)."""
    import argparse
    parser = argparse.ArgumentParser(description='Poses per second of the table method, and '
                                     'their errors, for the benchmark bodies.')
    parser.add_argument('bodies', nargs='*', metavar='BODY',
                        help='bodies to measure (default: all of scenarios.BODIES: oloid, '
                        'two_circle_roller, ...)')
    return parser


if __name__ == '__main__':
    _parser().parse_args()

import numpy as np  # noqa: E402

from reference import ReferenceTrace  # noqa: E402
from scenarios import GRAVITY, MASS  # noqa: E402
from work_precision import (REFERENCE_CHECK_RTOL, REFERENCE_RTOL, position_error,  # noqa: E402
                            _timed)

from twodisk_ros import simulate  # noqa: E402
from twodisk_ros.physics.motion.simulate import CLOSED_FORM_SOLVERS  # noqa: E402

TWO_PI = 2 * math.pi


# ------------------------------------------------------------------ target 1
@dataclass
class PositionsThroughput:
    body: str
    samples: int
    wall: float             #: s, best of repeats, RollingCycle.positions on all samples
    rate: float             #: samples per second
    error: float            #: max position error of G, A, B / size, vs the reference
    reference_error: float  #: estimated error of that reference / size
    phase_span: tuple       #: (u_lo, u_hi) (rad)
    chunk: int = 0          #: diagnostic: the same phases in calls of this many samples …
    rate_chunked: float = 0.0   #: … reach this many samples per second

    def as_dict(self):
        return asdict(self)


def positions_throughput(built, n=10**6, span=(-TWO_PI, 2 * TWO_PI)):
    """RollingCycle.positions on n phases (3 cycles, also negative u) vs the reference."""
    cycle = built.dynamics.cycle
    u = np.linspace(span[0], span[1], n)
    cycle.positions(u[:1000])                       # warm up
    _, wall = _timed(lambda: cycle.positions(u), min_time=math.inf, max_repeats=5)
    chunk = min(n, 100_000)

    def chunked():
        for i in range(0, n, chunk):
            cycle.positions(u[i:i + chunk])
    _, wall_chunked = _timed(chunked, min_time=math.inf, max_repeats=3)
    pos = cycle.positions(u)
    rb = built.ref_body
    trace = ReferenceTrace(rb, span[0], span[1], REFERENCE_RTOL)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        check = ReferenceTrace(rb, span[0], span[1], REFERENCE_CHECK_RTOL)
    ref = rb.world_positions(u, *trace(u))
    sub = u[::50]
    ref_check = rb.world_positions(sub, *check(sub))
    size = built.body.size
    err = position_error(pos, ref, size)
    ref_err = position_error(tuple(x[::50] for x in ref), ref_check, size)
    return PositionsThroughput(built.name, n, wall, n / wall, err, ref_err, span, chunk,
                               n / wall_chunked)


# ------------------------------------------------------------------ target 1, full poses
@dataclass
class PosesThroughput:
    """RollingCycle.poses (G, A, B, heading, quaternion) and .positions, one run, one body."""

    body: str
    samples: int
    rate_poses: float         #: samples/s, RollingCycle.poses, best of repeats
    rate_positions: float     #: samples/s, RollingCycle.positions, best of repeats
    rate_state: float         #: samples/s, RollingCycle.state (closed forms + quaternion)
    position_error: float     #: max over G, A, B of |poses − reference| / size
    orientation_error: float  #: max rotation angle between poses and reference (rad)
    reference_error: float    #: estimated error of the reference, / size or rad (the larger)
    sign_flips: int           #: consecutive quaternions with q_k · q_{k+1} < 0 (0 expected)
    phase_span: tuple         #: (u_lo, u_hi) (rad)

    def as_dict(self):
        return asdict(self)


def _reference_quaternions(rb, u, alpha):
    """Body → world (x, y, z, w) of the reference: R = R_z(α)·[t1; n × t1; n], via scipy."""
    from scipy.spatial.transform import Rotation
    _, _, n, t1 = rb.frame(np.asarray(u, dtype=float), 0)
    nv = np.stack([x.c[0] for x in n], -1)
    tv = np.stack([x.c[0] for x in t1], -1)
    contact = np.stack([tv, np.cross(nv, tv), nv], axis=-2)
    heading = Rotation.from_euler('z', np.asarray(alpha)[:, None])
    return (heading * Rotation.from_matrix(contact)).as_quat()


def _angle(q, q_ref):
    """Rotation angle between unit quaternions (rad), sign-blind: 2 atan2(|v|, |q·q_ref|).

    v is the vector part of q ⊗ q̄_ref.
    """
    dot = np.abs(np.sum(q * q_ref, axis=-1))
    w1, w2 = q[..., 3:], q_ref[..., 3:]
    vec = w2 * q[..., :3] - w1 * q_ref[..., :3] - np.cross(q[..., :3], q_ref[..., :3])
    return 2.0 * np.arctan2(np.linalg.norm(vec, axis=-1), dot)


def poses_throughput(built, n=10**6, span=(-TWO_PI, 2 * TWO_PI), repeats=5):
    """Full poses/s (RollingCycle.poses) and positions/s on n phases, errors vs the reference.

    The reference: heading α and trace Z_A by DOP853 (``ReferenceTrace``), positions from
    its own closed forms, orientation R_z(α)·C(u) from its own frame via scipy; its error is
    estimated with a tighter second integration on every 50th sample.
    """
    cycle = built.dynamics.cycle
    u = np.linspace(span[0], span[1], n)
    cycle.poses(u[:1000])                                    # warm up
    cycle.positions(u[:1000])
    poses, wall_poses = _timed(lambda: cycle.poses(u), min_time=math.inf,
                               max_repeats=repeats)
    _, wall_positions = _timed(lambda: cycle.positions(u), min_time=math.inf,
                               max_repeats=repeats)
    sub = u[::50]
    _, wall_state = _timed(lambda: cycle.state(sub).quaternion, min_time=math.inf,
                           max_repeats=repeats)
    rb = built.ref_body
    trace = ReferenceTrace(rb, span[0], span[1], REFERENCE_RTOL)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        check = ReferenceTrace(rb, span[0], span[1], REFERENCE_CHECK_RTOL)
    alpha, z_a = trace(u)
    size = built.body.size
    pos_err = position_error((poses.position_g, poses.contact_a, poses.contact_b),
                             rb.world_positions(u, alpha, z_a), size)
    q_ref = _reference_quaternions(rb, u, alpha)
    rot_err = float(np.max(_angle(poses.quaternion, q_ref)))
    alpha_check, z_check = check(sub)
    ref_err = max(position_error(rb.world_positions(sub, alpha[::50], z_a[::50]),
                                 rb.world_positions(sub, alpha_check, z_check), size),
                  float(np.max(_angle(q_ref[::50], _reference_quaternions(rb, sub,
                                                                          alpha_check)))))
    q = poses.quaternion
    flips = int(np.sum(np.sum(q[1:] * q[:-1], axis=-1) < 0))
    return PosesThroughput(built.name, n, n / wall_poses, n / wall_positions,
                           sub.size / wall_state, pos_err, rot_err, ref_err, flips, span)


# ------------------------------------------------------------------ target 2
@dataclass
class HourRun:
    body: str
    kind: str
    samples: int
    wall_simulate: float
    wall_positions: float
    drift: float             #: independent: energy (dynamic) or |ω| (kinematic), relative
    drift_package: float     #: RollingMotion.energy_drift over all samples (dynamic only)
    cycle_time: float        #: s, independent (trapezoid rule on the reference's formulas)
    cycles: int              #: whole cycles in the hour
    phase_error: float       #: max_k |u(k T) − u0 − 2πk| (rad)
    position_error: float    #: max_k position error at t = k T, / size (G, A, B)
    reference_error: float   #: estimated error of the reference poses at the last cycle / size
                             #: (piecewise-Chebyshev cycle map, 128 vs 64 panels)
    finite: bool
    conditioning: float = 0.0    #: pose change at the last cycle from one ulp(2π) of turn / size
    chunk: int = 0               #: diagnostic: the same hour simulated in chunks of samples …
    wall_chunked: float = 0.0    #: … takes this long (simulate + positions)
    walls: list = None           #: every repeat's simulate + positions (s); the best is kept

    @property
    def wall(self):
        return self.wall_simulate + self.wall_positions

    def as_dict(self):
        d = asdict(self)
        d['wall'] = self.wall
        return d


def _periodic_integral(f, rel=1e-15):
    """∫₀^{2π} f(s) ds for a smooth periodic f: trapezoid rule, doubled until converged."""
    n, previous = 256, None
    while True:
        s = TWO_PI * np.arange(n) / n
        value = TWO_PI * float(np.mean(f(s)))
        if previous is not None and abs(value - previous) <= rel * abs(value):
            return value
        if n > 2**22:
            raise RuntimeError('periodic integral did not converge')
        previous, n = value, 2 * n


def cycle_map(rb, panels=32, degree=24):
    """(e^{i turn}, shift) of one cycle u → u + 2π from s = 0 (world map p → e^{i turn} p + shift).

    Piecewise Chebyshev quadrature (``panels`` panels of ``degree + 1`` Chebyshev points):
    α' is interpolated and integrated cumulatively on each panel, then e^{iα}(t1·r1' +
    i m·r1') likewise; spectrally accurate per panel, sharing nothing with the package's
    global Fourier tables. Compare two panel counts for its error.
    """
    from numpy.polynomial import chebyshev as C
    x = np.cos(np.pi * np.arange(degree + 1) / degree)[::-1]      # [-1, 1], increasing
    edges = np.linspace(0.0, TWO_PI, panels + 1)
    alpha0, z0 = 0.0, 0.0j
    for lo, hi in zip(edges[:-1], edges[1:]):
        half = 0.5 * (hi - lo)
        s = lo + half * (x + 1.0)
        rates = np.array([rb.trace_rates(v) for v in s])            # (α', t·r1', m·r1')
        c_alpha = C.chebint(C.chebfit(x, rates[:, 0], degree), lbnd=-1.0) * half
        alpha = alpha0 + C.chebval(x, c_alpha)
        integrand = np.exp(1j * alpha) * (rates[:, 1] + 1j * rates[:, 2])
        c_re = C.chebint(C.chebfit(x, integrand.real, degree), lbnd=-1.0) * half
        c_im = C.chebint(C.chebfit(x, integrand.imag, degree), lbnd=-1.0) * half
        alpha0 = alpha0 + float(C.chebval(1.0, c_alpha))
        z0 = z0 + complex(C.chebval(1.0, c_re), C.chebval(1.0, c_im))
    return complex(np.exp(1j * alpha0)), z0


def _composed(p0, spin, shift, cycles):
    """World points p0 (complex) after k = 1..cycles cycles, by repeated application."""
    out = np.empty((cycles,) + np.shape(p0), dtype=complex)
    p = np.asarray(p0, dtype=complex)
    for k in range(cycles):
        p = spin * p + shift
        out[k] = p
    return out


def hour_run(built, sc, duration=3600.0, rate=1000.0, subsample=100, chunk=100_000, repeats=2):
    """simulate(..., t_eval=np.arange(0, duration, 1/rate), method='table') + positions."""
    assert sc.phase0 == 0.0, 'the cycle check below assumes the run starts at u = 0'
    dyn = built.dynamics
    rb = built.ref_body
    t = np.arange(0.0, duration, 1.0 / rate)
    kwargs = dict(mode=sc.mode, theta0=sc.theta0, branch=sc.branch, omega0=sc.omega0,
                  method='table')
    walls = []
    for repeat in range(repeats):       # best of `repeats` (the machine is shared)
        motion = pos = None
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', RuntimeWarning)
            t0 = time.perf_counter()
            motion = simulate(dyn, t, **kwargs)
            t1 = time.perf_counter()
            pos = motion.positions()
            t2 = time.perf_counter()
        walls.append((t2 - t0, t1 - t0, t2 - t1))
    _, wall_sim, wall_pos = min(walls)
    finite = bool(np.all(np.isfinite(motion.phase)))
    u_sub = motion.phase[::subsample]
    rate_sub = motion.phase_rate[::subsample]
    u_safe = np.where(np.isfinite(u_sub), u_sub, 0.0)
    size = built.body.size
    if sc.mode == 'dynamic':
        e0 = float(rb.energy(sc.phase0, sc.phase_rate0))
        drift = float(np.max(np.abs(rb.energy(u_safe, rate_sub) - e0))) / (MASS * GRAVITY * size)
        drift_pkg = motion.energy_drift

        def inverse_rate(s):
            m, v, _ = rb.mechanics(s, 0)
            return np.sqrt(m.c[0] / (2.0 * (e0 - v.c[0])))
    else:
        _, _, omega = rb.mechanics(u_safe, 0)
        w = np.sqrt(sum(x.c[0] ** 2 for x in omega))
        drift = float(np.max(np.abs(w * np.abs(rate_sub) - abs(sc.omega0)))) / abs(sc.omega0)
        drift_pkg = float('nan')

        def inverse_rate(s):
            _, _, om = rb.mechanics(s, 0)
            return np.sqrt(sum(x.c[0] ** 2 for x in om)) / abs(sc.omega0)
    if not finite:
        drift = math.inf
    del pos, motion
    cycle_time = _periodic_integral(inverse_rate)
    cycles = int(math.floor(duration / cycle_time))
    ks = np.arange(1, cycles + 1)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RuntimeWarning)
        at_cycles = simulate(dyn, ks * cycle_time, **kwargs)
    direction = math.copysign(1.0, sc.omega0)
    phase_err = float(np.max(np.abs(at_cycles.phase - (sc.phase0 + direction * TWO_PI * ks))))
    got = at_cycles.dynamics.cycle.positions(at_cycles.phase)
    p0 = rb.world_positions(np.array([sc.phase0]), np.zeros(1), np.zeros(1, complex))
    p0c = np.array([p[0, 0] + 1j * p[0, 1] for p in p0])
    heights = np.array([p[0, 2] for p in p0])
    spin, shift = cycle_map(rb, panels=128)
    spin2, shift2 = cycle_map(rb, panels=64)
    if direction < 0:    # u decreasing: one cycle back is the inverse map
        spin, shift = 1 / spin, -shift / spin
        spin2, shift2 = 1 / spin2, -shift2 / spin2
    ref = _composed(p0c, spin, shift, cycles)          # (cycles, 3) for G, A, B
    ref2 = _composed(p0c[None, :], spin2, shift2, cycles)[-1, 0]
    worst = 0.0
    for j, p in enumerate(got):
        d = np.hypot(np.abs(p[:, 0] + 1j * p[:, 1] - ref[:, j]), p[:, 2] - heights[j])
        worst = max(worst, float(np.max(d)) if np.all(np.isfinite(d)) else math.inf)
    ref_err = float(np.max(np.abs(ref[-1] - ref2))) / size
    ulp = math.ulp(TWO_PI)
    ref3 = _composed(p0c[None, :], spin * complex(math.cos(ulp), math.sin(ulp)), shift,
                     cycles)[-1, 0]
    conditioning = float(np.max(np.abs(ref[-1] - ref3))) / size
    # diagnostic: the same work in chunks of `chunk` samples (simulate accepts any t_eval ≥ 0)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RuntimeWarning)
        tc = time.perf_counter()
        for i in range(0, t.size, chunk):
            part = simulate(dyn, t[i:i + chunk], **kwargs)
            part.positions()
        wall_chunked = time.perf_counter() - tc
    return HourRun(built.name, sc.kind, t.size, wall_sim, wall_pos, drift, drift_pkg, cycle_time,
                   cycles, phase_err if math.isfinite(phase_err) else math.inf, worst / size,
                   ref_err, finite, conditioning, chunk, wall_chunked,
                   [w[0] for w in walls])


# ------------------------------------------------------------------ target 3
@dataclass
class SpeedRatio:
    body: str
    kind: str
    table_solver: str
    table_tolerance: float
    table_error: float
    table_wall_per_second: float
    direct_wall_per_second: float   #: at the table's error (interpolated) or the bound
    ratio: float
    relation: str                   #: '=', '>=' (direct never that accurate) or '<='
    note: str

    def as_dict(self):
        return asdict(self)


def _interp_direct(direct, error):
    """Direct wall/s at a given error: log-log interpolation along increasing tolerance."""
    pts = sorted(((r.tolerance, r.error, r.wall_per_second) for r in direct
                  if math.isfinite(r.error) and r.error > 0))
    errs = [p[1] for p in pts]
    if not pts:
        return math.nan, '=', 'no finite direct point'
    if error < min(errs):
        best = min(pts, key=lambda p: p[1])
        note = f'direct never reaches this error (its best: {best[1]:.1e} at tol {best[0]:.0e})'
        (_, e1, w1), (_, e2, w2) = pts[0], pts[min(1, len(pts) - 1)]  # two tightest tols
        if e2 > 3 * e1 and w1 > w2:                      # still converging: extrapolate
            slope = math.log(w1 / w2) / math.log(e1 / e2)  # d log w / d log e (< 0)
            extrap = w1 * math.exp(slope * math.log(error / e1))
            note += f'; log-log extrapolation: {extrap * 1e3:.3g} ms/s'
        else:
            note += '; its error has plateaued (no extrapolation)'
        return best[2], '>=', note
    if error > max(errs):
        cheap = min(pts, key=lambda p: p[2])
        return cheap[2], '<=', f'direct is more accurate even at tol {cheap[0]:.0e}'
    for (t1, e1, w1), (t2, e2, w2) in zip(pts, pts[1:]):
        lo, hi = min(e1, e2), max(e1, e2)
        if lo <= error <= hi:
            if e1 == e2:
                return min(w1, w2), '=', ''
            x = (math.log(error) - math.log(e1)) / (math.log(e2) - math.log(e1))
            return math.exp(math.log(w1) + x * (math.log(w2) - math.log(w1))), '=', (
                f'interpolated between tol {t1:.0e} and {t2:.0e}')
    best = min(pts, key=lambda p: abs(math.log(p[1] / error)))
    return best[2], '=', f'nearest direct point, tol {best[0]:.0e}'


def speed_ratios(results):
    """For each scenario and each table run: direct wall/s at the table's error, and ratio."""
    out = []
    seen = []
    for r in results:
        if (r.body, r.kind) not in seen:
            seen.append((r.body, r.kind))
    for body, kind in seen:
        direct = [r for r in results if (r.body, r.kind, r.method) == (body, kind, 'direct')]
        table = [r for r in results if (r.body, r.kind, r.method) == (body, kind, 'table')]
        if table and table[0].solver in CLOSED_FORM_SOLVERS:
            table = [min(table, key=lambda r: r.wall_per_second)]   # tolerance-independent
        for tr in table:
            if not (math.isfinite(tr.error) and tr.error < 1.0):
                out.append(SpeedRatio(body, kind, tr.solver, tr.tolerance, tr.error,
                                      tr.wall_per_second, math.nan, math.nan, '', 'table run failed (error ≥ size)'))
                continue
            w, rel, note = _interp_direct(direct, tr.error)
            match = re.search(r'extrapolation: ([0-9.e+-]+) ms/s', note)
            if match:
                note += f' → ≈ {float(match.group(1)) * 1e-3 / tr.wall_per_second:.0f}×'
            out.append(SpeedRatio(body, kind, tr.solver, tr.tolerance, tr.error,
                                  tr.wall_per_second, w, w / tr.wall_per_second, rel, note))
    return out


if __name__ == '__main__':       # PYTHONPATH=. python benchmarks/targets.py [body ...]
    from scenarios import BODIES
    from work_precision import build
    parser = _parser()
    chosen = parser.parse_args().bodies
    for unknown in set(chosen) - set(BODIES):
        parser.error(f'unknown body {unknown!r} (known: {", ".join(BODIES)})')
    for name in chosen or list(BODIES):
        r = poses_throughput(build(name))
        print(f'{name}: poses {r.rate_poses / 1e6:.2f} M/s, positions '
              f'{r.rate_positions / 1e6:.2f} M/s, state {r.rate_state / 1e6:.2f} M/s; errors: '
              f'position {r.position_error:.1e} of size, orientation {r.orientation_error:.1e} '
              f'rad (reference {r.reference_error:.1e}), sign flips {r.sign_flips}')

"""Work-precision runs: each method and tolerance against the independent reference."""

from dataclasses import dataclass, asdict
import math
import time
import warnings

import numpy as np

from reference import ReferenceBody, ReferenceSolution
from scenarios import BODIES, GRAVITY, MASS

from twodisk_ros import RollingCycle, RollingDynamics, EllipseBody, simulate
from twodisk_ros.physics.mass.models import laminae

METHODS = ('direct', 'table')
TOLERANCES = (1e-6, 1e-8, 1e-10, 1e-12)
REFERENCE_RTOL = 1e-13          # the reference
REFERENCE_CHECK_RTOL = 2.5e-14  # a second, tighter reference: estimates the first one's error
OUTPUT_RATE = 1000.0            # Hz: samples of every run


@dataclass
class Built:
    """A body with its tables, and what building them cost."""

    name: str
    body: EllipseBody
    dynamics: RollingDynamics
    ref_body: ReferenceBody
    cycle_build: float      #: s, RollingCycle(body)
    dynamics_build: float   #: s, RollingDynamics(...) on that cycle (its m, V, |ω_u| tables)
    resolution: int


def build(name):
    a, b, d, _ = BODIES[name]
    body = EllipseBody(a, b, d)
    mass = laminae(a, b, d, MASS)
    t0 = time.perf_counter()
    cycle = RollingCycle(body)
    t1 = time.perf_counter()
    dyn = RollingDynamics(body, mass, GRAVITY, cycle=cycle)
    t2 = time.perf_counter()
    return Built(name, body, dyn, ReferenceBody(a, b, d, MASS, GRAVITY), t1 - t0, t2 - t1,
                 cycle.resolution)


@dataclass
class ReferenceRun:
    scenario: object
    solution: ReferenceSolution
    t: np.ndarray
    positions: tuple
    phase: np.ndarray
    phase_rate: np.ndarray
    wall: float
    nfev: int
    estimated_error: float   #: max position difference to the tighter reference / size
    phase_difference: float  #: max |Δs| to the tighter reference (rad)
    cycles: float            #: cycles (rolling, kinematic) or oscillation periods covered
    energy0: float           #: E at t = 0 (J), independent formulas


def _reference(built, sc, rtol):
    if sc.mode == 'dynamic':
        return ReferenceSolution(built.ref_body, sc.span, sc.phase0, s_dot0=sc.phase_rate0,
                                 rtol=rtol)
    return ReferenceSolution(built.ref_body, sc.span, sc.phase0, omega_speed=sc.omega0,
                             rtol=rtol)


def sample_times(span):
    return np.linspace(0.0, span, int(round(span * OUTPUT_RATE)) + 1)


def position_error(p, q, size):
    """max over samples and over G, A, B of the Euclidean distance, relative to size."""
    worst = 0.0
    for x, y in zip(p, q):
        d = np.linalg.norm(np.asarray(x) - np.asarray(y), axis=-1)
        worst = max(worst, float(np.max(d)) if np.all(np.isfinite(d)) else math.inf)
    return worst / size


def sample_errors(p, q, size):
    """Per-sample max over G, A, B of the Euclidean distance / size (inf where not finite)."""
    worst = None
    for x, y in zip(p, q):
        d = np.linalg.norm(np.asarray(x) - np.asarray(y), axis=-1)
        d = np.where(np.isfinite(d), d, np.inf)
        worst = d if worst is None else np.maximum(worst, d)
    return worst / size


def reference_run(built, sc):
    t = sample_times(sc.span)
    t0 = time.perf_counter()
    ref = _reference(built, sc, REFERENCE_RTOL)
    wall = time.perf_counter() - t0
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')      # scipy: "rtol too small" is not raised at 2.5e-14
        check = _reference(built, sc, REFERENCE_CHECK_RTOL)
    pos = ref.positions(t)
    est = position_error(pos, check.positions(t), built.body.size)
    phase = ref.phase(t)
    dphase = float(np.max(np.abs(phase - check.phase(t))))
    rate = ref.phase_rate(t)
    if sc.kind == 'oscillating':
        cycles = 0.5 * int(np.count_nonzero(np.diff(np.sign(rate[1:])) != 0))
    else:
        cycles = abs(phase[-1] - phase[0]) / (2 * math.pi)
    e0 = float(built.ref_body.energy(sc.phase0, sc.phase_rate0))
    return ReferenceRun(sc, ref, t, pos, phase, rate, wall, ref.nfev + ref.trace.nfev, est,
                        dphase, cycles, e0)


@dataclass
class Result:
    body: str
    kind: str
    method: str
    tolerance: float
    solver: str
    span: float             #: simulated seconds
    samples: int
    wall_simulate: float    #: s
    wall_positions: float   #: s
    nfev: int
    error: float            #: max position error of G, A, B / body size
    energy_drift: float     #: dynamic: max|E − E0| / (M g size); kinematic: max||ω| − Ω| / Ω
    energy_drift_package: float  #: RollingMotion.energy_drift (the package's own, tables)
    phase_error: float      #: |u(T) − s_ref(T)| at the end (rad)
    cycles: float
    finite: bool = True
    bad_samples: int = 0    #: samples whose position error exceeds 1e-3 of the size

    @property
    def wall(self):
        return self.wall_simulate + self.wall_positions

    @property
    def wall_per_second(self):
        """Wall seconds per simulated second (simulate + positions)."""
        return self.wall / self.span

    def as_dict(self):
        d = asdict(self)
        d['wall_per_second'] = self.wall_per_second
        return d


def _timed(fn, min_time=0.3, max_repeats=5):
    """(result, best wall time) over repeats while the total stays short."""
    best, total, result = math.inf, 0.0, None
    for _ in range(max_repeats):
        t0 = time.perf_counter()
        result = fn()
        dt = time.perf_counter() - t0
        best, total = min(best, dt), total + dt
        if total > min_time:
            break
    return result, best


def run_method(built, ref_run, method, tolerance):
    sc = ref_run.scenario
    t = ref_run.t
    dyn = built.dynamics

    def sim():
        return simulate(dyn, t, mode=sc.mode, theta0=sc.theta0, branch=sc.branch,
                        omega0=sc.omega0, method=method, tolerance=tolerance)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RuntimeWarning)   # a diverging run is reported, not hidden
        motion, wall_sim = _timed(sim)
        pos, wall_pos = _timed(motion.positions)
    size = built.body.size
    per_sample = sample_errors(pos, ref_run.positions, size)
    err = float(np.max(per_sample))
    bad = int(np.count_nonzero(per_sample > 1e-3))
    rb = built.ref_body
    finite = bool(np.all(np.isfinite(motion.phase)))
    u = np.where(np.isfinite(motion.phase), motion.phase, 0.0)
    if sc.mode == 'dynamic':
        energy = rb.energy(u, motion.phase_rate)
        drift = float(np.max(np.abs(energy - ref_run.energy0))) / (MASS * GRAVITY * size)
    else:
        _, _, omega = rb.mechanics(u, 0)
        w = np.sqrt(sum(x.c[0] ** 2 for x in omega))
        speed = w * np.abs(motion.phase_rate)
        drift = float(np.max(np.abs(speed - abs(sc.omega0)))) / abs(sc.omega0)
    if not finite:
        drift = math.inf
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RuntimeWarning)
        package_drift = motion.energy_drift if finite else math.inf
    phase_err = float(abs(motion.phase[-1] - ref_run.phase[-1]))
    if not math.isfinite(phase_err):
        phase_err = math.inf
    return Result(sc.body, sc.kind, method, tolerance, motion.solver, sc.span, t.size,
                  wall_sim, wall_pos, int(motion.nfev), err, drift, package_drift, phase_err,
                  ref_run.cycles, finite, bad)

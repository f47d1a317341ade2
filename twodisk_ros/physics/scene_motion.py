"""Motion in a scene: the general integrator over the phase u (docs/physics.md#scenes).

The configuration is still a function of u (rolling is exact on any plane), so every scene
is the 1-DOF equation of motion (SI units, Q the generalised forces, J/rad):

    m(u) ü + ½ m′(u) u̇² + V′(u) = Q_drive + Q_damping + Q_rolling,

* V(u) = M g (h cos β − s sin β) on a slope (:mod:`~twodisk_ros.physics.scene_terms`);
* torque drive: a moment τ ê about the axis AB, Q = τ (ω_u·ê) = τ |ω_u| (ω_u ∥ ê, ω_u·ê > 0);
* damping, a moment −c ω: Q = −c |ω_u|² u̇;
* rolling resistance, a moment μ_r N ρ about AB opposing the rotation (N = N_A + N_B, ρ the
  distance of G from AB, so ρ |ω_u| = |dG/du| =: k): Q = −μ_r k N sgn(u̇). N depends on ü
  (N = N_g + N_2 u̇² + N_ü ü), so ü solves a linear equation;
* speed drive: the signed rolling speed Ω = |ω_u| u̇ follows the command by the first-order
  lag Ω(t) = Ω_cmd + (Ω₀ − Ω_cmd) e^{−t/T}; then u̇ = Ω/|ω_u| and the drive supplies
  Q_drive = m ü + ½ m′ u̇² + V′ − Q_damping − Q_rolling, i.e. the torque Q_drive/|ω_u| about AB
  and the power Q_drive u̇.

The state carries the dissipated work W (J, ≥ 0) and the drive's work W_d (J), so that
E(t) + W(t) − W_d(t) = E₀ is the energy balance. DOP853 (scipy, dense output) integrates
(u, u̇, W, W_d) (speed drive: (u, W, W_d)); rolling resistance switches sign with u̇, so each
stretch between two stops (u̇ = 0) is integrated on its own, and at a stop the body stays at
rest if |V′ − Q_drive| ≤ μ_r k N (it sticks: the time to rest is exact). Where the flat fast
paths hold (:func:`scene_stream`) today's :class:`~twodisk_ros.physics.motion.MotionStream` is
used unchanged, and a conservative scene on a slope has the closed forms of
:mod:`~twodisk_ros.physics.scene_closed` (:class:`ClosedSceneStream`).
"""

from dataclasses import dataclass
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .contact_validity import ValidityReport, check_validity
from .motion import MotionStream
from .scene_closed import DriftQuadrature, conservative_solution
from .scene_terms import C2, CN, CU, DM, DW, K_G, KIM, KRE, M, SceneTerms, W

__all__ = ['ClosedSceneStream', 'SceneStream', 'SceneSamples', 'scene_stream',
           'simulate_scene', 'settle', 'first_failure']


@dataclass
class SceneSamples:
    """A scene's motion at sample times (arrays over ``t``; SI units)."""

    t: np.ndarray                   #: s
    phase: np.ndarray               #: u (rad)
    phase_rate: np.ndarray          #: u̇ (rad/s)
    phase_acceleration: np.ndarray  #: ü (rad/s²)
    energy: np.ndarray              #: E = T + V (J), V along gravity (0 at A's start height)
    dissipated: np.ndarray          #: W (J): work done by damping and rolling resistance
    drive_work: np.ndarray          #: W_d (J): work done by the drive
    drive_torque: np.ndarray        #: τ about AB (N m) (0 without drive)
    power: np.ndarray               #: drive power τ ê·ω (W)
    rolling_speed: np.ndarray       #: Ω = |ω_u| u̇ (rad/s), signed

    @property
    def balance(self):
        """E + W − W_d (J): constant (= E₀) along any motion."""
        return self.energy + self.dissipated - self.drive_work


class _Piece:
    """One stretch [start, end] of the motion: dense output of the state, or rest."""

    def __init__(self, start, end, sol=None, rest=None):
        self.start, self.end, self.sol, self.rest = start, end, sol, rest

    def __call__(self, t):
        if self.sol is None:
            return np.repeat(np.asarray(self.rest, dtype=float)[:, None], len(t), axis=1)
        return self.sol(t)


class SceneStream:
    """Samples of a scene's motion at increasing times (DOP853, lazily in segments).

    Parameters
    ----------
    terms : SceneTerms
    u0, u_dot0 : float
        Initial phase (rad) and phase rate (rad/s).
    tolerance : float
        rtol of DOP853 (atol = tolerance × the state's scale).
    chunk, lookahead : float
        As :class:`~twodisk_ros.physics.motion.MotionStream`: segments of at most ``chunk``
        s, reaching ``lookahead`` s beyond the times asked.

    The dense output of every segment reaching back to the earliest time of the latest
    call is kept, so :meth:`evaluate` gives the state at any time of that window (the root
    finding of :func:`first_failure` and :func:`settle`).
    """

    def __init__(self, terms, u0, u_dot0, *, tolerance=1e-10, chunk=10.0, lookahead=0.5):
        if not isinstance(terms, SceneTerms):
            raise TypeError(f'terms must be a SceneTerms, got {type(terms).__name__}')
        self.terms, self.scene, self.tolerance = terms, terms.scene, float(tolerance)
        self._chunk, self._lookahead = float(chunk), min(float(lookahead), float(chunk))
        u0, u_dot0 = float(u0), float(u_dot0)
        self.speed_drive = self.scene.drive == 'speed'
        self.initial_speed = u_dot0 * float(terms.rows(u0)[W])
        self.initial_energy = float(terms.energy(u0, u_dot0))
        self.rest_time = math.nan                   #: time the body stuck at rest (s)
        self.nfev = 0
        scale = terms.dynamics.energy_scale
        state = [u0, 0.0, 0.0] if self.speed_drive else [u0, u_dot0, 0.0, 0.0]
        self._atol = self.tolerance * np.array(
            [1.0, scale, scale] if self.speed_drive else [1.0, max(abs(u_dot0), 1.0),
                                                          scale, scale])
        self._pieces = [_Piece(0.0, 0.0, rest=state)]
        self._sigma = self._direction(u0, u_dot0)
        self._stops = [(0.0, self._sigma)]          # (time, direction of motion from then)

    @property
    def solver(self):
        """'DOP853' (or 'rest' once stuck)."""
        return 'rest' if math.isfinite(self.rest_time) else 'DOP853'

    # -- the equation of motion (arrays or scalars) ---------------------------------------
    def _terms(self, u):
        t = self.terms
        row = t.rows(u)
        n_g = np.sum(t.quantities_from(u, row, 0.0, 0.0)[..., :2], axis=-1)
        return (row[..., M], row[..., DM], row[..., W], row[..., DW],
                t.potential_slope_from(u, row), row[..., K_G], n_g,
                row[..., C2] + row[..., C2 + 1], row[..., CU] + row[..., CU + 1])

    def speed(self, t):
        """The speed drive's Ω(t) (rad/s), t from the stream's start (s)."""
        cmd = self.scene.command
        return cmd + (self.initial_speed - cmd) * np.exp(-np.asarray(t, dtype=float)
                                                          / self.scene.lag)

    def _free(self, u, u_dot, sigma):
        """(ü, Q_drive, dW/dt) for the free or torque-driven equation (σ = sgn u̇)."""
        s = self.scene
        m, dm, w, _, dv, k, n_g, n_2, n_u = self._terms(u)
        q_drive = s.command * w if s.drive == 'torque' else 0.0 * w
        q_damp = -s.damping * w * w * u_dot
        rr = s.rolling_resistance * sigma * k
        u_ddot = (-0.5 * dm * u_dot**2 - dv + q_drive + q_damp - rr * (n_g + n_2 * u_dot**2)) \
            / (m + rr * n_u)
        q_roll = -rr * (n_g + n_2 * u_dot**2 + n_u * u_ddot)
        return u_ddot, q_drive, -(q_damp + q_roll) * u_dot

    def _driven(self, t, u):
        """(u̇, ü, Q_drive, dW/dt) under the speed drive."""
        s = self.scene
        m, dm, w, dw, dv, k, n_g, n_2, n_u = self._terms(u)
        omega = self.speed(t)
        u_dot = omega / w
        u_ddot = ((s.command - omega) / s.lag - dw * u_dot**2) / w
        q_damp = -s.damping * w * w * u_dot
        q_roll = -s.rolling_resistance * np.sign(u_dot) * k * (
            n_g + n_2 * u_dot**2 + n_u * u_ddot)
        q_drive = m * u_ddot + 0.5 * dm * u_dot**2 + dv - q_damp - q_roll
        return u_dot, u_ddot, q_drive, -(q_damp + q_roll) * u_dot

    def _direction(self, u, u_dot):
        """sgn(u̇), or at u̇ = 0 the way the body starts to move (0: it stays at rest)."""
        if u_dot != 0 or self.speed_drive:
            return math.copysign(1.0, u_dot)
        s = self.scene
        m, dm, w, _, dv, k, n_g, _, _ = (float(x) for x in self._terms(u))
        push = (s.command * w if s.drive == 'torque' else 0.0) - dv
        if s.rolling_resistance > 0 and abs(push) <= s.rolling_resistance * k * n_g:
            return 0.0
        return math.copysign(1.0, push) if push else 0.0

    # -- integration ----------------------------------------------------------------------
    def _advance(self, t0, t1, y0):
        """Pieces covering [t0, t1] from state y0 (stops split them)."""
        pieces = []
        while t0 < t1:
            if self._sigma == 0.0 and not self.speed_drive:
                self.rest_time = t0 if math.isnan(self.rest_time) else self.rest_time
                pieces.append(_Piece(t0, math.inf, rest=[y0[0], 0.0, y0[2], y0[3]]))
                return pieces
            if self.speed_drive:
                def rhs(t, y):
                    u_dot, _, q_drive, dw = self._driven(t, y[0])
                    return [u_dot, dw, q_drive * u_dot]
                events = None
            else:
                sigma = self._sigma

                def rhs(t, y):
                    u_ddot, q_drive, dw = self._free(y[0], y[1], sigma)
                    return [y[1], u_ddot, dw, q_drive * y[1]]

                def stop(t, y):
                    return y[1]
                stop.terminal, stop.direction = True, -sigma
                events = [stop] if self.scene.rolling_resistance > 0 else None
            result = solve_ivp(rhs, (t0, t1), y0, method='DOP853', rtol=self.tolerance,
                               atol=self._atol, dense_output=True, events=events)
            if not result.success:
                raise RuntimeError(f'scene integration failed: {result.message}')
            self.nfev += result.nfev
            end = float(result.t[-1])
            pieces.append(_Piece(t0, end, sol=result.sol))
            y0 = [float(x) for x in result.y[:, -1]]
            if result.status == 1:                  # stopped: u̇ = 0
                y0[1] = 0.0
                self._sigma = self._direction(y0[0], 0.0)
                self._stops.append((end, self._sigma))
            t0 = end
        return pieces

    def _states(self, t):
        """The state at times t (s, increasing, not before the window): array (ny, len)."""
        t = np.asarray(t, dtype=float)
        if t.size and t[0] < self._pieces[0].start:
            raise ValueError(f'time {t[0]!r} s is before the stream\'s window (from '
                             f'{self._pieces[0].start!r} s)')
        if t.size:      # keep only the pieces from the one holding t[0]
            first = max(i for i, p in enumerate(self._pieces) if p.start <= t[0])
            self._pieces = self._pieces[first:]
        while t.size and self._pieces[-1].end < t[-1]:
            last = self._pieces[-1]
            end = last.end
            y0 = [float(x) for x in last(np.array([end]))[:, 0]]
            span = min(self._chunk, max(float(t[-1]) - end, self._lookahead))
            self._pieces.extend(self._advance(end, end + span, y0))
        return self.evaluate(t)

    def evaluate(self, t):
        """The state (u, u̇, W, W_d) (speed drive: (u, W, W_d)) at times t (s) inside the
        window already integrated: from the earliest time of the latest call to its end."""
        t = np.asarray(t, dtype=float)
        out = np.empty((3 if self.speed_drive else 4, t.size))
        starts = np.array([p.start for p in self._pieces])
        if t.size and not (t.min() >= starts[0] and t.max() <= self._pieces[-1].end):
            raise ValueError('times outside the integrated window')
        which = np.clip(np.searchsorted(starts, t, side='right') - 1, 0, len(starts) - 1)
        for i in np.unique(which):
            inside = which == i
            out[:, inside] = self._pieces[i](t[inside])
        return out

    def sample(self, t):
        """(u, u̇) at times t (s, increasing, not before earlier calls)."""
        s = self.samples(t)
        return s.phase, s.phase_rate

    def samples(self, t):
        """:class:`SceneSamples` at times t (s, increasing, not before earlier calls)."""
        t = np.asarray(t, dtype=float)
        return self._samples_of(t, self._states(t))

    def samples_at(self, t):
        """:class:`SceneSamples` at times t (s) inside the window (:meth:`evaluate`)."""
        t = np.asarray(t, dtype=float)
        return self._samples_of(t, self.evaluate(t))

    def _samples_of(self, t, y):
        """The samples from the states y at times t, vectorised over the samples."""
        u = y[0]
        if self.speed_drive:
            u_dot, u_ddot, q_drive, _ = self._driven(t, u)
        else:
            u_dot = y[1]
            sigma = self._sigma_at(t, u_dot)
            u_ddot, q_drive, _ = self._free(u, u_dot, sigma)
            u_ddot = np.where(sigma == 0.0, 0.0, u_ddot)
        w = self.terms.rows(u)[..., W]
        return SceneSamples(t=t, phase=u, phase_rate=u_dot, phase_acceleration=u_ddot,
                            energy=self.terms.energy(u, u_dot), dissipated=y[-2],
                            drive_work=y[-1], drive_torque=q_drive / w, power=q_drive * u_dot,
                            rolling_speed=w * u_dot)

    def _sigma_at(self, t, u_dot):
        """sgn u̇, or where u̇ = 0 the direction in force after the last stop before t."""
        times = np.array([time for time, _ in self._stops])
        after = np.array([sigma for _, sigma in self._stops])
        held = after[np.clip(np.searchsorted(times, t, side='right') - 1, 0, len(times) - 1)]
        return np.where(u_dot != 0, np.sign(u_dot), held)


class ClosedSceneStream:
    """The motion of a conservative scene in closed form (:mod:`~twodisk_ros.physics.
    scene_closed`): ``sample``/``samples`` as :class:`SceneStream`, no time stepping."""

    rest_time = math.nan
    nfev = 0

    def __init__(self, terms, solution):
        self.terms, self.scene, self.solution = terms, terms.scene, solution
        self.initial_energy = float(solution.energy) if hasattr(solution, 'energy') else \
            float(terms.energy(*(float(x) for x in solution(0.0))))

    @property
    def solver(self):
        """'quadrature', 'oscillation', 'libration' or 'rest'."""
        return self.solution.name

    def sample(self, t):
        """(u, u̇) at times t (s, increasing)."""
        t = np.asarray(t, dtype=float)
        if isinstance(self.solution, DriftQuadrature) and t.size:
            self.solution.forget_before(float(t[0]))
        u, u_dot = self.solution(t)
        return u, u_dot

    def samples(self, t):
        """:class:`SceneSamples` at times t (s, increasing)."""
        t = np.asarray(t, dtype=float)
        u, u_dot = self.sample(t)
        return self._samples_of(t, u, u_dot)

    def samples_at(self, t):
        """:class:`SceneSamples` at any times t (s) the solution still holds."""
        t = np.asarray(t, dtype=float)
        return self._samples_of(t, *self.solution(t))

    def _samples_of(self, t, u, u_dot):
        m, v, dm, dv, w = np.moveaxis(self.terms.energy_jet(u)[..., :5], -1, 0)
        zero = np.zeros(t.shape)
        return SceneSamples(t=t, phase=u, phase_rate=u_dot,
                            phase_acceleration=-(0.5 * dm * u_dot**2 + dv) / m,
                            energy=0.5 * m * u_dot**2 + v, dissipated=zero, drive_work=zero,
                            drive_torque=zero, power=zero,
                            rolling_speed=w * u_dot)


def scene_stream(dynamics, scene, u0, u_dot0, *, method='table', tolerance=1e-10, terms=None,
                 chunk=10.0, lookahead=0.5):
    """The motion of a scene from (u0 (rad), u̇0 (rad/s)): closed forms where they hold.

    * flat, free, conservative (``Scene()``): today's dynamic MotionStream, bit for bit;
    * speed drive whose command equals the initial speed (Ω₀ = |ω_u(u0)| u̇0, to 1e-12): the
      motion is today's kinematic MotionStream on any slope and with any dissipation (u(t)
      is then kinematic; only the drive torque depends on the scene);
    * conservative on a slope, ``method='table'``: the closed forms of
      :func:`~twodisk_ros.physics.scene_closed.conservative_solution` (rolling on, rocking,
      rest) in a :class:`ClosedSceneStream`;
    * otherwise a :class:`SceneStream` (DOP853; ``terms`` reused if given).
    """
    kwargs = dict(method=method, tolerance=tolerance, chunk=chunk, lookahead=lookahead)
    if scene.flat_free:
        return MotionStream(dynamics, u0, u_dot0, mode='dynamic', **kwargs)
    if scene.drive == 'speed':
        omega0 = float(u_dot0) * float(dynamics.angular_speed_per_phase(u0))
        if abs(omega0 - scene.command) <= 1e-12 * max(abs(omega0), abs(scene.command)) \
                and omega0 != 0:
            return MotionStream(dynamics, u0, u_dot0, mode='kinematic', **kwargs)
    if terms is None:
        terms = SceneTerms(dynamics, scene)
    if scene.conservative and method == 'table':
        solution = conservative_solution(terms, u0, u_dot0)
        if solution is not None:
            return ClosedSceneStream(terms, solution)
    return SceneStream(terms, u0, u_dot0, tolerance=tolerance, chunk=chunk,
                       lookahead=lookahead)


def simulate_scene(terms, t_eval, u0, u_dot0, *, tolerance=1e-10):
    """:class:`SceneSamples` of the general integrator at times ``t_eval`` (s, increasing, ≥ 0)."""
    t_eval = np.asarray(t_eval, dtype=float)
    stream = SceneStream(terms, u0, u_dot0, tolerance=tolerance,
                         chunk=max(float(t_eval[-1]), 1e-3))
    return stream.samples(t_eval)


def settle(terms, u0, u_dot0, *, t_max=600.0, rest_energy=1e-9, step=1.0, tolerance=1e-10):
    """When a dissipative free body comes to rest: (time (s), u (rad), SceneEquilibrium).

    The criterion: the body is at rest when it sticks (rolling resistance: u̇ = 0 with
    |V′ − Q_drive| ≤ μ_r k N, the stop located by DOP853's event to its tolerance), or when
    its energy above the bottom of the well it oscillates in first falls to ``rest_energy``
    × M g L: E(t) − V(u*) = ε M g L (damping alone only approaches u* exponentially; E − V*
    decreases monotonically, so that instant is unique). It is bracketed on a grid of step/8
    s and located by Brent's method on the dense output (to 1e-9 s).
    (nan, nan, None) if not at rest by ``t_max`` s (e.g. it rolls down the slope).
    """
    stable = [eq for eq in terms.equilibria() if eq.stable]
    stream = SceneStream(terms, u0, u_dot0, tolerance=tolerance, chunk=10 * step)
    threshold = rest_energy * terms.dynamics.energy_scale

    def excess(samples):
        """E − V(u*) for the stable equilibrium within π/4 of each sample (J; 1e300 if
        none), and (that equilibrium, its phase)."""
        best, which = np.full(samples.t.shape, 1e300), [None] * samples.t.size
        for eq in stable:
            centre = eq.phase + 2 * math.pi * np.round((samples.phase - eq.phase) / (2 * math.pi))
            gap = samples.energy - terms.potential(centre)
            closer = np.abs(samples.phase - centre) < math.pi / 4
            for i in np.flatnonzero(closer & (gap < best)):
                best[i], which[i] = gap[i], (eq, centre[i])
        return best, which
    t = 0.0
    while t < t_max:
        grid = np.linspace(t, t + step, 9)
        samples = stream.samples(grid)
        gap, which = excess(samples)
        if math.isfinite(stream.rest_time) and stream.rest_time <= grid[-1]:
            rest = stream.samples_at(np.array([stream.rest_time]))
            near = excess(rest)[1][0]
            return stream.rest_time, float(rest.phase[0]), near[0] if near else None
        below = np.flatnonzero(gap <= threshold)
        if below.size:
            i = int(below[0])
            if i == 0:
                return float(grid[0]), float(samples.phase[0]), which[0][0]
            time = brentq(lambda x: float(excess(stream.samples_at(np.array([x])))[0][0])
                          - threshold, grid[i - 1], grid[i], xtol=1e-9)
            return time, float(stream.samples_at(np.array([time])).phase[0]), which[i][0]
        t = grid[-1]
    return math.nan, math.nan, None


def first_failure(terms, samples, stream=None, *, resolution=0.01):
    """Where the rolling model first fails along sampled motion: lift-off or slip.

    Returns a :class:`~twodisk_ros.physics.contact_validity.ValidityReport`, forces with the
    tilted gravity. Without ``stream`` the time is the first sample at which N_A < 0, N_B < 0
    or μ_required > the scene's friction (the sampling's resolution: a short lift-off
    between two samples is missed). With the stream that produced ``samples`` (its latest
    call; a SceneStream or ClosedSceneStream) the dense output is scanned between the
    samples, every ``resolution`` rad of u at most, up to the first failing sample, and the
    first sign change of N_A, N_B or μ − μ_required is located by Brent's method (to
    1e-12 s); ``index`` is then the first sample after it.
    """
    friction = terms.scene.friction
    forces = terms.forces(samples.phase, samples.phase_rate, samples.phase_acceleration)
    report = check_validity(samples.t, forces, friction)
    if not hasattr(stream, 'samples_at') or samples.t.size < 2:
        return report
    last = samples.t.size - 1 if report.valid else report.index
    t, u = samples.t[:last + 1], samples.phase[:last + 1]
    pieces = np.maximum(1, np.ceil(np.abs(np.diff(u)) / resolution)).astype(int)
    fine = np.concatenate([np.linspace(a, b, k, endpoint=False)
                           for a, b, k in zip(t[:-1], t[1:], pieces)] + [t[-1:]])
    names = ['lift-off A', 'lift-off B'] + ([] if math.isinf(friction) else ['slip'])

    def margins(times):
        s = stream.samples_at(np.atleast_1d(times))
        f = terms.forces(s.phase, s.phase_rate, s.phase_acceleration)
        out = [f.normal_a, f.normal_b]
        if 'slip' in names:
            out.append(np.clip(friction - f.mu_required, -1e300, 1e300))
        return np.stack(out)
    bad = np.flatnonzero(np.any(margins(fine) < 0, axis=0))
    if bad.size == 0 or bad[0] == 0:
        return report
    low, high = float(fine[bad[0] - 1]), float(fine[bad[0]])
    before, after = margins(low)[:, 0], margins(high)[:, 0]
    roots = [(brentq(lambda x, k=k: float(margins(x)[k, 0]), low, high, xtol=1e-12), names[k])
             for k in range(len(names)) if before[k] >= 0 > after[k]]
    time, kind = min(roots)
    index = int(np.searchsorted(samples.t, time))
    if kind == 'slip':
        reason = (f'the body would slip at t = {time:.9g} s: mu_required reaches mu = '
                  f'{friction:g}')
    else:
        reason = f'contact {kind[-1]} would lift off at t = {time:.9g} s: N_{kind[-1]} = 0'
    return ValidityReport(False, time, index, kind, reason)

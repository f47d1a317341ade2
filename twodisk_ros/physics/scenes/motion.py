"""Motion in a scene: the general integrator over the phase u (docs/physics.md#scenes).

The configuration is still a function of u (rolling is exact on any plane), so every scene
is the 1-DOF equation of motion (SI units, Q the generalised forces, J/rad):

    m(u) ü + ½ m′(u) u̇² + V′(u) = Q_drive + Q_damping + Q_rolling,

* V(u) = M g (h cos β − s sin β) on a slope (:mod:`~twodisk_ros.physics.scenes.terms`);
* torque drive: a moment τ ê about the axis AB, Q = τ (ω_u·ê) = τ |ω_u| (ω_u ∥ ê, ω_u·ê > 0);
* damping, a moment −c ω: Q = −c |ω_u|² u̇;
* rolling resistance, a moment μ_r N ρ about AB opposing the rotation (N = N_A + N_B, ρ the
  distance of G from AB, so ρ |ω_u| = |dG/du| =: k): Q = −μ_r k N sgn(u̇). N depends on ü
  (N = N_g + N_2 u̇² + N_ü ü), so ü solves a linear equation;
* speed drive: the signed rolling speed Ω = |ω_u| u̇ follows the command by the first-order
  lag Ω(t) = Ω_cmd + (Ω₀ − Ω_cmd) e^{−t/T}; then u̇ = Ω/|ω_u| and the drive supplies
  Q_drive = m ü + ½ m′ u̇² + V′ − Q_damping − Q_rolling, i.e. the torque Q_drive/|ω_u| about AB
  and the power Q_drive u̇.

**Regular form.** Where the body stops turning in u (|ω_u| = 0, m = 0: a flat vertex) u̇ is
infinite for an instant and the equation above is singular. With w = |ω_u| u̇ the angular
speed about AB (rad/s, finite), J = m/|ω_u|² the moment of inertia about AB (> 0), ρ as
above, and the regularised time τ, dt/dτ = |ω_u| (as
:class:`~twodisk_ros.physics.motion.solvers.SundmanSolution`):

    du/dτ = w,   (J + μ_r ρ σ N_ẇ) dw/dτ = −½ J′ w² − |ω_u| V_γ + Q_drive + Q_damping
                                          − μ_r ρ σ (|ω_u| N_g + N_w w²),

with V_γ = dV/dγ = V′/|ω_u| (regular), Q_drive = τ |ω_u|, Q_damping = −c |ω_u| w, σ = sgn w
and N = N_g + N_ẇ ẇ + N_w w²/|ω_u| the normal sum of
:mod:`~twodisk_ros.physics.forces.terms` (Q_a, P): |ω_u| N is regular, so every term is.
The speed drive prescribes w = Ω(t): du/dτ = Ω, and the drive's Q follows as above.

The state carries the dissipated work W (J, ≥ 0) and the drive's work W_d (J), so that
E(t) + W(t) − W_d(t) = E₀ (E = ½ J w² + V) is the energy balance: DOP853 (scipy, dense
output) integrates (u, w, W, W_d, t) in τ (speed drive: (u, W, W_d, t)), dW/dτ =
−(Q_damping + Q_rolling) w, dW_d/dτ = Q_drive w. Rolling resistance switches sign with w, so
each stretch between two stops (w = 0) is integrated on its own, and at a stop the body
stays at rest if |V_γ − τ| ≤ μ_r ρ N_g (it sticks: the time to rest is exact). A start
from rest exactly where |ω_u| = 0 (t(τ) would not advance) takes its first 1e-3 rad of u in
closed form (:data:`LEAVE_STOP`). Where the flat fast paths hold (:func:`scene_stream`)
the plain :class:`~twodisk_ros.physics.motion.simulate.MotionStream` is used unchanged, and a
conservative scene on a slope has the closed forms of
:mod:`~twodisk_ros.physics.scenes.closed` (:class:`ClosedSceneStream`).
"""

import math

import numpy as np

from ..motion.simulate import MotionStream
from .closed import conservative_solution
from ..bodies.cycle import TWO_PI
from .samples import Piece, SceneSamples, samples_from
from ..motion.solvers import import_integrator
from .terms import DJ, DW, J, PW, QA, RHO, SceneTerms, W

#: a start from rest where |ω_u| is below this fraction of its largest value is taken in
#: closed form over its first 1e-3 rad of u (SceneStream._leave_stop): t(τ) barely advances
LEAVE_STOP = 1e-6

__all__ = ['ClosedSceneStream', 'SceneStream', 'SceneSamples', 'scene_stream']


class SceneStream:
    """Samples of a scene's motion at increasing times (DOP853, lazily in segments).

    The state is (u, w, W, W_d), w = |ω_u| u̇ the angular speed about AB (rad/s), finite also
    where the body stops turning in u (speed drive: w = Ω(t) is known, the state is
    (u, W, W_d)). The independent variable is the regularised time τ, dt/dτ = |ω_u| (module
    docstring), regular also where |ω_u| vanishes (a flat vertex); t is the last component of
    the integrated state and samples are located in τ by safeguarded Newton.

    Parameters
    ----------
    terms : SceneTerms
    u0, u_dot0 : float
        Initial phase (rad) and phase rate (rad/s).
    tolerance : float
        rtol of DOP853 (atol = tolerance × the state's scale).
    chunk, lookahead : float
        As :class:`~twodisk_ros.physics.motion.simulate.MotionStream`: segments of at most ``chunk``
        s, reaching ``lookahead`` s beyond the times asked.
    angular_speed : float, optional
        w0 (rad/s) instead of u̇0 (which is then ignored): the start where |ω_u(u0)| = 0.

    The dense output of every segment reaching back to the earliest time of the latest
    call is kept, so :meth:`evaluate` gives the state at any time of that window (the root
    finding of :func:`~.scene_events.first_failure` and :func:`~.scene_events.settle`).
    """

    def __init__(self, terms, u0, u_dot0, *, tolerance=1e-10, chunk=10.0, lookahead=0.5,
                 angular_speed=None):
        if not isinstance(terms, SceneTerms):
            raise TypeError(f'terms must be a SceneTerms, got {type(terms).__name__}')
        self.terms, self.scene, self.tolerance = terms, terms.scene, float(tolerance)
        import_integrator()
        self._chunk, self._lookahead = float(chunk), min(float(lookahead), float(chunk))
        u0 = float(u0)
        w0 = float(angular_speed) if angular_speed is not None else \
            float(u_dot0) * float(terms.rows(u0)[W])
        self.speed_drive = self.scene.drive == 'speed'
        self._mean_rate = float(np.mean(terms.rows(TWO_PI * np.arange(64) / 64)[:, W]))
        self.initial_speed = w0
        self.initial_energy = float(terms.energy_turning(u0, w0))
        self.rest_time = math.nan                   #: time the body stuck at rest (s)
        self.nfev = 0
        scale = terms.dynamics.energy_scale
        state = [u0, 0.0, 0.0] if self.speed_drive else [u0, w0, 0.0, 0.0]
        self._atol = self.tolerance * np.array(
            [1.0, scale, scale] if self.speed_drive else [1.0, max(abs(w0), 1.0),
                                                          scale, scale])
        self._pieces = [Piece(0.0, 0.0, rest=state)]
        self._sigma = self._direction(u0, w0, 0.0)
        self._stops = [(0.0, self._sigma)]          # (time, direction of motion from then)

    @property
    def solver(self):
        """'DOP853' (or 'rest' once stuck)."""
        return 'rest' if math.isfinite(self.rest_time) else 'DOP853'

    # -- the equation of motion per unit τ (arrays or scalars) ---------------------------
    def _terms(self, u):
        """J, J′, |ω_u|, |ω_u|′, dV/dγ, ρ, N_g, N per w², N per ẇ at phase(s) u."""
        t = self.terms
        row = t.rows(u)
        q = t.quantities_from(u, row, 0.0, 0.0)
        n_g = q[..., 0] + q[..., 1]             # N_A + N_B (np.sum's arithmetic for two)
        return (row[..., J], row[..., DJ], row[..., W], row[..., DW],
                t.potential_turn_slope_from(u, row), row[..., RHO], n_g,
                row[..., PW] + row[..., PW + 1], row[..., QA] + row[..., QA + 1])

    def speed(self, t):
        """The speed drive's Ω(t) (rad/s), t from the stream's start (s)."""
        cmd = self.scene.command
        return cmd + (self.initial_speed - cmd) * np.exp(-np.asarray(t, dtype=float)
                                                          / self.scene.lag)

    def _free(self, u, w, sigma):
        """(dw/dτ, Q_drive, dW/dτ, |ω_u|) of the free or torque-driven equation (σ = sgn w);
        Q per unit u (J/rad), d/dτ = |ω_u| d/dt."""
        s = self.scene
        j, dj, rate, _, dv, rho, n_g, n_2, n_w = self._terms(u)
        q_drive = s.command * rate if s.drive == 'torque' else 0.0 * rate
        q_damp = -s.damping * rate * w
        rr = s.rolling_resistance * sigma * rho
        w_tau = (-0.5 * dj * w**2 - rate * dv + q_drive + q_damp - rr * (
            rate * n_g + n_2 * w**2)) / (j + rr * n_w)
        q_roll = -rr * (rate * n_g + n_2 * w**2 + n_w * w_tau)
        return w_tau, q_drive, -(q_damp + q_roll) * w, rate

    def _driven(self, t, u):
        """(w, dw/dτ, Q_drive, dW/dτ, |ω_u|) under the speed drive."""
        s = self.scene
        j, dj, rate, _, dv, rho, n_g, n_2, n_w = self._terms(u)
        w = self.speed(t)
        w_tau = rate * (s.command - w) / s.lag
        q_damp = -s.damping * rate * w
        q_roll = -s.rolling_resistance * np.sign(w) * rho * (
            rate * n_g + n_2 * w**2 + n_w * w_tau)
        q_drive = j * w_tau + 0.5 * dj * w**2 + rate * dv - q_damp - q_roll
        return w, w_tau, q_drive, -(q_damp + q_roll) * w, rate

    def _direction(self, u, w, t):
        """sgn w, or at w = 0 the way the body starts to move (0: it stays at rest)."""
        if w != 0 or self.speed_drive:
            return math.copysign(1.0, w)
        s = self.scene
        j, _, _, _, dv, rho, n_g, _, _ = (float(x) for x in self._terms(u))
        push = (s.command if s.drive == 'torque' else 0.0) - dv        # per unit γ (N m)
        if s.rolling_resistance > 0 and abs(push) <= s.rolling_resistance * rho * n_g:
            return 0.0
        return math.copysign(1.0, push) if push else 0.0

    # -- integration ----------------------------------------------------------------------
    def _leave_stop(self, t0, y0):
        """A start from w = 0 where |ω_u| = 0: (piece, state) over the first instants.

        There t(τ) does not advance, so the first 1e-3 rad of u are taken in closed form:
        with the angular acceleration a at rest, γ − γ0 = ½ a t² to O(t³), and as γ − γ0 ∝
        (u − u0)³ near the stop, u − u0 ∝ t^{2/3}; the works to the same order."""
        s, u0, sigma = self.scene, y0[0], self._sigma
        j, _, _, _, dv, rho, n_g, _, n_w = (float(x) for x in self._terms(u0))
        if self.speed_drive:
            accel = (s.command - float(self.speed(t0))) / s.lag
        else:
            torque = (s.command if s.drive == 'torque' else 0.0) - dv
            rr = s.rolling_resistance * sigma * rho
            accel = (torque - rr * n_g) / (j + rr * n_w)
        step = math.copysign(1e-3, accel)
        nodes, weights = np.polynomial.legendre.leggauss(8)
        points = u0 + 0.5 * step * (nodes + 1)
        turn = 0.5 * abs(step) * float(np.sum(weights * self.terms.rows(points)[:, W]))
        duration = math.sqrt(2 * turn / abs(accel))
        w1 = accel * duration
        dissipated = (s.damping * accel**2 * duration**3 / 3
                      + s.rolling_resistance * rho * n_g * abs(w1) * duration / 2)
        drive = (s.command * math.copysign(turn, step) if s.drive == 'torque' else
                 self.terms.energy_turning(u0 + step, w1) - self.terms.energy_turning(u0, 0.0)
                 + dissipated if self.speed_drive else 0.0)
        end = ([u0 + step, y0[-3] + dissipated, y0[-2] + drive] if self.speed_drive else
               [u0 + step, w1, y0[-3] + dissipated, y0[-2] + drive])
        end.append(t0 + duration)
        begin = np.asarray(y0, dtype=float)
        stop = np.asarray(end, dtype=float)

        def state(t):
            x = np.clip((np.asarray(t, dtype=float) - t0) / duration, 0.0, 1.0)
            out = begin[:, None] + (stop - begin)[:, None] * x**3
            out[0] = u0 + step * x ** (2.0 / 3.0)
            if not self.speed_drive:
                out[1] = w1 * x
            return out[:-1]
        return Piece(t0, t0 + duration, start_of=state), [float(x) for x in end]

    def _advance(self, t0, t1, y0):
        """Pieces covering [t0, t1] from state y0 (stops split them)."""
        from scipy.integrate import solve_ivp
        pieces = []
        y0 = list(y0) + [t0]
        while t0 < t1:
            if self._sigma == 0.0 and not self.speed_drive:
                self.rest_time = t0 if math.isnan(self.rest_time) else self.rest_time
                pieces.append(Piece(t0, math.inf, rest=[y0[0], 0.0, y0[2], y0[3]]))
                return pieces
            w_start = float(self.speed(t0)) if self.speed_drive else y0[1]
            if w_start == 0 and float(self.terms.rows(y0[0])[W]) <= \
                    LEAVE_STOP * self.terms.turn_scale:
                piece, y0 = self._leave_stop(t0, y0)
                pieces.append(piece)
                t0 = piece.end
                continue
            if self.speed_drive:
                def rhs(tau, y):
                    w, _, q_drive, dw, rate = self._driven(y[-1], y[0])
                    return [w, dw, q_drive * w, rate]
                events = []
            else:
                sigma = self._sigma

                def rhs(tau, y):
                    w_tau, q_drive, dw, rate = self._free(y[0], y[1], sigma)
                    return [y[1], w_tau, dw, q_drive * y[1], rate]

                def stop(tau, y):
                    return y[1]
                stop.terminal, stop.direction = True, -sigma
                events = [stop] if self.scene.rolling_resistance > 0 else []
            def reached(tau, y):
                return y[-1] - t1
            reached.terminal = True
            events = events + [reached]
            span = (0.0, 4.0 * (t1 - t0) / self._mean_rate + 1.0)
            atol = np.append(self._atol, self.tolerance * max(1.0, t1))
            result = solve_ivp(rhs, span, y0, method='DOP853', rtol=self.tolerance,
                               atol=atol, dense_output=True, events=events or None)
            if not result.success:
                raise RuntimeError(f'scene integration failed: {result.message}')
            self.nfev += result.nfev
            y_end = [float(x) for x in result.y[:, -1]]
            end = y_end[-1]
            if result.status == 1 and result.t_events[-1].size:
                end = y_end[-1] = t1               # reached t1 (to the event's rounding)
            pieces.append(Piece(t0, end, sol=result.sol, rate=lambda u: self.terms.rows(
                u)[..., W], steps=(result.t, result.y[-1])))
            y0 = y_end
            stopped = result.status == 1 and not self.speed_drive and \
                result.t_events[0].size > 0 and self.scene.rolling_resistance > 0
            if stopped:                             # w = 0
                y0[1] = 0.0
                self._sigma = self._direction(y0[0], 0.0, end)
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
        return self.state(t)

    def state(self, t):
        """The state (u, w, W, W_d) (speed drive: (u, W, W_d)) at times t (s) inside the
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

    def evaluate(self, t):
        """The state (u, u̇, W, W_d) (speed drive: (u, W, W_d)) at times t (s) inside the
        window (:meth:`state`; u̇ = w/|ω_u| is inf where the body stops turning in u)."""
        y = self.state(t)
        if not self.speed_drive:
            with np.errstate(divide='ignore', invalid='ignore'):
                y[1] = y[1] / self.terms.rows(y[0])[..., W]
        return y

    def sample(self, t):
        """(u, u̇) at times t (s, increasing, not before earlier calls)."""
        s = self.samples(t)
        return s.phase, s.phase_rate

    def samples(self, t):
        """:class:`SceneSamples` at times t (s, increasing, not before earlier calls)."""
        t = np.asarray(t, dtype=float)
        return self._samples_of(t, self._states(t))

    def samples_at(self, t):
        """:class:`SceneSamples` at times t (s) inside the window (:meth:`state`)."""
        t = np.asarray(t, dtype=float)
        return self._samples_of(t, self.state(t))

    def _samples_of(self, t, y):
        """The samples from the states y at times t, vectorised over the samples."""
        u = y[0]
        if self.speed_drive:
            w, w_tau, q_drive, _, rate = self._driven(t, u)
        else:
            w = y[1]
            sigma = self._sigma_at(t, w)
            w_tau, q_drive, _, rate = self._free(u, w, sigma)
            w_tau = np.where(sigma == 0.0, 0.0, w_tau)
        return samples_from(self.terms, t, u, w, w_tau, rate, y[-2], y[-1], q_drive)

    def _sigma_at(self, t, w):
        """sgn w, or where w = 0 the direction in force after the last stop before t."""
        times = np.array([time for time, _ in self._stops])
        after = np.array([sigma for _, sigma in self._stops])
        held = after[np.clip(np.searchsorted(times, t, side='right') - 1, 0, len(times) - 1)]
        return np.where(w != 0, np.sign(w), held)


class FreeSceneStream(MotionStream):
    """The flat, free, conservative scene's motion: the level ground's
    :class:`~twodisk_ros.physics.motion.simulate.MotionStream` (its closed forms, or DOP853 in
    t or τ), sampled also as a scene (:meth:`samples`, as :class:`SceneStream`)."""

    rest_time = math.nan

    def __init__(self, dynamics, scene, u0, u_dot0, *, terms=None, **kwargs):
        super().__init__(dynamics, u0, u_dot0, mode='dynamic', **kwargs)
        self.scene, self._terms = scene, terms

    @property
    def terms(self):
        """The scene's :class:`~twodisk_ros.physics.scenes.terms.SceneTerms` (built on first
        use: :meth:`sample` does not need them)."""
        if self._terms is None:
            self._terms = SceneTerms(self.dynamics, self.scene)
        return self._terms

    def samples(self, t):
        """:class:`SceneSamples` at times t (s, increasing, not before earlier calls)."""
        t = np.asarray(t, dtype=float)
        u, _, w = self.sample_with_speed(t)
        jet = self.terms.energy_jet(u)
        w_tau = -(0.5 * jet[..., 8] * w**2 + jet[..., 3]) / jet[..., 7]
        zero = np.zeros(t.shape)
        return samples_from(self.terms, t, u, w, w_tau, jet[..., 4], zero, zero, zero)


class ClosedSceneStream:
    """The motion of a conservative scene in closed form (:mod:`~twodisk_ros.physics.
    scenes.closed`): ``sample``/``samples`` as :class:`SceneStream`, no time stepping."""

    rest_time = math.nan
    nfev = 0

    def __init__(self, terms, solution):
        self.terms, self.scene, self.solution = terms, terms.scene, solution
        self.initial_energy = solution.initial_energy(terms.energy_turning, self._turn_rate)

    @property
    def solver(self):
        """'quadrature', 'oscillation', 'libration' or 'rest'."""
        return self.solution.name

    def sample(self, t):
        """(u, u̇) at times t (s, increasing); u̇ is inf where the body stops turning in u.

        Straight from the solution (one read of the narrow energy table at most), without
        the wide table :meth:`samples` reads for ü and the energies."""
        t = np.asarray(t, dtype=float)
        if t.size:
            self.solution.forget_before(float(t[0]))
        u, u_dot = self.solution(t)
        return u, u_dot

    def _turn_rate(self, u):
        """|ω_u| (rad per rad of u) at phases u, from the scene's energy jet."""
        return self.terms.energy_jet(u)[..., 4]

    def state(self, t):
        """(u, w) at times t (s): the phase and the angular speed about AB (rad/s)."""
        return self.solution.state(np.asarray(t, dtype=float), self._turn_rate)

    def samples(self, t):
        """:class:`SceneSamples` at times t (s, increasing)."""
        t = np.asarray(t, dtype=float)
        if t.size:
            self.solution.forget_before(float(t[0]))
        return self._samples_of(t, *self.state(t))

    def samples_at(self, t):
        """:class:`SceneSamples` at any times t (s) the solution still holds."""
        t = np.asarray(t, dtype=float)
        return self._samples_of(t, *self.state(t))

    def _samples_of(self, t, u, w):
        jet = self.terms.energy_jet(u)
        w_tau = -(0.5 * jet[..., 8] * w**2 + jet[..., 3]) / jet[..., 7]
        zero = np.zeros(t.shape)
        return samples_from(self.terms, t, u, w, w_tau, jet[..., 4], zero, zero, zero)


def scene_stream(dynamics, scene, u0, u_dot0, *, method='table', tolerance=1e-10, terms=None,
                 chunk=10.0, lookahead=0.5, angular_speed=None):
    """The motion of a scene from (u0 (rad), u̇0 (rad/s)): closed forms where they hold.

    ``angular_speed`` w0 = |ω_u(u0)| u̇0 (rad/s) replaces u̇0 if given: the one form of the
    start where the body stops turning in u (u̇0 infinite).

    * flat, free, conservative (``Scene()``): the level ground's dynamic MotionStream, bit
      for bit, with the scene's samples (:class:`FreeSceneStream`);
    * speed drive whose command equals the initial speed (Ω₀ = w0, to 1e-12): the
      motion is the plain kinematic MotionStream on any slope and with any dissipation (u(t)
      is then kinematic; only the drive torque depends on the scene);
    * conservative on a slope, ``method='table'``: the closed forms of
      :func:`~twodisk_ros.physics.scenes.closed.conservative_solution` (rolling on, rocking,
      rest) in a :class:`ClosedSceneStream`;
    * otherwise a :class:`SceneStream` (DOP853 in t, or in τ where the body stops turning in
      u; ``terms`` reused if given).
    """
    kwargs = dict(method=method, tolerance=tolerance, chunk=chunk, lookahead=lookahead)
    rate0 = float(dynamics.angular_speed_per_phase(u0))
    omega0 = float(angular_speed) if angular_speed is not None else float(u_dot0) * rate0
    if angular_speed is not None:
        kwargs['angular_speed'] = omega0
    if scene.flat_free:
        return FreeSceneStream(dynamics, scene, u0, u_dot0, terms=terms, **kwargs)
    if scene.drive == 'speed':
        if abs(omega0 - scene.command) <= 1e-12 * max(abs(omega0), abs(scene.command)) \
                and omega0 != 0:
            return MotionStream(dynamics, u0, u_dot0, mode='kinematic', **kwargs)
    if terms is None:
        terms = SceneTerms(dynamics, scene)
    if scene.conservative and method == 'table':
        solution = conservative_solution(terms, u0, None, angular_speed=omega0)
        if solution is not None:
            return ClosedSceneStream(terms, solution)
    return SceneStream(terms, u0, None, tolerance=tolerance, chunk=chunk,
                       lookahead=lookahead, angular_speed=omega0)

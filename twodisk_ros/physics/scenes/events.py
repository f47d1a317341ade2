"""When a scene's motion ends or fails: time to rest and the first lift-off or slip.

Both read the dense output of a :class:`~twodisk_ros.physics.scenes.motion.SceneStream` or
:class:`~twodisk_ros.physics.scenes.motion.ClosedSceneStream` (``samples_at``) and locate the
instant by Brent's method (docs/physics.md#scenes). Re-exported by scenes.motion.
"""

import math

import numpy as np

from ..forces.validity import ValidityReport, check_validity

__all__ = ['settle', 'first_failure']


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
    from scipy.optimize import brentq
    stable = [eq for eq in terms.equilibria() if eq.stable]
    from .motion import SceneStream
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


def _forces(terms, samples):
    """The scene's forces along samples, from (u, w, ẇ) where the samples carry ẇ (finite
    where the body stops turning in u), else from (u, u̇, ü)."""
    if samples.angular_acceleration is not None:
        return terms.forces(samples.phase, samples.rolling_speed,
                            samples.angular_acceleration, turning=True)
    return terms.forces(samples.phase, samples.phase_rate, samples.phase_acceleration)


def first_failure(terms, samples, stream=None, *, resolution=0.01):
    """Where the rolling model first fails along sampled motion: lift-off or slip.

    Returns a :class:`~twodisk_ros.physics.forces.validity.ValidityReport`, forces with the
    tilted gravity. Without ``stream`` the time is the first sample at which N_A < 0, N_B < 0
    or μ_required > the scene's friction (the sampling's resolution: a short lift-off
    between two samples is missed). With the stream that produced ``samples`` (its latest
    call; a SceneStream or ClosedSceneStream) the dense output is scanned between the
    samples, every ``resolution`` rad of u at most, up to the first failing sample, and the
    first sign change of N_A, N_B or μ − μ_required is located by Brent's method (to
    1e-12 s); ``index`` is then the first sample after it.
    """
    from scipy.optimize import brentq
    friction = terms.scene.friction
    forces = _forces(terms, samples)
    report = check_validity(samples.t, forces, friction)
    if stream is None or samples.t.size < 2:
        return report
    last = samples.t.size - 1 if report.valid else report.index
    t, u = samples.t[:last + 1], samples.phase[:last + 1]
    pieces = np.maximum(1, np.ceil(np.abs(np.diff(u)) / resolution)).astype(int)
    fine = np.concatenate([np.linspace(a, b, k, endpoint=False)
                           for a, b, k in zip(t[:-1], t[1:], pieces)] + [t[-1:]])
    names = ['lift-off A', 'lift-off B'] + ([] if math.isinf(friction) else ['slip'])

    def margins(times):
        s = stream.samples_at(np.atleast_1d(times))
        f = _forces(terms, s)
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

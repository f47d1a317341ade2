"""Where the rolling model of the two-disk body holds: lift-off and slip.

The model assumes both contacts stay on the ground without slipping. It fails where a normal
force would have to pull (N_A < 0 or N_B < 0: lift-off) or where the ground's friction
coefficient μ is below μ_required (slip). Forces come from
:class:`twodisk_ros.physics.forces.contact.ContactForceModel`; units are SI (s, rad/s, N, J).
The derivation is in docs/physics.md, section "Contact forces".
"""

from dataclasses import dataclass
from functools import partial
import math

import numpy as np

from ..bodies.cycle import TWO_PI
from .contact import QUANTITIES, squeeze_split
from ..numerics.spectral import real_spectral_derivative
from ..numerics.tables import hermite_jet
from ..motion.turning import turning_points

__all__ = ['ValidityReport', 'check_validity', 'motion_validity', 'liftoff_speed',
           'liftoff_speed_batch', 'mu_required_kinematic', 'mu_required_kinematic_batch',
           'mu_required_dynamic']

_STRIDE = len(QUANTITIES) + 1   # kinematic columns: A (6 + ẇ), C (6 + ẇ), s = dγ/dy, …


@dataclass(frozen=True)
class ValidityReport:
    """Where the rolling model first fails along a motion (or that it never does)."""

    valid: bool
    time: float     #: time of the first failing sample (s); nan if valid
    index: int      #: its sample index; −1 if valid
    kind: str       #: 'lift-off A', 'lift-off B', 'slip' or ''
    reason: str     #: one sentence, e.g. 'contact B would lift off at t = 2.31 s: N_B = -0.4 N'


def check_validity(times, forces, mu=math.inf):
    """First sample at which a contact lifts off (N < 0) or slips (μ_required > μ).

    Parameters
    ----------
    times : array_like
        Sample times (s), one per state of ``forces`` (flattened in the same order).
    forces : ContactForces
    mu : float
        Friction coefficient of the ground, ≥ 0 (inf: no slip ever).

    Returns
    -------
    ValidityReport
        The time resolution is the sampling: the reported time is the first bad sample's.
        Lift-off is reported before slip at the same sample (μ_required is inf there).
    """
    mu = float(mu)
    if not mu >= 0:
        raise ValueError(f'mu must be >= 0 (inf allowed), got {mu!r}')
    t = np.asarray(times, dtype=float).ravel()
    n_a, n_b = forces.normal_a.ravel(), forces.normal_b.ravel()
    need = forces.mu_required.ravel()
    if not (t.size == n_a.size):
        raise ValueError(f'times has {t.size} samples, forces {n_a.size}')
    bad = (n_a < 0) | (n_b < 0) | (need > mu)
    if not np.any(bad):
        return ValidityReport(True, math.nan, -1, '', f'rolling holds for t in '
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
    """:func:`check_validity` along a simulated :class:`RollingMotion`: (report, forces)."""
    forces = model.along(motion)
    return check_validity(motion.t, forces, mu), forces


def liftoff_speed(model):
    """Critical |ω| (rad/s) above which a contact lifts off in kinematic motion.

    In kinematic mode N(u; Ω) = N0(u) + Ω² C_N(u)/s(u) exactly (s = dγ/dy ≥ 0, forces.terms),
    so Ω_c² = min over u and both contacts of −N0 s/C_N where C_N < 0 (Ω_c = 0 if N0 ≤ 0
    somewhere: the drive holding the body at rest already lifts a contact; Ω_c = 0 also
    where the body stops turning on a flat vertex with C_N < 0: the force there is −∞ at any
    speed). The minimum is located on the table nodes and refined by bounded Brent on the
    interpolated tables (to ~1e-12 rad in u).

    Parameters
    ----------
    model : ContactForceModel

    Returns
    -------
    speed : float
        Ω_c (rad/s); inf if no speed lifts a contact off.
    phase : float
        u (rad, in [0, 2π)) where the first contact lifts off.
    contact : str
        'A' or 'B' ('' if never).
    """
    from scipy.optimize import minimize_scalar
    u = model.terms.u                               # the phases of the table's nodes
    cols = model.coefficients(u)
    best = (math.inf, math.nan, '')
    for j, name in ((0, 'A'), (1, 'B')):
        n0, n2, s = cols[:, j], cols[:, _STRIDE + j], cols[:, 2 * _STRIDE]
        if np.any(n0 <= 0):
            return 0.0, float(u[np.argmin(n0)] % TWO_PI), name
        # Ω² = −N0 s / C_N where C_N < 0: smooth, 0 where a flat vertex lifts the contact
        ratio = np.where(n2 < 0, -n0 * np.maximum(s, 0.0) / np.where(n2 < 0, n2, -1.0),
                         np.inf)
        i = int(np.argmin(ratio))
        if not np.isfinite(ratio[i]):
            continue
        if ratio[i] == 0.0:
            return 0.0, float(u[i] % TWO_PI), name

        def square(x, j=j):
            c = model.coefficients(x)
            return -c[j] * c[2 * _STRIDE] / c[_STRIDE + j] if c[_STRIDE + j] < 0 else math.inf
        low, high = u[i - 1] if i else u[-1] - TWO_PI, u[(i + 1) % len(u)] + (
            TWO_PI if i + 1 == len(u) else 0.0)
        res = minimize_scalar(square, bounds=(low, high), method='bounded',
                              options={'xatol': 1e-12})
        value, phase = (float(res.fun), float(res.x)) if res.fun <= ratio[i] else (
            float(ratio[i]), float(u[i]))
        if value < best[0] ** 2:
            best = (math.sqrt(max(value, 0.0)), phase % TWO_PI, name)
    return best


def liftoff_speed_batch(n0, n2, iterations=6):
    """:func:`liftoff_speed` of B bodies from their kinematic normal forces at the nodes.

    Parameters
    ----------
    n0, n2 : ndarray, shape (2, N, B)
        N_A, N_B = N0 + Ω² N2 at u_j = 2πj/N (:func:`~twodisk_ros.physics.forces.contact.
        kinematic_coefficients`, the model's table nodes).
    iterations : int
        Newton steps of the refinement.

    Returns
    -------
    ndarray, shape (B,)
        Ω_c (rad/s): 0 where N0 ≤ 0 at a node (a contact already lifts at rest), inf where
        N2 < 0 nowhere, else √(min −N0/N2) over the cycle and both contacts.

    Notes
    -----
    As :func:`liftoff_speed`: the smallest ratio −N0/N2 on the nodes, refined on the
    quintic Hermite interpolant of the tables (spectral f′ and f″ at the nodes) within one
    node spacing of it. The refinement is Newton's method on the interpolant (exact slope and
    curvature of the quintic, steps kept inside the two intervals), the best value found
    kept; this reaches the interpolant's minimum to rounding where the scalar path's bounded
    Brent stops at 1e-12 rad.
    """
    n, bodies = n0.shape[1:]
    columns = np.concatenate([n0, n2])                          # (4, N, B)
    step = TWO_PI / n
    first = real_spectral_derivative(columns, axis=1) * step
    second = real_spectral_derivative(first, axis=1) * step
    with np.errstate(divide='ignore', invalid='ignore'):
        ratio = np.where(n2 < 0, -n0 / np.where(n2 < 0, n2, -1.0), np.inf)
    best = np.full(bodies, np.inf)
    index = np.arange(bodies)
    for j in range(2):
        i = np.argmin(ratio[j], axis=0)
        value = ratio[j, i, index]
        some = np.isfinite(value)                # N2 < 0 at some node (else never lifts)
        x = np.zeros(bodies)                     # offset from node i, in node spacings
        for _ in range(iterations):
            left = x < 0
            node = np.where(left, i - 1, i) % n
            t = np.where(left, x + 1.0, x)
            jets = [hermite_jet(t, [a[col, node, index] for a in (columns, first, second)],
                                [a[col, (node + 1) % n, index] for a in (columns, first,
                                                                        second)])
                    for col in (j, 2 + j)]
            (f0, d0, s0), (f2, d2, s2) = jets
            with np.errstate(divide='ignore', invalid='ignore'):
                q = -f0 / f2                     # N2 q = −N0, differentiated twice
                dq = (-d0 - q * d2) / f2
                ddq = (-s0 - 2 * dq * d2 - q * s2) / f2
                value = np.where(some & (f2 < 0) & (q < value), q, value)
                move = np.where(ddq > 0, -dq / ddq, 0.0)
            x = np.clip(x + np.where(np.isfinite(move), move, 0.0), -1.0, 1.0)
        best = np.minimum(best, value)
    lifted = np.any(n0 <= 0, axis=(0, 1))
    with np.errstate(invalid='ignore'):         # a negative ratio: N0 < 0, lifted
        return np.where(lifted, 0.0, np.sqrt(best))


def mu_required_kinematic(model, omega, samples=2048):
    """max over one cycle of μ_required at each kinematic speed Ω (rad/s, array_like).

    Sampled at ``samples`` phases; inf at and above the lift-off speed.
    """
    omega = np.asarray(omega, dtype=float)
    u = TWO_PI * np.arange(samples) / samples
    return model.kinematic(u, omega[..., None]).mu_required.max(axis=-1)


def mu_required_dynamic(model, energy, u0=None, samples=2048):
    """μ_required over the phases a free motion of energy E (J) reaches.

    Rolling over (E above every maximum of V) reaches the whole cycle; otherwise, if ``u0``
    (rad) is given, the well of V holding it, or (E above the lower maximum bounding that
    well) the span between the turning points either side of u0; else every u with V(u) ≤ E. w² = 2(E − V)/J (the
    angular speed, J the inertia about AB: finite also where the body does not turn in u).

    Returns
    -------
    peak : float
        max μ_required over the reached phases (inf if a contact lifts off; nan if none).
    u : ndarray
        The sampled phases (rad).
    mu : ndarray
        μ_required(u), nan where not reached.
    """
    dynamics = model.dynamics
    u = TWO_PI * np.arange(samples) / samples
    if u0 is not None and energy < dynamics.barrier:
        _, low, high = dynamics.well(float(u0))
        if energy >= dynamics.well_rim(float(u0)):   # over the lower maximum: several wells
            bounds = turning_points(dynamics.tabulated_potential, partial(
                dynamics.tabulated_potential, derivative=1), energy, float(u0), 1.0, samples)
            low, high = bounds if bounds is not None else (low, high)
        u = low + (high - low) * (np.arange(samples) + 0.5) / samples
    rate2 = 2 * (energy - dynamics.tabulated_potential(u)) / dynamics.tabulated_inertia(u)
    reached = rate2 >= 0
    mu = np.where(reached, model.dynamic(u, angular_speed=np.sqrt(np.maximum(rate2, 0.0)))
                  .mu_required, np.nan)
    return (float(np.nanmax(mu)) if np.any(reached) else math.nan), u, mu


def mu_required_kinematic_batch(q0, q2, omega, samples=2048):
    """:func:`mu_required_kinematic` of B bodies at one speed Ω (rad/s), from the nodes.

    Parameters
    ----------
    q0, q2 : ndarray, shape (5, N, B)
        N_A, N_B, T_A, T_B, S = Q0 + Ω² Q2 at u_j = 2πj/N
        (:func:`~twodisk_ros.physics.forces.contact.kinematic_coefficients`); N must be a
        multiple of ``samples``, whose phases 2πj/samples are then nodes.
    omega : float
        Ω (rad/s).

    Returns
    -------
    ndarray, shape (B,)
        max over the ``samples`` phases of μ_required (inf at and above the lift-off speed).
    """
    n = q0.shape[1]
    if n % samples:
        raise ValueError(f'the nodes ({n}) must be a multiple of samples ({samples})')
    stride = n // samples
    values = q0[:, ::stride] + float(omega) ** 2 * q2[:, ::stride]
    return squeeze_split(*values)[3].max(axis=0)

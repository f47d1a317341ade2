"""The checks of ``twodisk-inspect``: what the physics says a recording must satisfy.

Everything is recomputed from the recorded messages and the recorded parameters alone.

The checks (L is the body size, :attr:`EllipseBody.size`; X = max(L, max |G|) the coordinate
scale, so that round-off far from the origin is allowed for):

``inputs``
    pose, contacts and rolling state are recorded with the expected types and the parameters
    define a body, a mass model and a mode (tolerance 0 problems; the diagnostics, only
    reported and plotted, may be missing).
``ground``
    A and B on the ground: max |n·p| ≤ 1e-9 X, n the ground normal (ez; on a slope β
    (sin β, 0, cos β), the ground through the origin).
``contact_points``
    A and B where the body puts them: |A − (G + R r1(u))| and |B − (G + R r2(u))| ≤ 1e-8 X,
    r1, r2 from :meth:`EllipseBody.phase_geometry` at the recorded phase u.  The recorded
    values are float64 from closed forms and tables accurate to ~1e-13 L, so anything above
    the tolerance is an inconsistency, not round-off.
``tangent_plane``
    the ground is the tangent plane: angle between R n(u) and the ground normal ≤ 1e-8 rad.
``theta``
    recorded θ equals θ(u): ≤ 1e-8 rad.
``psi``
    recorded ψ equals ψ(θ, branch), branch = sign(cos u), ≤ 1e-7 rad.  ψ(θ) has a square-root
    singularity at the turning points θ = ±θ_max, so ψ is compared with the range of
    ψ(θ ± 1e-12 rad): the last bits of θ would otherwise move ψ by ~1e-8 rad there.
``no_slip``
    material velocity of the body at A and at B, v_G + ω × (P − G), max over the samples,
    relative to the largest |v_G|; v_G and ω by central differences of the recorded poses over
    the neighbouring samples t ± h, t ± 2h (:func:`finite_differences`; ω from the rotation
    vectors of R(t + kh) R(t)ᵀ).  Their error is ~ (ω h)⁴ relative, times a factor set by the
    body's geometry and the speed profile; the plain three-point difference would leave
    ~ (ω h)² (about 1e-3 at 100 Hz, hiding millimetre errors of the contacts).  The tolerance
    is *computed*: the same differences of the model's poses at the recorded phases (rolling
    exactly without slip) give the slip a perfect recording shows at this rate; the tolerance
    is twice that, plus round-off 100 ε X / (h max |v_G|).
``energy`` (dynamic mode)
    relative drift max |E − E₀| / (M g L) of E = ½ M |v_G|² + ½ ωᵀ (R I Rᵀ) ω + M g z_G, with
    v_G and ω from the recorded poses alone as above (I from the recorded mass model).
    FD-limited: the tolerance is 4 × the largest FD error of E that the model's poses at the
    recorded phases show against the exact E(u, u̇) of the recorded rolling state (a drift is
    the difference of two errors; factor 2 margin), plus max(1e-9, 10 × the recorded solver
    ``tolerance``) for the integration itself.
``angular_speed`` (kinematic mode)
    max | |ω| − |omega0| | / |omega0| with ω from the recorded poses; tolerance twice the FD
    error of the model's poses at the recorded phases plus the same solver allowance.
Every FD-limited check (``no_slip``, ``energy``, ``angular_speed``, ``energy_balance``,
``speed_drive`` and force_checks' ``contact_forces``) judges only the samples its
differences resolve: those where the FD part of its tolerance, from that sample alone, is
within 1e-3 of its scale (:mod:`.resolution`). It names the stretches it left out (around a
superellipse's flat vertices, where the body stops turning in u and its acceleration
spikes); with none left it is not evaluated ("the samples do not resolve the motion here"),
a failed check. ``energy`` then measures the drift from its first sample kept, and
``energy_balance`` starts again after each stretch left out.

``timestamps`` (:mod:`.stamp_checks`)
    stamps of pose, contacts and rolling state increase with no gaps: every interval within
    1 % of 1/rate (the recorded ``rate``; the median interval if it is missing).
``stamps`` (:mod:`.stamp_checks`)
    header stamp = log time = publish time, and pose, contacts and rolling state carry the same
    stamps (the tail cut off a truncated file excepted); tolerance 0 mismatches.
"""

import math

import numpy as np
from scipy.spatial.transform import Rotation

from .engine_stretches import rolling_starts
from .balance import balance_stretches, scene_timeline
from .differences import kinetic_energy, motion_of
from .resolution import Resolution, resolve
from .results import Check, json_ready
from .speed_drive import TITLE as SPEED_DRIVE_TITLE, speed_drive_check
from .series import SAMPLED, TOPIC_TYPES, WRENCHES, values_at
from .stamp_checks import STAMP_TITLES, check_stamps, check_timestamps, nominal_step_ns

__all__ = ['TITLES', 'run_checks']

GROUND_TOLERANCE = 1e-9       # × coordinate scale (m)
CONTACT_TOLERANCE = 1e-8      # × coordinate scale (m)
ANGLE_TOLERANCE = 1e-8        # rad: θ against θ(u), R n against the world's up
PSI_TOLERANCE = 1e-7          # rad, beyond the spread of ψ(θ ± THETA_UNCERTAINTY)
THETA_UNCERTAINTY = 1e-12     # rad
FD_MARGIN = 2.0               # tolerance of an FD-limited check / FD error of a perfect record
ROUNDOFF = 100 * np.finfo(float).eps
SOLVER_FLOOR = 1e-9           # relative energy or speed drift always allowed to the solver

#: What each check verifies, in words.
TITLES = {
    'inputs': 'topics and parameters present and valid',
    'ground': 'contact points A and B on the ground (max |n·p|, n its normal)',
    'contact_points': 'A and B where the body puts them: G + R r1(u), G + R r2(u)',
    'tangent_plane': 'the ground is the tangent plane: R n(u) is its normal',
    'theta': 'recorded θ equals θ(u) of the recorded phase u',
    'psi': 'recorded ψ equals ψ(θ, branch), branch = sign(cos u)',
    'no_slip': 'no slip at A and B (velocities by central differences of poses)',
    'energy': 'energy conserved (from the recorded poses alone)',
    'angular_speed': 'kinematic mode: angular speed |ω| constant = |omega0|',
    'energy_balance': 'drive or dissipation: E + W − W_d = E0 on each stretch (from the '
                      'recording alone)',
    'speed_drive': SPEED_DRIVE_TITLE,
    **STAMP_TITLES,
}


def _where(samples, k):
    return f'at t = {samples.t[k]:.6g} s'


def _fmt(value):
    return 'n/a' if value is None or not math.isfinite(value) else f'{value:.3g}'


def _check(name, value, tolerance, unit='', detail=()):
    """A :class:`Check` titled from :data:`TITLES`; it passes if ``value <= tolerance``."""
    passed = value is not None and tolerance is not None and bool(value <= tolerance)
    return Check(name, TITLES[name], passed, json_ready(value), json_ready(tolerance), unit,
                 list(detail))


def _not_evaluated(name, reason, unit=''):
    """A failed check that could not be evaluated."""
    return _check(name, None, None, unit, [reason])


def _check_inputs(problems, chosen, model):
    missing = [role for role in SAMPLED if role not in chosen]
    detail = [f'no {role} topic of type {TOPIC_TYPES[role]}' for role in missing]
    detail += problems
    if model is None and not detail:
        detail.append('no model')
    if not detail:
        return _check('inputs', 0, 0, 'problems', [
            f'body {model.shape}, mass model '
            f'{model.dynamics.mass.model}, mode {model.mode}; topics '
            + ', '.join(chosen[role] for role in TOPIC_TYPES if role in chosen)])
    return _check('inputs', len(detail), 0, 'problems', detail)


def _check_ground(series, scale, normal=None):
    points = [series[role].values['point'] for role in ('contact_a', 'contact_b')
              if role in series and len(series[role])]
    if not points:
        return _not_evaluated('ground', 'no contact points recorded', 'm')
    normal = np.array([0.0, 0.0, 1.0]) if normal is None else normal
    heights = np.abs(np.concatenate(points) @ normal)
    tolerance = GROUND_TOLERANCE * scale
    return _check('ground', float(np.max(heights)), tolerance, 'm', [
        f'{heights.size} points, {int(np.sum(heights > tolerance))} above the tolerance '
        f'(1e-9 × coordinate scale {scale:.3g} m)'])


def _check_contact_points(samples, geometry, scale):
    rotation = samples.rotation
    error_a = np.linalg.norm(
        samples.contact_a - samples.position_g - rotation.apply(geometry.contact_a), axis=1)
    error_b = np.linalg.norm(
        samples.contact_b - samples.position_g - rotation.apply(geometry.contact_b), axis=1)
    worst = np.maximum(error_a, error_b)
    k = int(np.argmax(worst))
    tolerance = CONTACT_TOLERANCE * scale
    return _check('contact_points', float(worst[k]), tolerance, 'm', [
        f'max |A − (G + R r1)| = {_fmt(np.max(error_a))} m, max |B − (G + R r2)| = '
        f'{_fmt(np.max(error_b))} m, worst {_where(samples, k)}; '
        f'{int(np.sum(worst > tolerance))} of {worst.size} samples off; '
        f'tolerance 1e-8 × coordinate scale {scale:.3g} m'])


def _check_tangent_plane(samples, geometry, ground=None):
    up = samples.rotation.apply(geometry.ground_normal)
    ground = np.array([0.0, 0.0, 1.0]) if ground is None else ground
    angle = np.arctan2(np.linalg.norm(np.cross(up, ground), axis=1), up @ ground)
    k = int(np.argmax(angle))
    return _check('tangent_plane', float(angle[k]), ANGLE_TOLERANCE, 'rad', [
        f'largest angle between R n(u) and the ground\'s normal {_vector(ground)}, '
        f'{_where(samples, k)}'])


def _vector(v):
    return '(' + ', '.join(f'{x:.6g}' for x in v) + ')'


def _wrap(angle):
    return np.angle(np.exp(1j * angle))


def _check_theta(samples, geometry):
    error = np.abs(_wrap(samples.angles[:, 0] - geometry.theta))
    k = int(np.argmax(error))
    return _check('theta', float(error[k]), ANGLE_TOLERANCE, 'rad',
                  [f'worst {_where(samples, k)}'])


def _check_psi(samples, body):
    phase = samples.angles[:, 2]
    branch = np.where(np.cos(phase) < 0, -1, 1)
    theta = np.clip(samples.angles[:, 0], -body.theta_max, body.theta_max)
    psi = body.contact_angle_psi(theta, branch)
    spread = np.zeros_like(psi)
    for shift in (-THETA_UNCERTAINTY, THETA_UNCERTAINTY):
        moved = np.clip(theta + shift, -body.theta_max, body.theta_max)
        spread = np.maximum(spread, np.abs(_wrap(body.contact_angle_psi(moved, branch) - psi)))
    error = np.maximum(np.abs(_wrap(samples.angles[:, 1] - psi)) - spread, 0.0)
    k = int(np.argmax(error))
    return _check('psi', float(error[k]), PSI_TOLERANCE, 'rad', [
        f'worst {_where(samples, k)} (branch {int(branch[k]):+d}); ψ compared with '
        f'ψ(θ ± {THETA_UNCERTAINTY:g} rad, branch), up to {_fmt(np.max(spread))} rad apart '
        'near the turning points'])


_NO_DIFFERENCES = 'no sample with four regular intervals around it for central differences'


def _slip(position_g, contact_a, contact_b, velocity, omega):
    slip_a = velocity + np.cross(omega, contact_a - position_g)
    slip_b = velocity + np.cross(omega, contact_b - position_g)
    return np.maximum(np.linalg.norm(slip_a, axis=1), np.linalg.norm(slip_b, axis=1))


def _check_no_slip(samples, motion, scale, body=None):
    k = motion.index
    if k.size == 0:
        return _not_evaluated('no_slip', _NO_DIFFERENCES)
    state = motion.model_state
    recorded = _slip(samples.position_g[k], samples.contact_a[k], samples.contact_b[k],
                     motion.velocity, motion.angular_velocity)
    expected = _slip(state.position_g[k], state.contact_a[k], state.contact_b[k],
                     motion.model_velocity, motion.model_angular_velocity)
    speed = float(np.max(np.linalg.norm(motion.velocity, axis=1)))
    roundoff = ROUNDOFF * scale / motion.step
    if speed > roundoff:
        unit, norm = '', speed
        what = f'max |v_A|, |v_B| / max |v_G| (max |v_G| = {speed:.4g} m/s)'
        kept = resolve(FD_MARGIN * expected / norm, k, samples, body)
    else:       # at rest: absolute speeds, no scale to cap them against
        unit, norm = 'm/s', 1.0
        what = 'max |v_A|, |v_B| (the body is at rest)'
        kept = Resolution(np.ones(k.size, dtype=bool), None)
    if not kept.count:
        return _not_evaluated('no_slip', kept.note, unit)
    rows = np.nonzero(kept.keep)[0]
    worst = rows[int(np.argmax(recorded[rows]))]
    omega_h = float(np.max(np.linalg.norm(motion.angular_velocity[rows], axis=1))) * motion.step
    fd_error = float(np.max(expected[rows])) / norm
    return _check('no_slip', float(recorded[worst]) / norm,
                  FD_MARGIN * fd_error + roundoff / norm, unit, [
                      f'{what}, worst {_where(samples, k[worst])}, {rows.size} samples',
                      f'FD-limited: the model poses at the recorded phases (rolling without '
                      f'slip) show {fd_error:.3g} at h = {motion.step:.4g} s '
                      f'((ω h)⁴ = {omega_h**4:.3g}); tolerance {FD_MARGIN:g} × that + '
                      'round-off'] + _left_out(kept))


def _left_out(resolution):
    """The detail line on the samples a check left out (none if it kept them all)."""
    return [] if resolution.note is None else [resolution.note]


def _solver_allowance(model):
    return max(SOLVER_FLOOR, 10.0 * model.solver_tolerance)


def _energies(samples, motion, model):
    """Energy from the recorded poses, from the model's poses and exact, at motion.index."""
    k = motion.index
    mass, gravity = model.dynamics.mass, model.dynamics.gravity
    recorded = (kinetic_energy(mass, motion.velocity, motion.angular_velocity,
                                samples.rotation[k])
                + mass.mass * gravity * samples.position_g[k, 2])
    state = motion.model_state
    model_fd = (kinetic_energy(mass, motion.model_velocity, motion.model_angular_velocity,
                                Rotation.from_matrix(state.rotation[k]))
                + mass.mass * gravity * state.position_g[k, 2])
    phase = np.unwrap(samples.angles[:, 2])[k]
    exact = model.dynamics.energy(phase, samples.rates[k, 2])
    return recorded, model_fd, exact


def _check_energy(samples, motion, model, restarts=()):
    """E against E0, E0 the first kept sample's, again after each stamp of ``restarts``
    (int ns: exact rolling resumes with the engine's energy, contact_model hybrid; a reset
    or restart starts a new motion)."""
    k = motion.index
    if k.size == 0:
        return _not_evaluated('energy', _NO_DIFFERENCES)
    if not np.any(np.isfinite(samples.rates[k, 2])):
        return _not_evaluated('energy', 'rolling_state carries no phase rate: the FD error '
                                        'cannot be estimated')
    scale = model.dynamics.energy_scale
    recorded, model_fd, exact = _energies(samples, motion, model)
    errors = np.abs(model_fd - exact) / scale
    kept = resolve(2 * FD_MARGIN * errors, k, samples, model.body, minimum=2)
    if kept.count < 2:
        return _not_evaluated('energy', kept.note)
    rows = np.nonzero(kept.keep)[0]
    reference = rows[0]
    stretch = np.searchsorted(np.sort(np.asarray(restarts, dtype=np.int64)),
                              samples.stamp_ns[k[rows]], side='right')
    references = rows[np.searchsorted(stretch, stretch)]    # the first row of each stretch
    drift = np.abs(recorded[rows] - recorded[references]) / scale
    worst = rows[int(np.argmax(drift))]
    fd_error = float(np.max(errors[rows]))
    solver = _solver_allowance(model)
    model_drift = float(np.max(np.abs(exact[rows] - exact[references]))) / scale
    return _check('energy', float(np.max(drift)), 2 * FD_MARGIN * fd_error + solver, '', [
        f'max |E − E0| / (M g L), E0 = {recorded[reference]:.8g} J'
        + ('' if reference == 0 else f' (at t = {samples.t[k[reference]]:.6g} s)')
        + f', M g L = {scale:.4g} J; worst {_where(samples, k[worst])}, {rows.size} samples'
        + (f'; E0 again at each of {stretch[-1]} returns to rolling, resets or restarts'
           if stretch[-1] else ''),
        f'FD-limited: the model poses at the recorded phases give E within {fd_error:.3g} of '
        f'the exact E(u, u̇); tolerance 2 × {FD_MARGIN:g} × that + {solver:.3g} (solver)',
        f'the exact E(u, u̇) of the recorded rolling_state drifts by {model_drift:.3g}']
        + _left_out(kept))


def _check_angular_speed(samples, motion, model):
    k = motion.index
    if k.size == 0:
        return _not_evaluated('angular_speed', _NO_DIFFERENCES)
    target = abs(model.omega0)
    speed = np.linalg.norm(motion.angular_velocity, axis=1)
    model_speed = np.linalg.norm(motion.model_angular_velocity, axis=1)
    if target > 0:
        error = np.abs(speed - target) / target
        errors = np.abs(model_speed - target) / target
        kept = resolve(FD_MARGIN * errors, k, samples, model.body)
        allowance = _solver_allowance(model)
        unit, what = '', f'max ||ω| − |omega0|| / |omega0|, |omega0| = {target:g} rad/s'
    else:       # omega0 = 0: absolute speeds, no scale to cap them against
        error, errors = speed, model_speed
        kept = Resolution(np.ones(k.size, dtype=bool), None)
        allowance = ROUNDOFF / motion.step
        unit, what = 'rad/s', 'max |ω| (omega0 = 0)'
    if not kept.count:
        return _not_evaluated('angular_speed', kept.note, unit)
    rows = np.nonzero(kept.keep)[0]
    worst = rows[int(np.argmax(error[rows]))]
    fd_error = float(np.max(errors[rows]))
    return _check('angular_speed', float(error[worst]), FD_MARGIN * fd_error + allowance, unit, [
        f'{what}; worst {_where(samples, k[worst])}, {rows.size} samples',
        f'FD-limited: the model poses at the recorded phases show {fd_error:.3g}; '
        f'tolerance {FD_MARGIN:g} × that + solver allowance'] + _left_out(kept))


def _run(checks, name, function, *args):
    """Append ``function(*args)``; an error while evaluating it is a failed check."""
    try:
        checks.append(function(*args))
    except Exception as error:  # noqa: BLE001 - reported as a failed check, not a traceback
        checks.append(_not_evaluated(name, f'cannot be evaluated: {type(error).__name__}: '
                                           f'{" ".join(str(error).split())}'))


def run_checks(recording, problems, chosen, series, samples, model, parameters, events=(),
               whole=None):
    """Every check of a recording, in report order; returns (checks, Motion or None).
    ``whole``: the series with the engine stretches of a hybrid run, for the stamp checks.

    An error while evaluating a check makes that check fail with the reason: never an
    exception out of here.
    """
    checks = []
    scale = _coordinate_scale(model, series)
    _run(checks, 'inputs', _check_inputs, problems, chosen, model)
    _run(checks, 'ground', _check_ground, series, scale,
         None if model is None else model.ground_normal)
    step_ns, source = nominal_step_ns(series, model)
    motion = _physics_checks(checks, samples, model, step_ns, scale, parameters, events,
                             series)
    whole = series if whole is None else whole
    _run(checks, 'timestamps', check_timestamps, whole, step_ns, source)
    _run(checks, 'stamps', check_stamps, whole, recording.truncated)
    return checks, motion


def _physics_checks(checks, samples, model, step_ns, scale, parameters, events=(),
                    series=None):
    """Append the checks that need the model; return the finite differences (or None)."""
    speed_check = 'angular_speed' if parameters.get('mode') == 'kinematic' else 'energy'
    if model is None or samples is None:
        reason = ('no model (see inputs)' if model is None
                  else 'no stamps shared by pose, contacts and rolling_state')
        _not_evaluated_all(checks, ('contact_points', 'tangent_plane', 'theta', 'psi',
                                    'no_slip', speed_check), reason)
        return None
    try:
        geometry = model.body.phase_geometry(samples.angles[:, 2])
    except (ValueError, FloatingPointError) as error:
        geometry, reason = None, f'phases unusable: {" ".join(str(error).split())}'
    if geometry is None:
        _not_evaluated_all(checks, ('contact_points', 'tangent_plane', 'theta'), reason)
    else:
        _run(checks, 'contact_points', _check_contact_points, samples, geometry, scale)
        _run(checks, 'tangent_plane', _check_tangent_plane, samples, geometry,
             model.ground_normal)
        _run(checks, 'theta', _check_theta, samples, geometry)
    _run(checks, 'psi', _check_psi, samples, model.body)
    motion, reason = None, 'no stamp interval'
    if step_ns is not None:
        try:
            motion = motion_of(samples, model, step_ns * 1e-9,
                               [stamp for stamp, _ in events])
        except Exception as error:  # noqa: BLE001 - reported as failed checks
            reason = f'{type(error).__name__}: {" ".join(str(error).split())}'
    if motion is None:
        _not_evaluated_all(checks, ('no_slip', speed_check), f'no finite differences: {reason}')
        return None
    _run(checks, 'no_slip', _check_no_slip, samples, motion, scale, model.body)
    timeline = scene_timeline(parameters, events) if model.scene else []
    speed_driven = [state['active'] == 'speed' for _, state in timeline]
    if model.mode == 'kinematic' and not model.scene:
        _run(checks, 'angular_speed', _check_angular_speed, samples, motion, model)
    elif model.scene and not _conservative(parameters):
        if not all(speed_driven):   # a speed drive's work is what its rule needs: speed_drive
            _run(checks, 'energy_balance', _check_energy_balance, samples, motion, model,
                 parameters, events, series)
    else:
        _run(checks, 'energy', _check_energy, samples, motion, model,
             rolling_starts(events))
    if any(speed_driven) and motion.index.size:
        _run(checks, 'speed_drive', speed_drive_check, samples, motion, model, timeline,
             parameters, events, FD_MARGIN, ROUNDOFF / motion.step + _solver_allowance(model))
    return motion


def _check_energy_balance(samples, motion, model, parameters, events, series):
    """E + W − W_d = E(t₀) on each stretch whose drive's work is known (:mod:`.balance`)."""
    if motion.index.size == 0:
        return _not_evaluated('energy_balance', _NO_DIFFERENCES)
    (force_a, found_a), (force_b, found_b) = (
        values_at(series.get(role), 'force', samples.stamp_ns) for role in WRENCHES)
    normal = ((force_a + force_b) @ model.ground_normal
              if np.all(found_a & found_b) else None)
    scale = model.dynamics.energy_scale
    _, model_fd, exact = _energies(samples, motion, model)
    errors = np.abs(model_fd - exact) / scale
    kept = resolve(2 * FD_MARGIN * errors, motion.index, samples, model.body, minimum=3)
    if kept.count < 3:
        return _not_evaluated('energy_balance', kept.note)
    residuals, skipped, quadrature = balance_stretches(
        samples, motion, model, scene_timeline(parameters, events), normal, kept.keep)
    if not residuals:
        return _not_evaluated('energy_balance', 'no stretch whose drive\'s work is known: '
                              + '; '.join(skipped[:3]))
    fd_error = float(np.max(errors[kept.keep]))
    tolerance = 2 * FD_MARGIN * fd_error + 2 * quadrature / scale + _solver_allowance(model)
    value = max(float(np.max(r)) for _, r in residuals) / scale
    return _check('energy_balance', value, tolerance, '', [
        f'max |E + W − W_d − E(t0)| / (M g L) over {len(residuals)} stretch(es), M g L = '
        f'{scale:.4g} J; E from the poses, W and W_d from the powers of damping, rolling '
        f'resistance (recorded N) and the torque commanded (events)',
        f'tolerance 2 × {FD_MARGIN:g} × the FD error of E ({fd_error:.3g}) + 2 × the '
        f'trapezoid error ({quadrature / scale:.3g}) + solver'] + [
        f'not checked: {line}' for line in skipped[:5]] + (
        [] if kept.note is None else
        [kept.note, 'the balance starts again after each stretch left out (t0: its first '
                    'sample after it)']))


def _conservative(parameters):
    """True if the recorded scene conserves E = T + V: no drive, no dissipation."""
    return (parameters.get('drive', 'none') == 'none' and parameters.get('mode') != 'kinematic'
            and float(parameters.get('rolling_resistance', 0)) == 0
            and float(parameters.get('damping', 0)) == 0)


def _not_evaluated_all(checks, names, reason):
    checks.extend(_not_evaluated(name, f'not evaluated: {reason}') for name in names)


def _coordinate_scale(model, series):
    size = model.body.size if model is not None else 1.0
    pose = series.get('pose')
    if pose is not None and len(pose):
        size = max(size, float(np.max(np.abs(pose.values['position']))))
    return size

"""The contact-force checks of ``twodisk-inspect``: recorded wrenches against the poses, and
where the rolling model is outside its validity.

Evaluated for recordings that carry the contact forces (topics ``wrench_a``/``wrench_b``,
parameter ``friction``); older recordings have neither and skip both checks (the report says
so, and shows the lift-off the poses imply, for information). W = M g is the force unit
(M × max |a_G| of the model if g = 0).

``contact_forces``
    The ground forces are recomputed from the recorded poses alone (Newton–Euler,
    :func:`~twodisk_ros.inspector.forces.newton_euler`): a_G and ω̇ by fourth-order central
    second differences (:func:`~twodisk_ros.inspector.differences.second_differences`),
    recorded contact points and mass model. Compared with the recorded wrenches at the same
    samples: |ΣF_rec − ΣF|, and the determinate components |ΔN_A|, |ΔN_B|, |ΔT_A|, |ΔT_B|
    (perpendicular to AB; the total along AB is in ΣF), max over samples, / W. The split along
    AB is free and is compared with the least-friction rule separately (``force_split``).
    FD-limited: the same differences of the model's poses at the recorded phases, against the
    model's exact forces at the recorded (u, u̇) (kinematic: |ω| = |omega0|), give the error
    of a perfect recording; tolerance = 2 × that + max(1e-9, 10 × solver tolerance) +
    round-off 100 ε (M X + I_max / L) / (h² W). Samples lacking a wrench fail the check (a
    truncated file's tail excepted). Only the samples whose own FD error keeps that within
    1e-3 W are judged; the others are named (:mod:`.resolution`: around flat vertices the
    force spikes and no difference resolves it), and with none left the check is not
    evaluated.
``force_split``
    The recorded F_A·ê equals the split that needs the least friction (the node's rule,
    :func:`~twodisk_ros.physics.forces.contact.squeeze_split`) applied to the recorded
    determinate components: max |Δ| / W ≤ 1e-7, at samples where both |N| > 1e-6 W (the rule
    jumps to S/2 where a contact lifts off).
``rolling_validity``
    From the recorded wrenches (from the recomputed forces if the wrenches are missing): every
    stretch of samples where N_A < 0 or N_B < 0 (lift-off) or μ_required > μ (slip), μ the
    recorded ``friction`` (inf if not recorded, said so). μ_required is the least friction the
    recorded determinate components need. Tolerance 0 stretches: a recording faithful to the
    model fails this check where the model is outside its validity, since the motion shown
    there is not physics.
"""

import math

import numpy as np
from scipy.spatial.transform import Rotation

from .forces import exact_components, invalid_stretches, newton_euler, recorded_components
from .resolution import resolve
from .results import Check, json_ready
from .series import WRENCHES, values_at

__all__ = ['FORCE_TITLES', 'force_checks']

FD_MARGIN = 2.0
ROUNDOFF = 100 * np.finfo(float).eps
SOLVER_FLOOR = 1e-9
SPLIT_TOLERANCE = 1e-7          # × W
SPLIT_GUARD = 1e-6              # × W: the rule is compared where both |N| exceed this
SKIPPED = ('no wrench_a/wrench_b topics and no friction parameter: a recording made before '
           'the contact forces; contact_forces, force_split and rolling_validity skipped')

#: What each check verifies, in words.
FORCE_TITLES = {
    'contact_forces': 'recorded wrenches = Newton–Euler forces from the poses (N, T, ΣF)',
    'force_split': 'recorded split along AB = the least-friction split',
    'rolling_validity': 'rolling model valid: no lift-off (N > 0), no slip (μ_required ≤ μ)',
}


def _check(name, value, tolerance, unit, detail):
    passed = value is not None and tolerance is not None and bool(value <= tolerance)
    return Check(name, FORCE_TITLES[name], passed, json_ready(value), json_ready(tolerance),
                 unit, list(detail))


def _not_evaluated(name, reason):
    return _check(name, None, None, '', [f'not evaluated: {reason}'])


def _friction(parameters):
    """(μ, note, problem): the recorded friction coefficient, inf if not recorded."""
    text = parameters.get('friction')
    if text is None:
        return math.inf, 'friction not recorded (older recording): mu = inf assumed', None
    try:
        mu = float(text[1:] if text.strip().lower() in ('.inf', '+.inf') else text)
    except (ValueError, AttributeError):
        mu = math.nan
    if not mu >= 0:
        return None, '', f'recorded friction {text!r} is not a number >= 0'
    return mu, f'mu = {mu:g} (recorded friction)', None


def _weight(model, motion):
    mass, gravity = model.dynamics.mass.mass, model.dynamics.gravity
    if gravity > 0:
        return mass * gravity, 'M g'
    peak = 0.0
    if motion is not None and motion.model_acceleration is not None and motion.index.size:
        peak = float(np.max(np.linalg.norm(motion.model_acceleration, axis=1)))
    return mass * max(peak, model.body.size), 'M max|a_G| (g = 0)'


def _components(samples, motion, model, k, recorded):
    """Forces from the FD of the recorded (or the model's) poses at samples k."""
    mass, gravity = model.dynamics.mass, model.dynamics.gravity
    rows = np.searchsorted(motion.index, k)
    if recorded:
        return newton_euler(mass, gravity, samples.position_g[k], samples.rotation[k],
                            samples.contact_a[k], samples.contact_b[k],
                            motion.acceleration[rows], motion.angular_velocity[rows],
                            motion.angular_acceleration[rows], model.ground_normal)
    state = motion.model_state
    return newton_euler(mass, gravity, state.position_g[k],
                        Rotation.from_matrix(state.rotation[k]), state.contact_a[k],
                        state.contact_b[k], motion.model_acceleration[rows],
                        motion.model_angular_velocity[rows],
                        motion.model_angular_acceleration[rows])


_COMPONENTS = ('F_A + F_B', 'N_A', 'N_B', 'T_A', 'T_B')


def _differences(one, other, weight):
    """|Δ| / W of the compared quantities: {name: array over samples}."""
    out = {'F_A + F_B': np.linalg.norm(one.total - other.total, axis=1)}
    for name, attr in zip(_COMPONENTS[1:], ('normal_a', 'normal_b', 'tangential_a',
                                            'tangential_b')):
        out[name] = np.abs(getattr(one, attr) - getattr(other, attr))
    return {name: value / weight for name, value in out.items()}


def _wrenches(series, samples, truncated):
    """Recorded forces at the samples' stamps: (F_A, F_B, found, lacking count, max |torque|)."""
    (force_a, found_a), (force_b, found_b) = (
        values_at(series.get(role), 'force', samples.stamp_ns) for role in WRENCHES)
    found = found_a & found_b
    torques = [series[role].values['torque'] for role in WRENCHES
               if role in series and len(series[role])]
    torque = max(float(np.max(np.abs(x))) for x in torques) if torques else 0.0
    lacking = ~found
    if truncated:
        ends = [int(series[role].stamp_ns.max()) for role in WRENCHES
                if role in series and len(series[role])]
        last = min(ends) if len(ends) == 2 else -1
        lacking &= samples.stamp_ns <= last
    return force_a, force_b, found, int(np.sum(lacking)), torque


def _check_contact_forces(samples, motion, model, wrenches, weight, scale):
    force_a, force_b, found, lacking, _ = wrenches
    k = motion.index[found[motion.index]]
    if k.size == 0:
        return _not_evaluated('contact_forces', 'no sample with both wrenches and central '
                                                'differences')
    rates = samples.rates[k, 2]
    if model.mode != 'kinematic' and not np.any(np.isfinite(rates)):
        return _not_evaluated('contact_forces', 'rolling_state carries no phase rate: the '
                                                'FD error cannot be estimated')
    phase = np.unwrap(samples.angles[:, 2])[k]
    with np.errstate(invalid='ignore', divide='ignore'):
        exact = exact_components(model, phase, rates, _scene_acceleration(samples, model, k))
        fd_errors = _differences(_components(samples, motion, model, k, recorded=False),
                                 exact, weight)
    per_sample = np.max(np.stack(list(fd_errors.values())), axis=0)
    kept = resolve(FD_MARGIN * per_sample, k, samples, model.body)
    if not kept.count:
        return _not_evaluated('contact_forces', kept.reason)
    rows = np.nonzero(kept.keep)[0]
    k = k[rows]
    fd = _components(samples, motion, model, k, recorded=True)
    recorded = recorded_components(force_a[k], force_b[k], samples.contact_a[k],
                                   samples.contact_b[k], model.ground_normal)
    errors = _differences(recorded, fd, weight)
    fd_error = float(np.max(per_sample[rows]))
    worst_name = max(errors, key=lambda name: float(np.max(errors[name])))
    j = int(np.argmax(errors[worst_name]))
    value = float(errors[worst_name][j])
    mass, inertia = model.dynamics.mass.mass, model.dynamics.mass.inertia
    roundoff = ROUNDOFF * (mass * scale + float(np.max(inertia)) / model.body.size) / (
        motion.step**2 * weight)
    solver = max(SOLVER_FLOOR, 10.0 * model.solver_tolerance)
    tolerance = FD_MARGIN * fd_error + solver + roundoff
    parts = ', '.join(f'{name} {float(np.max(v)):.3g}' for name, v in errors.items())
    detail = [f'max |recorded − from poses| / W over {k.size} samples: {parts}; worst '
              f'{worst_name} at t = {samples.t[k[j]]:.6g} s',
              f'FD-limited: the model poses at the recorded phases give forces within '
              f'{fd_error:.3g} W of the exact model forces at the recorded (u, u̇) '
              f'(h = {motion.step:.4g} s); tolerance {FD_MARGIN:g} × that + {solver:.3g} '
              f'(solver) + round-off {roundoff:.2g}']
    if fd.drive_torque is not None and model.mode != 'kinematic':
        torque = float(np.max(np.abs(fd.drive_torque))) / (weight * model.body.size)
        detail.append(f'free motion: the drive moment about AB the poses need, max |τ| / '
                      f'(W L) = {torque:.3g} (0 up to the FD error)')
    if kept.note is not None:
        detail.append(kept.note)
    if lacking:
        detail.append(f'{lacking} samples (pose, contacts, rolling_state) lack a wrench_a or '
                      f'wrench_b of the same stamp')
        return Check('contact_forces', FORCE_TITLES['contact_forces'], False,
                     json_ready(value), json_ready(tolerance), '', detail)
    return _check('contact_forces', value, tolerance, '', detail)


def _scene_acceleration(samples, model, k):
    """ü (rad/s²) at samples k from the recorded u̇ (second-order differences) in a scene
    other than the flat free one (whose ü the model gives), else None."""
    if not model.scene:
        return None
    return np.gradient(samples.rates[:, 2], samples.t)[k]


def _check_split(samples, wrenches, weight, model):
    force_a, force_b, found, _, torque = wrenches
    k = np.nonzero(found)[0]
    if k.size == 0:
        return _not_evaluated('force_split', 'no sample with both wrenches')
    recorded = recorded_components(force_a[k], force_b[k], samples.contact_a[k],
                                   samples.contact_b[k], model.ground_normal)
    compared = np.minimum(np.abs(recorded.normal_a), np.abs(recorded.normal_b)) > (
        SPLIT_GUARD * weight)
    error = np.where(compared, np.abs(recorded.along_a - recorded.rule_split), 0.0) / weight
    j = int(np.argmax(error))
    detail = [f'max |F_A·ê − x_rule| / W over {int(np.sum(compared))} of {k.size} samples '
              f'(both |N| > {SPLIT_GUARD:g} W), worst at t = {samples.t[k[j]]:.6g} s; '
              f'x_rule from the recorded N_A, N_B, T_A, T_B and total along AB; tolerance '
              f'{SPLIT_TOLERANCE:g}']
    check = _check('force_split', float(error[j]), SPLIT_TOLERANCE, '', detail)
    if torque:
        check.detail.append(f'recorded wrench torques are not 0 (the force acts at the contact '
                            f'point): max |torque| = {torque:.3g} N m')
        check.passed = False
    return check


def _validity_forces(samples, motion, model, wrenches):
    """(t, ForceComponents, source) for the validity check: recorded wrenches, else FD."""
    if wrenches is not None and np.any(wrenches[2]):
        force_a, force_b, found = wrenches[:3]
        k = np.nonzero(found)[0]
        return samples.t[k], recorded_components(
            force_a[k], force_b[k], samples.contact_a[k], samples.contact_b[k],
            model.ground_normal), 'the recorded wrenches'
    if motion is None or motion.index.size == 0 or motion.acceleration is None:
        return None, None, 'no forces: no wrenches and no central differences'
    k = motion.index
    return (samples.t[k], _components(samples, motion, model, k, recorded=True),
            'the forces recomputed from the poses (no wrenches recorded)')


def _validity_summary(t, forces, mu, weight):
    need = forces.mu_required
    contact = np.isfinite(need)
    return {'samples': int(t.size), 't_first_s': float(t[0]), 't_last_s': float(t[-1]),
            'min_normal_a': float(np.min(forces.normal_a)),
            'min_normal_b': float(np.min(forces.normal_b)),
            'lift_off_margin': float(min(np.min(forces.normal_a), np.min(forces.normal_b))
                                     / weight),
            'max_mu_required': float(np.max(need[contact])) if np.any(contact) else math.inf,
            'friction': mu}


def _check_validity(t, forces, source, mu, mu_note, weight, faithful):
    need = forces.mu_required
    stretches = invalid_stretches(t, forces.normal_a, forces.normal_b, need, mu)
    info = _validity_summary(t, forces, mu, weight)
    detail = [f'from {source} at {t.size} samples; {mu_note}']
    if stretches:
        follows = ('the recording follows the rolling model (contact_forces passes)'
                   if faithful else 'the recorded forces are those of the rolling model')
        detail.append(f'{follows}, but the model is outside its validity in '
                      f'{len(stretches)} stretch(es): a real body would lift off or slip '
                      'there, so the motion recorded there is not physics')
        detail.extend(stretch.describe() for stretch in stretches)
    else:
        detail.append(f'rolling holds for t in [{t[0]:.6g}, {t[-1]:.6g}] s: min N_A = '
                      f'{info["min_normal_a"]:.4g} N, min N_B = {info["min_normal_b"]:.4g} N '
                      f'(lift-off margin {info["lift_off_margin"]:.3g} W), max mu_required = '
                      f'{info["max_mu_required"]:.4g} (mu = {mu:g})')
    info['stretches'] = [stretch.as_dict() for stretch in stretches]
    return _check('rolling_validity', len(stretches), 0, 'stretches', detail), info


def force_checks(series, samples, motion, model, parameters, truncated):
    """The contact-force checks of a recording, and a JSON-ready summary of its forces.

    Parameters
    ----------
    series : dict of str to Series
    samples : Samples or None
    motion : Motion or None
        Finite differences of the poses (with the second differences).
    model : RecordedModel or None
    parameters : dict of str to str
        The recorded parameters (``friction`` is read from here).
    truncated : bool

    Returns
    -------
    checks : list of Check
        Empty for a recording made before the contact forces (no wrench topics, no
        ``friction``).
    summary : dict
        ``recorded``, ``friction``, the forces' extremes and the invalid stretches (or the
        note why the checks are skipped, with the stretches the poses imply).
    series : dict of str to numpy.ndarray
        t, N_A, N_B, μ_required for the plot (may be empty).
    """
    has_wrenches = any(role in series and len(series[role]) for role in WRENCHES)
    recorded = has_wrenches or 'friction' in parameters
    summary = {'recorded': recorded}
    if model is None or samples is None:
        reason = 'no model (see inputs)' if model is None else 'no samples'
        if not recorded:
            summary['note'] = SKIPPED
            return [], json_ready(summary), {}
        return [_not_evaluated(name, reason) for name in FORCE_TITLES], json_ready(summary), {}
    weight, weight_name = _weight(model, motion)
    summary.update(weight_n=weight, weight=weight_name)
    if not recorded:
        summary['note'] = SKIPPED
        t, forces, source = _validity_forces(samples, motion, model, None)
        if forces is not None:
            stretches = invalid_stretches(t, forces.normal_a, forces.normal_b,
                                          forces.mu_required, math.inf)
            summary['from_poses'] = dict(_validity_summary(t, forces, None, weight),
                                         stretches=[s.as_dict() for s in stretches])
        return [], json_ready(summary), {}
    checks = []
    wrenches = _wrenches(series, samples, truncated) if has_wrenches else None
    if wrenches is None:
        checks.append(_not_evaluated('contact_forces', 'friction is recorded (a node with '
                                     'contact forces) but no wrench_a/wrench_b topic'))
    elif motion is None or motion.index.size == 0 or motion.acceleration is None:
        checks.append(_not_evaluated('contact_forces', 'no central differences'))
    else:
        checks.append(_run_safely('contact_forces', _check_contact_forces, samples, motion,
                                  model, wrenches, weight, _coordinate_scale(model, samples)))
    if wrenches is not None:
        checks.append(_run_safely('force_split', _check_split, samples, wrenches, weight,
                                      model))
    mu, mu_note, problem = _friction(parameters)
    t, forces, source = _validity_forces(samples, motion, model, wrenches)
    plot = {}
    if problem or forces is None:
        checks.append(_not_evaluated('rolling_validity', problem or source))
    else:
        faithful = bool(checks) and checks[0].passed
        check, info = _check_validity(t, forces, source, mu, mu_note, weight, faithful)
        checks.append(check)
        summary.update(source=source, friction_note=mu_note, **info)
        plot = {'t_forces': t, 'normal_a': forces.normal_a, 'normal_b': forces.normal_b,
                'mu_required': forces.mu_required, 'weight': np.array(weight),
                'friction': np.array(mu)}
    return checks, json_ready(summary), plot


def _coordinate_scale(model, samples):
    return max(model.body.size, float(np.max(np.abs(samples.position_g))))


def _run_safely(name, function, *args):
    """``function(*args)``; an error while evaluating it is a failed check."""
    try:
        return function(*args)
    except Exception as error:  # noqa: BLE001 - reported as a failed check, not a traceback
        return _not_evaluated(name, f'{type(error).__name__}: {" ".join(str(error).split())}')

"""Offline inspection of a ``roller`` recording: a summary and physics checks.

``twodisk-inspect FILE.mcap [--json] [--plot PNG]`` (or ``python -m twodisk_ros.inspect_mcap``)
reads an MCAP file written by the node (:mod:`twodisk_ros.recording`), summarises it (topics,
types, counts, duration, rates, recorded parameters) and recomputes, from the recorded messages
and the recorded parameters alone, what the physics library says must hold.

What is read (topics are matched by their last path component, so a namespace is allowed):
``pose`` (PoseStamped: G and the body → world orientation), ``contact_a`` and ``contact_b``
(PointStamped), ``rolling_state`` (JointState ``theta``, ``psi``, ``phase``: positions and
rates), ``diagnostics`` (DiagnosticArray, key ``energy``) and the metadata record
``twodisk_ros`` (every node parameter as a string).  Samples of pose, contacts and rolling
state are joined by their stamps.

The checks (L is the body size, :attr:`TwoDiskBody.size`; X = max(L, max |G|) the coordinate
scale, so that round-off far from the origin is allowed for):

``inputs``
    pose, contacts and rolling state are recorded with the expected types and the parameters
    define a body, a mass model and a mode (tolerance 0 problems; the diagnostics, only
    reported and plotted, may be missing).
``ground``
    A and B on the ground: max |z| ≤ 1e-9 X.
``contact_points``
    A and B where the body puts them: |A − (G + R r1(u))| and |B − (G + R r2(u))| ≤ 1e-8 X,
    r1, r2 from :meth:`TwoDiskBody.phase_geometry` at the recorded phase u.  The recorded
    values are float64 from closed forms and tables accurate to ~1e-13 L, so anything above
    the tolerance is an inconsistency, not round-off.
``tangent_plane``
    the ground is the tangent plane: angle between R n(u) and the world's up ≤ 1e-8 rad.
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
``timestamps``
    stamps of pose, contacts and rolling state increase with no gaps: every interval within
    1 % of 1/rate (the recorded ``rate``; the median interval if it is missing).
``stamps``
    header stamp = log time = publish time, and pose, contacts and rolling state carry the same
    stamps (the tail cut off a truncated file excepted); tolerance 0 mismatches.

A truncated file (writer killed, no footer) is checked on the part that was recovered; the
report says how many messages and bytes that is.

Exit status: 0 when every check passes, 1 when one fails, 2 when the file cannot be read or the
plot cannot be written (one line on stderr).
"""

import argparse
import json
import math
import os
import re
import sys
import textwrap
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from .body import TwoDiskBody
from .dynamics import MODES, RollingDynamics
from .mass_models import MODELS, mass_properties
from .recording import RecordingError, read_recording

__all__ = [
    'Check',
    'Inspection',
    'TOPIC_TYPES',
    'finite_differences',
    'format_report',
    'inspect_recording',
    'main',
]

PROG = 'twodisk-inspect'

#: The topics read, by the last component of their name, and the types they must have.
TOPIC_TYPES = {
    'pose': 'geometry_msgs/msg/PoseStamped',
    'contact_a': 'geometry_msgs/msg/PointStamped',
    'contact_b': 'geometry_msgs/msg/PointStamped',
    'rolling_state': 'sensor_msgs/msg/JointState',
    'diagnostics': 'diagnostic_msgs/msg/DiagnosticArray',
}
#: Topics published together at every step, at ``rate`` Hz; all are required (the
#: diagnostics are only reported and plotted).
SAMPLED = ('pose', 'contact_a', 'contact_b', 'rolling_state')
METADATA_NAME = 'twodisk_ros'
JOINT_NAMES = ('theta', 'psi', 'phase')

GROUND_TOLERANCE = 1e-9       # × coordinate scale (m)
CONTACT_TOLERANCE = 1e-8      # × coordinate scale (m)
ANGLE_TOLERANCE = 1e-8        # rad: θ against θ(u), R n against the world's up
PSI_TOLERANCE = 1e-7          # rad, beyond the spread of ψ(θ ± THETA_UNCERTAINTY)
THETA_UNCERTAINTY = 1e-12     # rad
STAMP_TOLERANCE = 0.01        # relative deviation of a stamp interval from 1/rate
FD_MARGIN = 2.0               # tolerance of an FD-limited check / FD error of a perfect record
ROUNDOFF = 100 * np.finfo(float).eps
SOLVER_FLOOR = 1e-9           # relative energy or speed drift always allowed to the solver

#: What each check verifies, in words.
TITLES = {
    'inputs': 'topics and parameters present and valid',
    'ground': 'contact points A and B on the ground (max |z|)',
    'contact_points': 'A and B where the body puts them: G + R r1(u), G + R r2(u)',
    'tangent_plane': 'the ground is the tangent plane: R n(u) is vertical',
    'theta': 'recorded θ equals θ(u) of the recorded phase u',
    'psi': 'recorded ψ equals ψ(θ, branch), branch = sign(cos u)',
    'no_slip': 'no slip at A and B (velocities by central differences of poses)',
    'energy': 'energy conserved (from the recorded poses alone)',
    'angular_speed': 'kinematic mode: angular speed |ω| constant = |omega0|',
    'timestamps': 'stamps increasing with no gaps (pose, contacts, rolling_state)',
    'stamps': 'consistent stamps across messages and topics',
}


# --------------------------------------------------------------------------------------------
# Results.

@dataclass
class Check:
    """One check: a value compared with a tolerance.

    Attributes
    ----------
    name : str
        Short identifier (``'ground'``, ``'no_slip'``, ...).
    title : str
        What is checked, in words.
    passed : bool
    value, tolerance : float or None
        The measured value and the largest allowed; None if it could not be evaluated.
    unit : str
        Unit of both (``''`` for relative values).
    detail : list of str
        How it was measured (where the worst sample is, the estimated FD error, ...).
    """

    name: str
    title: str
    passed: bool
    value: float | None
    tolerance: float | None
    unit: str = ''
    detail: list = field(default_factory=list)

    @property
    def status(self):
        """``'PASS'`` or ``'FAIL'``."""
        return 'PASS' if self.passed else 'FAIL'

    def as_dict(self):
        """The check as a JSON-ready dict."""
        return {'name': self.name, 'title': self.title, 'status': self.status,
                'passed': bool(self.passed), 'value': _plain(self.value),
                'tolerance': _plain(self.tolerance), 'unit': self.unit,
                'detail': list(self.detail)}


@dataclass
class Inspection:
    """Summary, checks and the series used for plots of one recording.

    Attributes
    ----------
    summary : dict
        JSON-ready: file, truncation, duration, topics, parameters, samples.
    checks : list of Check
    series : dict of str to numpy.ndarray
        Time series for :func:`twodisk_ros.inspection_plot.plot_inspection` (times in s
        from the first stamp).
    """

    summary: dict
    checks: list
    series: dict = field(default_factory=dict)

    @property
    def passed(self):
        """True if every check passed."""
        return bool(self.checks) and all(check.passed for check in self.checks)

    def as_dict(self):
        """One JSON-ready document: summary, checks, overall result."""
        return {'summary': self.summary, 'checks': [c.as_dict() for c in self.checks],
                'passed': self.passed, 'exit_status': 0 if self.passed else 1}


def _plain(value):
    """A JSON-ready copy: numpy scalars and arrays as Python, NaN and infinities as None."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_plain(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return value if math.isfinite(value) else None
    return value


# --------------------------------------------------------------------------------------------
# Reading the messages.

@dataclass
class _Series:
    """Messages of one topic: stamps (int ns) and named value arrays."""

    topic: str
    stamp_ns: np.ndarray
    log_ns: np.ndarray
    publish_ns: np.ndarray
    values: dict

    def __len__(self):
        return len(self.stamp_ns)


def _role(topic):
    """The last component of a topic name: ``'/ns/pose'`` → ``'pose'``."""
    return topic.rstrip('/').rsplit('/', 1)[-1]


def _select_topics(topics, problems):
    """Map each role of :data:`TOPIC_TYPES` to a recorded topic of the right type."""
    chosen = {}
    for role, type_name in TOPIC_TYPES.items():
        named = [name for name in topics if _role(name) == role]
        typed = [name for name in named if topics[name].type_name == type_name]
        for name in named:
            if name not in typed:
                problems.append(f'topic {name} has type {topics[name].type_name}, '
                                f'expected {type_name}')
        if not typed:
            continue
        typed.sort(key=lambda name: (-topics[name].message_count, name))
        if len(typed) > 1:
            problems.append(f'{len(typed)} {role} topics ({", ".join(typed)}); '
                            f'using {typed[0]}')
        chosen[role] = typed[0]
    return chosen


def _stamp(header):
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _xyz(point):
    return (float(point.x), float(point.y), float(point.z))


def _pose_values(msg):
    q = msg.pose.orientation
    return {'position': _xyz(msg.pose.position),
            'quaternion': (float(q.x), float(q.y), float(q.z), float(q.w))}


def _point_values(msg):
    return {'point': _xyz(msg.point)}


def _joint_values(msg):
    names = list(msg.name)
    index = [names.index(name) for name in JOINT_NAMES]
    position = [float(msg.position[k]) for k in index]
    velocity = list(msg.velocity)
    rate = ([float(velocity[k]) for k in index] if len(velocity) == len(names)
            else [math.nan] * 3)
    return {'position': position, 'velocity': rate}


def _number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def _diagnostic_values(msg):
    found = {}
    for status in msg.status:
        for pair in status.values:
            if pair.key in ('energy', 'energy_drift') and pair.key not in found:
                found[pair.key] = _number(pair.value)
    return {'energy': found.get('energy', math.nan),
            'energy_drift': found.get('energy_drift', math.nan)}


_EXTRACT = {
    'pose': _pose_values,
    'contact_a': _point_values,
    'contact_b': _point_values,
    'rolling_state': _joint_values,
    'diagnostics': _diagnostic_values,
}


def _extract(recording, chosen, problems):
    """Collect the chosen topics' messages into :class:`_Series`."""
    roles = {topic: role for role, topic in chosen.items()}
    rows = {role: ([], [], [], []) for role in chosen}
    bad = {}
    for message in recording.messages:
        role = roles.get(message.topic)
        if role is None:
            continue
        try:
            values = _EXTRACT[role](message.msg)
            stamp = _stamp(message.msg.header)
        except (AttributeError, TypeError, ValueError, IndexError):
            bad[message.topic] = bad.get(message.topic, 0) + 1
            continue
        stamps, logs, publishes, value_rows = rows[role]
        stamps.append(stamp)
        logs.append(message.log_time_ns)
        publishes.append(message.publish_time_ns)
        value_rows.append(values)
    for topic, count in bad.items():
        problems.append(f'{count} messages of {topic} lack the expected fields')
    series = {}
    for role, (stamps, logs, publishes, value_rows) in rows.items():
        keys = value_rows[0].keys() if value_rows else ()
        series[role] = _Series(
            chosen[role], np.array(stamps, dtype=np.int64), np.array(logs, dtype=np.int64),
            np.array(publishes, dtype=np.int64),
            {key: np.array([row[key] for row in value_rows], dtype=float) for key in keys})
    return series


# --------------------------------------------------------------------------------------------
# The model from the recorded parameters.

_NUMBER = re.compile(r'[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?')


@dataclass
class _Model:
    body: TwoDiskBody
    dynamics: RollingDynamics
    mode: str
    omega0: float
    rate: float | None
    solver_tolerance: float


def _float_parameter(parameters, name, problems, required=True):
    text = parameters.get(name)
    if text is None:
        if required:
            problems.append(f'parameter {name} is missing')
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        problems.append(f'parameter {name} = {text!r} is not a finite number')
        return None
    return value


def _build_model(parameters, problems):
    """The body, mass model and mode the recorded parameters describe, or None."""
    found = len(problems)
    values = {name: _float_parameter(parameters, name, problems)
              for name in ('a', 'b', 'delta', 'mass', 'gravity', 'omega0')}
    rate = _float_parameter(parameters, 'rate', problems, required=False)
    solver = _float_parameter(parameters, 'tolerance', problems, required=False)
    model_name = parameters.get('mass_model', 'laminae')
    if model_name not in MODELS:
        problems.append(f'parameter mass_model = {model_name!r} is not one of {MODELS}')
    mode = parameters.get('mode', 'dynamic')
    if mode not in MODES:
        problems.append(f'parameter mode = {mode!r} is not one of {MODES}')
    moments = None
    if model_name == 'custom':
        moments = [float(x) for x in _NUMBER.findall(parameters.get('principal_moments', ''))]
        if len(moments) != 3:
            problems.append('parameter principal_moments = '
                            f'{parameters.get("principal_moments")!r} is not 3 numbers')
    if len(problems) > found:
        return None
    try:
        body = TwoDiskBody(values['a'], values['b'], values['delta'])
        mass = mass_properties(model_name, body.a, body.b, body.delta, values['mass'],
                               principal_moments=moments)
        dynamics = RollingDynamics(body, mass, values['gravity'])
    except (ValueError, TypeError, RuntimeError) as error:
        problems.append(f'the recorded parameters define no body: {error}')
        return None
    if rate is not None and rate <= 0:
        problems.append(f'parameter rate = {rate!r} is not positive')
        rate = None
    solver = solver if solver is not None and 0 < solver < 1 else 1e-10
    return _Model(body, dynamics, mode, values['omega0'], rate, solver)


# --------------------------------------------------------------------------------------------
# Joined samples and finite differences.

@dataclass
class _Samples:
    """Pose, contacts and rolling state at the stamps they share."""

    stamp_ns: np.ndarray
    t: np.ndarray               # s from the first stamp of the recording
    position_g: np.ndarray
    rotation: Rotation
    contact_a: np.ndarray
    contact_b: np.ndarray
    angles: np.ndarray          # θ, ψ, u
    rates: np.ndarray           # θ̇, ψ̇, u̇


def _first_of_each(stamps):
    """Indices of the first message of every distinct stamp, sorted by stamp."""
    _, index = np.unique(stamps, return_index=True)
    return index


def _join(series, t0_ns):
    """Samples at the stamps present in pose, both contacts and rolling state."""
    if any(role not in series or len(series[role]) == 0 for role in SAMPLED):
        return None
    firsts = {role: _first_of_each(series[role].stamp_ns) for role in SAMPLED}
    common = series['pose'].stamp_ns[firsts['pose']]
    for role in SAMPLED[1:]:
        common = np.intersect1d(common, series[role].stamp_ns[firsts[role]],
                                assume_unique=True)
    if common.size == 0:
        return None
    picked = {}
    for role in SAMPLED:
        stamps = series[role].stamp_ns[firsts[role]]
        picked[role] = firsts[role][np.searchsorted(stamps, common)]
    pose = series['pose'].values
    quaternion = pose['quaternion'][picked['pose']]
    state = series['rolling_state'].values
    return _Samples(
        stamp_ns=common, t=(common - t0_ns) * 1e-9,
        position_g=pose['position'][picked['pose']],
        rotation=Rotation.from_quat(quaternion),
        contact_a=series['contact_a'].values['point'][picked['contact_a']],
        contact_b=series['contact_b'].values['point'][picked['contact_b']],
        angles=state['position'][picked['rolling_state']],
        rates=state['velocity'][picked['rolling_state']])


_STENCIL = np.arange(-2, 3)


def finite_differences(t, position, rotation, step):
    """Fourth-order central differences of a rigid motion at samples with regular neighbours.

    Parameters
    ----------
    t : numpy.ndarray, shape (N,)
        Sample times (s), increasing.
    position : numpy.ndarray, shape (N, 3)
        A point of the body (m).
    rotation : scipy.spatial.transform.Rotation, N rotations
        Body → world.
    step : float
        Nominal interval h (s).  Sample i is used if its four intervals to the samples
        i − 2 ... i + 2 are all within 1 % of ``step`` (so never across a gap).

    Returns
    -------
    index : numpy.ndarray of int
        The samples used.
    velocity : numpy.ndarray, shape (K, 3)
        dx/dt (m/s) from x at t_{i-2} ... t_{i+2}.
    angular_velocity : numpy.ndarray, shape (K, 3)
        World frame (rad/s): the derivative at τ = 0 of the rotation vector of
        R(t + τ) R(t)ᵀ, from the same five samples.

    Notes
    -----
    The weights are those of the five-point stencil at the actual stamps (for equal intervals
    (1, −8, 0, 8, −1) / 12h), exact for polynomials of degree 4: the error is ~ h⁴/30 × the
    fifth derivative, i.e. ~ (ω h)⁴ relative for a body turning at ω.
    """
    t = np.asarray(t, dtype=float)
    none = np.zeros(0, dtype=int), np.zeros((0, 3)), np.zeros((0, 3))
    if t.size < 5:
        return none
    regular = np.abs(np.diff(t) - step) <= STAMP_TOLERANCE * step
    usable = regular[:-3] & regular[1:-2] & regular[2:-1] & regular[3:]
    index = np.nonzero(usable)[0] + 2
    if index.size == 0:
        return none
    around = index[:, None] + _STENCIL[None, :]
    offsets = (t[around] - t[index][:, None]) / step            # ≈ -2 ... 2
    powers = offsets[:, None, :] ** np.arange(5)[None, :, None]  # (K, degree, node)
    unit = np.zeros((index.size, 5, 1))
    unit[:, 1] = 1.0
    weights = np.linalg.solve(powers, unit)[..., 0] / step       # d/dt at offset 0
    displacement = position[around] - position[index][:, None, :]
    velocity = np.einsum('kn,knj->kj', weights, displacement)
    reference_inverse = rotation[index].inv()
    turns = np.stack([(rotation[index + k] * reference_inverse).as_rotvec()
                      for k in _STENCIL], axis=1)
    angular_velocity = np.einsum('kn,knj->kj', weights, turns)
    return index, velocity, angular_velocity


@dataclass
class _Motion:
    """Velocities of the recorded poses and of the model's poses at the recorded phases."""

    index: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    model_velocity: np.ndarray
    model_angular_velocity: np.ndarray
    model_state: object
    step: float


def _motion(samples, model, step):
    phase = np.unwrap(samples.angles[:, 2])
    state = model.dynamics.cycle.state(phase)
    index, velocity, omega = finite_differences(samples.t, samples.position_g,
                                                samples.rotation, step)
    model_rotation = Rotation.from_matrix(state.rotation)
    _, model_velocity, model_omega = finite_differences(samples.t, state.position_g,
                                                        model_rotation, step)
    return _Motion(index, velocity, omega, model_velocity, model_omega, state, step)


def _kinetic_energy(mass, velocity, omega, rotation):
    """½ M |v|² + ½ ωᵀ (R I Rᵀ) ω, with ω in the world frame (J)."""
    body_omega = rotation.inv().apply(omega)
    spin = np.einsum('ni,ij,nj->n', body_omega, mass.inertia, body_omega)
    return 0.5 * mass.mass * np.sum(velocity * velocity, axis=1) + 0.5 * spin


# --------------------------------------------------------------------------------------------
# The checks.

def _where(samples, k):
    return f'at t = {samples.t[k]:.6g} s'


def _fmt(value):
    return 'n/a' if value is None or not math.isfinite(value) else f'{value:.3g}'


def _check(name, value, tolerance, unit='', detail=()):
    """A :class:`Check` titled from :data:`TITLES`; it passes if ``value <= tolerance``."""
    passed = value is not None and tolerance is not None and bool(value <= tolerance)
    return Check(name, TITLES[name], passed, _plain(value), _plain(tolerance), unit,
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
        body = model.body
        return _check('inputs', 0, 0, 'problems', [
            f'body a = {body.a:g} m, b = {body.b:g} m, delta = {body.delta:g} m, mass model '
            f'{model.dynamics.mass.model}, mode {model.mode}; topics '
            + ', '.join(chosen[role] for role in TOPIC_TYPES if role in chosen)])
    return _check('inputs', len(detail), 0, 'problems', detail)


def _check_ground(series, scale):
    points = [series[role].values['point'] for role in ('contact_a', 'contact_b')
              if role in series and len(series[role])]
    if not points:
        return _not_evaluated('ground', 'no contact points recorded', 'm')
    heights = np.abs(np.concatenate(points)[:, 2])
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


def _check_tangent_plane(samples, geometry):
    up = samples.rotation.apply(geometry.ground_normal)
    angle = np.arctan2(np.hypot(up[:, 0], up[:, 1]), up[:, 2])
    k = int(np.argmax(angle))
    return _check('tangent_plane', float(angle[k]), ANGLE_TOLERANCE, 'rad', [
        f'largest angle between R n(u) and the up direction, {_where(samples, k)}'])


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


def _check_no_slip(samples, motion, scale):
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
    worst = int(np.argmax(recorded))
    omega_h = float(np.max(np.linalg.norm(motion.angular_velocity, axis=1))) * motion.step
    if speed > roundoff:
        unit, norm = '', speed
        what = f'max |v_A|, |v_B| / max |v_G| (max |v_G| = {speed:.4g} m/s)'
    else:
        unit, norm = 'm/s', 1.0
        what = 'max |v_A|, |v_B| (the body is at rest)'
    fd_error = float(np.max(expected)) / norm
    return _check('no_slip', float(recorded[worst]) / norm,
                  FD_MARGIN * fd_error + roundoff / norm, unit, [
                      f'{what}, worst {_where(samples, k[worst])}, {k.size} samples',
                      f'FD-limited: the model poses at the recorded phases (rolling without '
                      f'slip) show {fd_error:.3g} at h = {motion.step:.4g} s '
                      f'((ω h)⁴ = {omega_h**4:.3g}); tolerance {FD_MARGIN:g} × that + '
                      'round-off'])


def _solver_allowance(model):
    return max(SOLVER_FLOOR, 10.0 * model.solver_tolerance)


def _energies(samples, motion, model):
    """Energy from the recorded poses, from the model's poses and exact, at motion.index."""
    k = motion.index
    mass, gravity = model.dynamics.mass, model.dynamics.gravity
    recorded = (_kinetic_energy(mass, motion.velocity, motion.angular_velocity,
                                samples.rotation[k])
                + mass.mass * gravity * samples.position_g[k, 2])
    state = motion.model_state
    model_fd = (_kinetic_energy(mass, motion.model_velocity, motion.model_angular_velocity,
                                Rotation.from_matrix(state.rotation[k]))
                + mass.mass * gravity * state.position_g[k, 2])
    phase = np.unwrap(samples.angles[:, 2])[k]
    exact = model.dynamics.energy(phase, samples.rates[k, 2])
    return recorded, model_fd, exact


def _check_energy(samples, motion, model):
    k = motion.index
    if k.size == 0:
        return _not_evaluated('energy', _NO_DIFFERENCES)
    if not np.all(np.isfinite(samples.rates[k, 2])):
        return _not_evaluated('energy', 'rolling_state carries no phase rate: the FD error '
                                        'cannot be estimated')
    scale = model.dynamics.energy_scale
    recorded, model_fd, exact = _energies(samples, motion, model)
    drift = np.abs(recorded - recorded[0]) / scale
    worst = int(np.argmax(drift))
    fd_error = float(np.max(np.abs(model_fd - exact))) / scale
    solver = _solver_allowance(model)
    model_drift = float(np.max(np.abs(exact - exact[0]))) / scale
    return _check('energy', float(drift[worst]), 2 * FD_MARGIN * fd_error + solver, '', [
        f'max |E − E0| / (M g L), E0 = {recorded[0]:.8g} J, M g L = {scale:.4g} J; worst '
        f'{_where(samples, k[worst])}, {k.size} samples',
        f'FD-limited: the model poses at the recorded phases give E within {fd_error:.3g} of '
        f'the exact E(u, u̇); tolerance 2 × {FD_MARGIN:g} × that + {solver:.3g} (solver)',
        f'the exact E(u, u̇) of the recorded rolling_state drifts by {model_drift:.3g}'])


def _check_angular_speed(samples, motion, model):
    k = motion.index
    if k.size == 0:
        return _not_evaluated('angular_speed', _NO_DIFFERENCES)
    target = abs(model.omega0)
    speed = np.linalg.norm(motion.angular_velocity, axis=1)
    model_speed = np.linalg.norm(motion.model_angular_velocity, axis=1)
    if target > 0:
        error = np.abs(speed - target) / target
        fd_error = float(np.max(np.abs(model_speed - target))) / target
        tolerance = FD_MARGIN * fd_error + _solver_allowance(model)
        unit, what = '', f'max ||ω| − |omega0|| / |omega0|, |omega0| = {target:g} rad/s'
    else:
        error = speed
        fd_error = float(np.max(model_speed))
        tolerance = FD_MARGIN * fd_error + ROUNDOFF / motion.step
        unit, what = 'rad/s', 'max |ω| (omega0 = 0)'
    worst = int(np.argmax(error))
    return _check('angular_speed', float(error[worst]), tolerance, unit, [
        f'{what}; worst {_where(samples, k[worst])}, {k.size} samples',
        f'FD-limited: the model poses at the recorded phases show {fd_error:.3g}; '
        f'tolerance {FD_MARGIN:g} × that + solver allowance'])


def _nominal_step_ns(series, model):
    """1/rate in ns from the recorded rate, else the median stamp interval; and its source."""
    if model is not None and model.rate:
        return 1e9 / model.rate, f'1/rate, rate = {model.rate:g} Hz'
    intervals = [np.diff(series[role].stamp_ns) for role in SAMPLED
                 if role in series and len(series[role]) > 1]
    if not intervals:
        return None, 'no intervals'
    return float(np.median(np.concatenate(intervals))), 'median interval (no valid rate)'


def _check_timestamps(series, step_ns, source):
    roles = [role for role in SAMPLED if role in series]
    if step_ns is None or not roles:
        return _check('timestamps', None, STAMP_TOLERANCE, '', ['too few messages'])
    detail, worst = [], 0.0
    for role in roles:
        stamps = series[role].stamp_ns
        if stamps.size < 2:
            detail.append(f'{series[role].topic}: {stamps.size} message(s), no interval')
            worst = math.inf
            continue
        intervals = np.diff(stamps)
        deviation = np.abs(intervals - step_ns) / step_ns
        bad = np.nonzero(deviation > STAMP_TOLERANCE)[0]
        worst = max(worst, float(np.max(deviation)))
        line = f'{series[role].topic}: {stamps.size} stamps'
        if bad.size:
            first = int(bad[0])
            line += (f', {bad.size} bad intervals, the first {intervals[first] * 1e-9:.6g} s '
                     f'after t = {stamps[first] * 1e-9:.6g} s')
            if np.any(intervals <= 0):
                line += f', {int(np.sum(intervals <= 0))} not increasing'
        detail.append(line)
    detail.append(f'nominal interval {step_ns * 1e-9:.6g} s ({source}); '
                  f'tolerance {STAMP_TOLERANCE:.0%} of it')
    return _check('timestamps', worst, STAMP_TOLERANCE, '', detail)


def _check_stamps(series, truncated):
    roles = [role for role in SAMPLED if role in series and len(series[role])]
    detail, mismatches = [], 0
    for role in roles:
        data = series[role]
        count = int(np.sum(data.stamp_ns != data.log_ns) + np.sum(data.log_ns != data.publish_ns))
        if count:
            detail.append(f'{data.topic}: {count} header stamp / log time / publish time '
                          'mismatches')
        mismatches += count
    if roles:
        sets = {role: np.unique(series[role].stamp_ns) for role in roles}
        union = np.unique(np.concatenate(list(sets.values())))
        if truncated:
            union = union[union <= min(stamps[-1] for stamps in sets.values())]
        for role, stamps in sets.items():
            lacking = union.size - np.intersect1d(union, stamps).size
            if lacking:
                detail.append(f'{series[role].topic}: lacks {lacking} stamps of the others')
            mismatches += lacking
    if not detail:
        detail.append('pose, contacts and rolling_state share their stamps; header stamp = '
                      'log time = publish time'
                      + (' (the tail cut by the truncation ignored)' if truncated else ''))
    return _check('stamps', mismatches, 0, 'mismatches', detail)


def _run(checks, name, function, *args):
    """Append ``function(*args)``; an error while evaluating it is a failed check."""
    try:
        checks.append(function(*args))
    except Exception as error:  # noqa: BLE001 - reported as a failed check, not a traceback
        checks.append(_not_evaluated(name, f'cannot be evaluated: {type(error).__name__}: '
                                           f'{" ".join(str(error).split())}'))


# --------------------------------------------------------------------------------------------
# Inspection.

_DECODED = frozenset(TOPIC_TYPES)


def _summary(recording, chosen, parameters, samples, model, t0_ns, t1_ns):
    truncated = recording.truncated
    topics = []
    times = {}
    for message in recording.messages:
        first, last = times.get(message.topic, (message.log_time_ns, message.log_time_ns))
        times[message.topic] = (min(first, message.log_time_ns), max(last, message.log_time_ns))
    for name in sorted(recording.topics):
        info = recording.topics[name]
        first, last = times.get(name, (None, None))
        rate = None
        if info.message_count > 1 and last > first:
            rate = (info.message_count - 1) / ((last - first) * 1e-9)
        topics.append({'topic': name, 'type': info.type_name, 'count': info.message_count,
                       'first_s': None if first is None else (first - t0_ns) * 1e-9,
                       'last_s': None if last is None else (last - t0_ns) * 1e-9,
                       'rate_hz': rate, 'role': next((r for r, t in chosen.items()
                                                      if t == name), None)})
    size = recording.total_bytes
    summary = {
        'file': recording.path,
        'size_bytes': size,
        'profile': recording.profile,
        'library': recording.library,
        'truncated': truncated,
        'recovered': {'messages': len(recording.messages), 'bytes': recording.recovered_bytes,
                      'total_bytes': size,
                      'fraction': recording.recovered_bytes / size if size else None},
        'message_count': len(recording.messages),
        'start_ns': t0_ns,
        'end_ns': t1_ns,
        'duration_s': None if t0_ns is None else (t1_ns - t0_ns) * 1e-9,
        'topics': topics,
        'parameters': dict(parameters),
        'samples': 0 if samples is None else int(samples.stamp_ns.size),
        'mode': None if model is None else model.mode,
    }
    return _plain(summary)


def inspect_recording(path):
    """Read a recording and run every check.

    Parameters
    ----------
    path : str or os.PathLike
        An MCAP file written by the ``roller`` node (or a truncated copy).

    Returns
    -------
    Inspection

    Raises
    ------
    RecordingError
        If the file cannot be read at all (missing, a directory, not MCAP, damaged).
    """
    recording = read_recording(path, decode=lambda topic: _role(topic) in _DECODED)
    problems = []
    chosen = _select_topics(recording.topics, problems)
    series = _extract(recording, chosen, problems)
    parameters = recording.metadata.get(METADATA_NAME)
    if parameters is None:
        problems.append(f'no metadata record {METADATA_NAME!r} (node parameters)')
        parameters = {}
    model = _build_model(parameters, problems) if METADATA_NAME in recording.metadata else None
    log_times = [message.log_time_ns for message in recording.messages]
    t0_ns = min(log_times) if log_times else None
    t1_ns = max(log_times) if log_times else None
    stamp0 = min([int(s.stamp_ns.min()) for s in series.values() if len(s)] or [0])
    samples = None
    try:
        samples = _join(series, stamp0)
    except ValueError as error:  # e.g. a zero quaternion
        problems.append(f'cannot use the poses: {" ".join(str(error).split())}')
    checks = []
    scale = _coordinate_scale(model, series)
    _run(checks, 'inputs', _check_inputs, problems, chosen, model)
    _run(checks, 'ground', _check_ground, series, scale)
    step_ns, source = _nominal_step_ns(series, model)
    motion = _physics_checks(checks, samples, model, step_ns, scale, parameters)
    _run(checks, 'timestamps', _check_timestamps, series, step_ns, source)
    _run(checks, 'stamps', _check_stamps, series, recording.truncated)
    summary = _summary(recording, chosen, parameters, samples, model, t0_ns, t1_ns)
    summary['diagnostics'] = _diagnostics_summary(series)
    return Inspection(summary, checks, _plot_series(series, samples, motion, model, stamp0))


def _physics_checks(checks, samples, model, step_ns, scale, parameters):
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
        _run(checks, 'tangent_plane', _check_tangent_plane, samples, geometry)
        _run(checks, 'theta', _check_theta, samples, geometry)
    _run(checks, 'psi', _check_psi, samples, model.body)
    motion, reason = None, 'no stamp interval'
    if step_ns is not None:
        try:
            motion = _motion(samples, model, step_ns * 1e-9)
        except Exception as error:  # noqa: BLE001 - reported as failed checks
            reason = f'{type(error).__name__}: {" ".join(str(error).split())}'
    if motion is None:
        _not_evaluated_all(checks, ('no_slip', speed_check), f'no finite differences: {reason}')
        return None
    _run(checks, 'no_slip', _check_no_slip, samples, motion, scale)
    if model.mode == 'kinematic':
        _run(checks, 'angular_speed', _check_angular_speed, samples, motion, model)
    else:
        _run(checks, 'energy', _check_energy, samples, motion, model)
    return motion


def _not_evaluated_all(checks, names, reason):
    checks.extend(_not_evaluated(name, f'not evaluated: {reason}') for name in names)


def _coordinate_scale(model, series):
    size = model.body.size if model is not None else 1.0
    pose = series.get('pose')
    if pose is not None and len(pose):
        size = max(size, float(np.max(np.abs(pose.values['position']))))
    return size


def _diagnostics_summary(series):
    diagnostics = series.get('diagnostics')
    if diagnostics is None or not len(diagnostics):
        return None
    energy = diagnostics.values['energy']
    drift = diagnostics.values['energy_drift']
    return _plain({
        'topic': diagnostics.topic,
        'count': len(diagnostics),
        'energy_first': energy[0] if energy.size else None,
        'energy_last': energy[-1] if energy.size else None,
        'max_energy_drift': float(np.nanmax(np.abs(drift))) if np.any(np.isfinite(drift))
        else None,
    })


def _plot_series(series, samples, motion, model, stamp0):
    out = {}
    for role, key in (('contact_a', 'point'), ('contact_b', 'point'), ('pose', 'position')):
        if role in series and len(series[role]):
            out[role] = series[role].values[key]
            out[f't_{role}'] = (series[role].stamp_ns - stamp0) * 1e-9
    if 'diagnostics' in series and len(series['diagnostics']):
        out['t_diagnostics'] = (series['diagnostics'].stamp_ns - stamp0) * 1e-9
        out['energy_diagnostics'] = series['diagnostics'].values['energy']
    if motion is not None and motion.index.size:
        k = motion.index
        mass, gravity = model.dynamics.mass, model.dynamics.gravity
        kinetic = _kinetic_energy(mass, motion.velocity, motion.angular_velocity,
                                  samples.rotation[k])
        out['t_fd'] = samples.t[k]
        out['kinetic_fd'] = kinetic
        out['potential_fd'] = mass.mass * gravity * samples.position_g[k, 2]
        out['energy_scale'] = np.array(model.dynamics.energy_scale)
        if np.all(np.isfinite(samples.rates[:, 2])):
            phase = np.unwrap(samples.angles[:, 2])
            out['t_model'] = samples.t
            out['energy_model'] = model.dynamics.energy(phase, samples.rates[:, 2])
    return out


# --------------------------------------------------------------------------------------------
# Output.

def _size(nbytes):
    for unit in ('B', 'KiB', 'MiB', 'GiB'):
        if nbytes < 1024 or unit == 'GiB':
            return f'{nbytes:.0f} {unit}' if unit == 'B' else f'{nbytes:.1f} {unit}'
        nbytes /= 1024
    return f'{nbytes} B'


def _value(value, unit):
    if value is None:
        return 'n/a'
    text = f'{value:.3g}'
    return f'{text} {unit}' if unit else text


def format_report(inspection):
    """The human-readable report of an :class:`Inspection` (several lines, no final newline)."""
    s = inspection.summary
    lines = [f'{PROG}: {s["file"]}',
             f'  file: {_size(s["size_bytes"])}, MCAP profile {s["profile"]!r}, '
             f'written by {s["library"] or "?"}']
    if s['truncated']:
        rec = s['recovered']
        fraction = rec['fraction'] if rec['fraction'] is not None else 0.0
        lines.append(f'  TRUNCATED (no footer: the writer did not close it): recovered '
                     f'{rec["messages"]} messages from {rec["bytes"]} of {rec["total_bytes"]} '
                     f'bytes ({fraction:.1%}); the checks below are of that part')
    if s['duration_s'] is not None:
        lines.append(f'  duration: {s["duration_s"]:.3f} s, {s["message_count"]} messages on '
                     f'{len(s["topics"])} topics')
    else:
        lines.append('  no messages')
    lines.append('topics:')
    width = max([len(t['topic']) for t in s['topics']] + [5])
    type_width = max([len(t['type']) for t in s['topics']] + [4])
    for topic in s['topics']:
        rate = f'{topic["rate_hz"]:9.3f} Hz' if topic['rate_hz'] is not None else '        -'
        lines.append(f'  {topic["topic"]:<{width}}  {topic["type"]:<{type_width}}  '
                     f'{topic["count"]:7d}  {rate}')
    lines.append(f'parameters (metadata {METADATA_NAME!r}):')
    if s['parameters']:
        items = [f'{key} = {value}' for key, value in s['parameters'].items()]
        row = '  '
        for item in items:
            if len(row) + len(item) > 96 and row.strip():
                lines.append(row.rstrip())
                row = '  '
            row += item + '; '
        lines.append(row.rstrip().rstrip(';'))
    else:
        lines.append('  (none)')
    if s.get('diagnostics'):
        d = s['diagnostics']
        lines.append(f'diagnostics: {d["count"]} messages, energy {_value(d["energy_first"], "J")}'
                     f' → {_value(d["energy_last"], "J")}, max recorded energy_drift '
                     f'{_value(d["max_energy_drift"], "")}')
    else:
        lines.append('diagnostics: none recorded')
    lines.append(f'samples: {s["samples"]} stamps shared by pose, contacts and rolling_state'
                 + (f' ({s["mode"]} mode)' if s['mode'] else ''))
    lines.append('checks:')
    for check in inspection.checks:
        lines.append(f'  {check.status}  {check.name:<14} {_value(check.value, check.unit)} '
                     f'(tolerance {_value(check.tolerance, check.unit)})  {check.title}')
        for line in check.detail:
            lines.extend(textwrap.wrap(line, 99, initial_indent=' ' * 8,
                                       subsequent_indent=' ' * 10))
    failed = [check.name for check in inspection.checks if not check.passed]
    if failed:
        lines.append(f'result: FAIL ({len(failed)} of {len(inspection.checks)} checks failed: '
                     f'{", ".join(failed)})')
    else:
        lines.append(f'result: PASS (all {len(inspection.checks)} checks passed)')
    return '\n'.join(lines)


# --------------------------------------------------------------------------------------------
# Command line.

def _parser():
    parser = argparse.ArgumentParser(
        prog=PROG,
        description='Summarise a roller MCAP recording and check it offline against the '
                    'physics (contacts, no slip, energy, timestamps).',
        epilog='Exit status: 0 every check passes, 1 a check fails, 2 the file cannot be read '
               '(or the plot cannot be written).')
    parser.add_argument('file', help='the .mcap recording')
    parser.add_argument('--json', action='store_true',
                        help='print one JSON document (summary and checks) instead of text')
    parser.add_argument('--plot', metavar='PNG',
                        help='write a figure: traces on the ground, height of G, energy')
    return parser


def _print(text):
    """Print to stdout; a reader that went away (``| head``) is not an error."""
    try:
        print(text, flush=True)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def main(argv=None):
    """Run ``twodisk-inspect``; return the exit status.

    0 when every check passes, 1 when a check fails, 2 when the file cannot be read or the
    plot cannot be written (one line on stderr, no traceback).

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name; ``sys.argv[1:]`` if omitted.

    Returns
    -------
    int
    """
    args = _parser().parse_args(argv)
    try:
        inspection = inspect_recording(args.file)
    except RecordingError as error:
        print(f'{PROG}: {error}', file=sys.stderr)
        return 2
    if args.json:
        _print(json.dumps(inspection.as_dict(), indent=2, allow_nan=False, ensure_ascii=False))
    else:
        _print(format_report(inspection))
    if args.plot:
        try:
            from .inspection_plot import plot_inspection
            plot_inspection(inspection, args.plot)
        except (OSError, ValueError) as error:
            print(f'{PROG}: cannot write plot {args.plot}: {" ".join(str(error).split())}',
                  file=sys.stderr)
            return 2
        if not args.json:
            _print(f'plot: {args.plot}')
    return 0 if inspection.passed else 1


if __name__ == '__main__':
    sys.exit(main())

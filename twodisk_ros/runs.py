"""Runs to show: sampled poses and contacts, from the library or from a recording.

A :class:`Run` holds everything a frame needs, in the world frame (Z up, m, s, N): G, A, B
and the orientation at increasing times, optionally the ground forces at A and B, and the
body, whose real outlines it draws (:mod:`~twodisk_ros.physics.bodies.outline`). It comes from the
physics (:func:`library_run`, the parameters of the node's contract) or from an MCAP
recording of the node (:func:`recorded_run`), both through the run description
(:class:`~twodisk_ros.run.description.RunDescription`), so any shape the node runs is
shown with the body the node moved. The animation (plotting/animation.py) and the
Foxglove view (view/) read runs; nothing here plots. No matplotlib and no rclpy here.
"""

from dataclasses import dataclass
import math

import numpy as np

from .recordings.errors import one_line
from .recordings.reader import read_recording
from .model.frames import disk_rims
from .physics.bodies.outline import DEFAULT_TOLERANCE
from .run.parameters import BY_NAME, DEFAULTS
from .run.params_yaml import ArgumentError, params_file_values
from .run.scene_simulation import flat_free
from .run.simulation import Simulation
from .physics.forces.contact import ContactForceModel
from .physics.motion.simulate import simulate
from .run.description import RunDescription

__all__ = ['Run', 'RunError', 'library_run', 'recorded_run', 'settings_from',
           'rotation_matrices']

#: Samples per second of a library run (the traces between frames are drawn from them).
LIBRARY_RATE = 200.0


class RunError(ValueError):
    """Input that defines no run (unreadable file, invalid parameters); one line."""


@dataclass
class Run:
    """A sampled motion of one body (world frame, SI units), times increasing.

    ``force_a``/``force_b`` are the ground forces on the body at A and B (N), or None.
    ``quaternion`` holds the orientations as sampled or recorded (x, y, z, w, body → world),
    ``stamp_ns`` the recorded header stamps (ns; None for a library run), ``settings`` the
    node's settings the run was made with (for a recording: the last recorded). ``body`` is
    any body with a ``lamina`` (EllipseBody, LaminaBody, ContactSolver).
    """

    body: object
    t: np.ndarray              #: (n,) s
    position_g: np.ndarray     #: (n, 3) m
    contact_a: np.ndarray      #: (n, 3) m
    contact_b: np.ndarray      #: (n, 3) m
    rotation: np.ndarray       #: (n, 3, 3) body → world
    force_a: np.ndarray | None = None
    force_b: np.ndarray | None = None
    weight: float = 1.0        #: M g (N), the scale of the force arrows
    label: str = ''            #: one line describing the body and the motion
    quaternion: np.ndarray | None = None   #: (n, 4) x, y, z, w
    stamp_ns: np.ndarray | None = None     #: (n,) int64 ns
    settings: object = None                #: RollerSettings
    slope: float = 0.0         #: β (rad): the ground through the origin, normal ground_normal

    def __len__(self):
        return len(self.t)

    @property
    def ground_normal(self):
        """The ground's unit normal (sin β, 0, cos β) in the world frame: the ground is the
        plane through the origin with this normal, going down along +X at the slope β
        (the node's ``frame_id`` is gravity-aligned, docs/physics.md "Scenes")."""
        return np.array([math.sin(self.slope), 0.0, math.cos(self.slope)])

    def ground_height(self, x):
        """Z (m) of the ground at world X = ``x`` (m): −x tan β."""
        return -np.asarray(x, dtype=float) * math.tan(self.slope)

    def span(self, start, stop):
        """The samples with start ≤ t ≤ stop (a new Run)."""
        keep = (self.t >= start - 1e-9) & (self.t <= stop + 1e-9)
        pick = (lambda x: None if x is None else x[keep])
        return Run(self.body, self.t[keep], self.position_g[keep], self.contact_a[keep],
                   self.contact_b[keep], self.rotation[keep], pick(self.force_a),
                   pick(self.force_b), self.weight, self.label, pick(self.quaternion),
                   pick(self.stamp_ns), self.settings, self.slope)

    def outlines(self, index, tolerance=DEFAULT_TOLERANCE):
        """World points (m) of both disk rims at sample ``index``: two closed arrays (N + 1, 3)
        (the last point the first), each starting at its disk's far tip and reaching the near
        tip at index N/2; the real outline of ``body.lamina`` to a polygon error of
        ``tolerance`` × its size (:func:`~twodisk_ros.model.frames.disk_rims`)."""
        rims = self.__dict__.setdefault('_rims', {})
        if tolerance not in rims:
            rims[tolerance] = disk_rims(self.body, tolerance)
        r, g = self.rotation[index], self.position_g[index]
        return tuple(rim @ r.T + g for rim in rims[tolerance])


def rotation_matrices(quaternions):
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) given as x, y, z, w."""
    q = np.asarray(quaternions, dtype=float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)],
        axis=-2)


def _describe(run):
    """One short line on the body and the motion (the animation's title)."""
    s = run.settings
    if s.shape == 'ellipse':
        body = f'a = {s.a:.4g} m, b = {s.b:.4g} m'
    elif s.shape == 'superellipse':
        body = f'superellipse n = {s.exponent:.3g}, a = {s.a:.4g} m, b = {s.b:.4g} m'
    elif s.shape == 'egg':
        body = f'egg a = {s.a:.4g} m, b = {s.b:.4g} m, ε = {run.lamina.epsilon:.3g} m'
    else:
        body = 'outline'
    if s.shape != 'ellipse' and s.arrangement != 'parallel':
        body += f', {s.arrangement}'
    return (f'{body}, Δ = {s.delta:.4g} m, {s.mass_model}, {s.mode}, '
            f'θ0 = {s.theta0:.3g} rad, ω0 = {s.omega0:.3g} rad/s' + _describe_scene(s))


def _describe_scene(s):
    """', slope …, drive …, damping …' for what the scene adds to the flat free one."""
    parts = []
    if s.slope:
        parts.append(f'slope {s.slope:.3g} rad, heading0 {s.heading0:.3g} rad')
    if s.drive != 'none':
        parts.append(f'{s.drive} drive')
    if s.rolling_resistance:
        parts.append(f'μr = {s.rolling_resistance:.3g}')
    if s.damping:
        parts.append(f'damping {s.damping:.3g} N m s')
    return ''.join(', ' + part for part in parts)


def _description(settings):
    """The :class:`RunDescription` of checked settings, or :class:`RunError` (one line)."""
    try:
        run = RunDescription(settings)
        run.dynamics                      # the body and its mass model, built now
        return run
    except (ValueError, TypeError, RuntimeError, ArithmeticError) as error:
        raise RunError(f'the parameters define no run: {one_line(error)}') from None


def _params_file_values(path):
    """The ros__parameters a params file (the node's format) sets for the roller node."""
    try:
        values = params_file_values(path)
    except ArgumentError as error:
        raise RunError(one_line(error)) from None
    if not values:
        raise RunError(f'params file {path}: no ros__parameters for the roller node')
    return values


def settings_from(params_file=None, **values):
    """Checked node settings from a params file and keyword values (None values are skipped).

    Names outside the node's parameter contract are ignored (as the node ignores them).
    Raises :class:`RunError` (one line) for an unreadable file or an invalid value.
    """
    merged = _params_file_values(params_file) if params_file else {}
    merged.update({k: v for k, v in values.items() if v is not None})
    known = {k: v for k, v in merged.items() if k in BY_NAME}
    if isinstance(known.get('principal_moments'), list):
        known['principal_moments'] = tuple(known['principal_moments'])
    for name in ('a', 'b', 'delta', 'mass', 'gravity', 'theta0', 'omega0', 'exponent',
                 'egg_asymmetry', 'slope', 'heading0', 'drive_lag', 'cmd_timeout',
                 'rolling_resistance', 'damping'):
        if isinstance(known.get(name), int) and not isinstance(known[name], bool):
            known[name] = float(known[name])
    try:
        return DEFAULTS.with_values(**known).checked()
    except (ValueError, RuntimeError) as error:
        raise RunError(one_line(error)) from None


def library_run(settings=None, *, stop=6.0, rate=LIBRARY_RATE, forces=False, **values):
    """Simulate a run of the node's physics over [0, stop] s, sampled at ``rate`` Hz.

    Parameters
    ----------
    settings : RollerSettings, optional
        The node's settings (a, b, delta, mass_model, mode, theta0, branch, omega0, ...);
        built from ``values`` (parameter names of the node) if omitted.
    stop : float
        End time (s), > 0.
    rate : float
        Samples per second.
    forces : bool
        Also compute the ground forces at A and B (:class:`ContactForceModel`).
    """
    if settings is None:
        settings = settings_from(**values)
    if not (math.isfinite(stop) and stop > 0):
        raise RunError(f'the run must end after 0 s, got stop = {stop!r} s')
    description = _description(settings)
    s, body, dynamics = description.settings, description.body, description.dynamics
    count = max(2, int(math.ceil(stop * rate)) + 1)
    t = np.linspace(0.0, stop, count)
    if not flat_free(s):
        return _scene_run(description, t, forces)
    motion = simulate(dynamics, t, mode=s.mode, theta0=s.theta0, branch=s.branch,
                      omega0=s.omega0, method=s.method, tolerance=s.tolerance)
    poses = dynamics.cycle.poses(motion.phase)
    run = Run(body, t, poses.position_g, poses.contact_a, poses.contact_b,
              rotation_matrices(poses.quaternion), weight=dynamics.mass.mass * s.gravity,
              label=_describe(description), quaternion=poses.quaternion, settings=s)
    if forces:
        computed = ContactForceModel(dynamics).along(motion)
        run.force_a, run.force_b = computed.force_a, computed.force_b
    return run


def _scene_run(description, t, forces):
    """A run of a scene (slope, drive, dissipation) as the node's batch run makes it: the
    node's :class:`~twodisk_ros.run.simulation.Simulation`, with no command and no service
    call (a speed drive holds its starting speed, a torque drive gives 0 N m)."""
    s = description.settings
    try:
        simulation = Simulation(s, description)
        sample = simulation.sample(t, forces=forces)
    except (ValueError, RuntimeError, ArithmeticError) as error:
        raise RunError(f'the parameters define no run: {one_line(error)}') from None
    run = Run(description.body, t, sample.position_g, sample.contact_a, sample.contact_b,
              rotation_matrices(sample.quaternion), weight=simulation.weight,
              label=_describe(description), quaternion=sample.quaternion, settings=s,
              slope=s.slope)
    if forces:
        run.force_a, run.force_b = sample.forces.force_a, sample.forces.force_b
    return run


def _topic_role(topic):
    return topic.rstrip('/').rsplit('/', 1)[-1]


_ROLES = ('pose', 'contact_a', 'contact_b', 'wrench_a', 'wrench_b')


def _stamp(msg):
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


def _vector(v):
    return (float(v.x), float(v.y), float(v.z))


def recorded_run(path):
    """The run of an MCAP recording of the node: /pose, /contact_a, /contact_b (and
    /wrench_a, /wrench_b if recorded), the body from the ``twodisk_ros`` metadata.

    Raises :class:`RunError` (one line) if the file cannot be read or holds no run.
    """
    from .recordings.errors import RecordingError
    try:
        recording = read_recording(path, decode=lambda topic: _topic_role(topic) in _ROLES)
    except RecordingError as error:
        raise RunError(one_line(error)) from None
    if 'twodisk_ros' not in recording.metadata:
        raise RunError(f'{path}: no twodisk_ros metadata (not a recording of the roller node)')
    description, problems = RunDescription.from_recorded(recording.metadata['twodisk_ros'])
    if description is None:
        raise RunError(f'{path}: {problems[0]}')
    settings = description.settings
    by_role = {role: {} for role in _ROLES}
    for message in recording.messages:
        role = _topic_role(message.topic)
        if role in by_role and not isinstance(message.msg, bytes):
            msg = message.msg
            if role == 'pose':
                p, q = msg.pose.position, msg.pose.orientation
                value = _vector(p) + (float(q.x), float(q.y), float(q.z), float(q.w))
            elif role.startswith('contact'):
                value = _vector(msg.point)
            else:
                value = _vector(msg.wrench.force)
            by_role[role][_stamp(msg)] = value
    stamps = sorted(set(by_role['pose']) & set(by_role['contact_a']) & set(by_role['contact_b']))
    if len(stamps) < 2:
        raise RunError(f'{path}: fewer than 2 samples with pose, contact_a and contact_b')
    pose = np.array([by_role['pose'][k] for k in stamps])
    quaternion = pose[:, 3:]
    if not np.all(np.isfinite(pose)) or np.any(np.linalg.norm(quaternion, axis=1) < 0.5):
        raise RunError(f'{path}: the recorded poses are not finite unit quaternions')
    stamps_ns = np.array(stamps, dtype=np.int64)
    try:
        body = description.body        # the body the node moved (its origin the recorded pose)
    except (ValueError, TypeError, RuntimeError, ArithmeticError) as error:
        raise RunError(f'{path}: the recorded parameters define no body: '
                       f'{one_line(error)}') from None
    run = Run(body, (stamps_ns - stamps_ns[0]) * 1e-9, pose[:, :3],
              np.array([by_role['contact_a'][k] for k in stamps]),
              np.array([by_role['contact_b'][k] for k in stamps]),
              rotation_matrices(quaternion), weight=settings.mass * settings.gravity,
              label=_describe(description), quaternion=quaternion, stamp_ns=stamps_ns,
              settings=settings, slope=settings.slope)
    if by_role['wrench_a'] and by_role['wrench_b']:
        run.force_a = _resample(by_role['wrench_a'], stamps_ns)
        run.force_b = _resample(by_role['wrench_b'], stamps_ns)
    return run


def _resample(values_by_stamp, stamps_ns):
    """Vectors recorded at their own stamps, linearly interpolated at ``stamps_ns``."""
    keys = np.array(sorted(values_by_stamp), dtype=np.int64)
    values = np.array([values_by_stamp[k] for k in keys])
    x = (stamps_ns - stamps_ns[0]).astype(float)
    xp = (keys - stamps_ns[0]).astype(float)
    return np.stack([np.interp(x, xp, values[:, j]) for j in range(3)], axis=-1)

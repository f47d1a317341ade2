"""The parameter contract of the ``roller`` node: every parameter defined once.

Names, types, defaults, ranges, units, read-only flags and descriptions live in
:data:`PARAMETERS`; the node's ROS descriptors, the validation at start-up and at run time,
the inspector's reading of recorded parameters and the README table all come from here
(``tests/test_parameters.py`` compares the README with it).

The ranges are those within which the motion stays representable and the physics keeps its
stated accuracy (docs/physics.md#accuracy-and-its-limits): shapes with b/a in [0.01, 100] and
Δ/a in [1e-3, 1 − 1e-6], speeds up to 1000 rad/s. No rclpy here, so the offline tools use the
same contract.
"""

from dataclasses import dataclass, make_dataclass, replace
import math
import re

from ..model.frames import DISK_SUFFIXES, check_frame_id
from ..physics.laminae.shapes import SUPERELLIPSE_EXPONENT
from ..physics.mass.models import MODELS, custom, mass_properties
from ..physics.motion.simulate import METHODS, MODES
from ..physics.scenes.scene import DRIVES
from . import shape as shapes

__all__ = ['BY_NAME', 'CONTACT_MODELS', 'DEFAULTS', 'PARAMETERS', 'Parameter', 'RollerSettings', 'SHAPE_ONLY',
           'markdown_table', 'parse_recorded']

B_OVER_A = (0.01, 100.0)             # allowed b/a
DAMPING_RATE = 1000.0                # 1/s: damping <= this x mass x max(a, b)^2
SOLID_EXPONENT = 50.0                # largest superellipse exponent of the solid hull
DELTA_OVER_A = (1e-3, 1.0 - 1e-6)    # allowed Δ/a
SLOPE_MAX = 1.5                      # rad: |slope| allowed (86 deg; pi/2 is a wall)
#: contact_model values: exact rolling only, or rolling and MuJoCo's free body (issue 31)
CONTACT_MODELS = ('rolling', 'hybrid')
#: the largest friction of contact_model hybrid (MuJoCo's engine: engine/model.py)
HYBRID_FRICTION_MAX = 10.0


@dataclass(frozen=True)
class Parameter:
    """One parameter of the node.

    ``kind`` is the Python type of the value (``float``, ``int``, ``bool``, ``str``, or
    ``tuple`` for a list of doubles); ``low``/``high`` bound numbers (inclusive, per element
    for lists); ``choices`` lists the allowed strings or integers.
    """

    name: str
    kind: type
    default: object
    unit: str
    description: str
    low: float | None = None
    high: float | None = None
    choices: tuple | None = None
    read_only: bool = False
    physics: bool = False     #: a change restarts the motion
    scene: bool = False       #: a change continues the motion from its current state

    @property
    def rule(self):
        """The allowed values in words, e.g. ``'0.001 <= a <= 1000 m'``."""
        if self.choices is not None:
            return f'one of {", ".join(str(c) for c in self.choices)}'
        if self.kind is bool:
            return 'true or false'
        if self.kind is str:
            return 'a string'
        unit = f' {self.unit}' if self.unit else ''
        each = 'each element ' if self.kind is tuple else ''
        return f'{each}{_number(self.low)} <= {self.name} <= {_number(self.high)}{unit}'


def _number(value):
    return 'inf' if value == math.inf else f'{value:g}'


PARAMETERS = (
    Parameter('a', float, 0.1, 'm', 'semi-axis of each disk along the common axis',
              1e-3, 1e3, physics=True),
    Parameter('b', float, 0.1, 'm', 'other semi-axis of each disk; '
              f'{B_OVER_A[0]:g} <= b/a <= {B_OVER_A[1]:g} (b > a is allowed)',
              1e-5, 1e5, physics=True),
    Parameter('delta', float, 0.05, 'm', 'half the distance between the disk centres; '
              f'{DELTA_OVER_A[0]:g} <= delta/a <= 1 - 1e-6', 1e-6, 1e3, physics=True),
    Parameter('shape', str, 'ellipse', '', 'the shape of each disk: ellipse (a, b), '
              'superellipse (a, b, exponent), egg (a, b, egg_asymmetry) or points (the '
              'outline in shape_file; a and b are then the outline\'s and the parameters a, b '
              'are not used)', choices=shapes.SHAPES, physics=True),
    Parameter('exponent', float, 4.0, '', 'superellipse exponent n: |x/b|^n + |y/a|^n <= 1 '
              '(2: the ellipse; large: a rounded rectangle); only for shape superellipse',
              SUPERELLIPSE_EXPONENT[0], SUPERELLIPSE_EXPONENT[1], physics=True),
    Parameter('egg_asymmetry', float, 0.5, '', 'egg: the third harmonic epsilon of the '
              'support function as a share of its largest convex value epsilon_max(a, b); > 0 '
              'makes the end of disk 1 away from disk 2 the sharper; only for shape egg',
              -shapes.EGG_ASYMMETRY, shapes.EGG_ASYMMETRY, physics=True),
    Parameter('shape_file', str, '', '', 'shape points: a CSV (x, y per line) or YAML (list '
              'of [x, y]) file of outline points in metres, in order around the outline, x '
              'across, y along the common axis, origin at the disk centre; fitted by a '
              'smooth convex curve symmetric in x (a relative path is from the working '
              'directory); only for shape points', physics=True),
    Parameter('arrangement', str, 'parallel', '', 'parallel (disk 2 is disk 1 turned by 90 '
              'deg about the common axis: an egg points the same way on both) or swapped '
              '(disk 2 also turned end for end: the body looks the same from both ends); the '
              'same body for laminae symmetric end to end (ellipse, superellipse)',
              choices=shapes.ARRANGEMENT_NAMES, physics=True),
    Parameter('mass', float, 1.0, 'kg', 'total mass', 1e-6, 1e6, physics=True),
    Parameter('gravity', float, 9.81, 'm/s^2', 'gravitational acceleration g', 0.0, 1e3,
              physics=True),
    Parameter('mass_model', str, 'laminae', '', 'laminae (two thin disks), solid (uniform '
              'convex hull: the oloid toy) or custom', choices=MODELS, physics=True),
    Parameter('principal_moments', tuple, (0.0, 0.0, 0.0), 'kg m^2', 'custom mass model: '
              'I1, I2, I3 about G along e1, e2, e3', 0.0, 1e12, physics=True),
    Parameter('mode', str, 'dynamic', '', 'dynamic (gravity only) or kinematic (constant '
              'angular speed |omega0|)', choices=MODES, physics=True),
    Parameter('theta0', float, 0.3, 'rad', 'initial contact angle on disk 1; '
              '|theta0| <= theta_max of the body', -math.pi, math.pi, physics=True),
    Parameter('branch', int, 1, '', '+1: B below the plane of disk 1, -1: the mirror half '
              'of the cycle', choices=(-1, 1), physics=True),
    Parameter('omega0', float, 3.0, 'rad/s', 'initial signed angular speed; + means theta '
              'increasing on branch +1', -1e3, 1e3, physics=True),
    Parameter('slope', float, 0.0, 'rad', 'inclination of the ground (0: horizontal); poses '
              'stay in frame_id, z up against gravity, x the horizontal of straight downhill',
              -SLOPE_MAX, SLOPE_MAX, physics=True),
    Parameter('heading0', float, 0.0, 'rad', 'heading of the mean travel (increasing phase) '
              'from straight downhill, towards +y (+-pi/2: across the slope)',
              -math.pi, math.pi, physics=True),
    Parameter('drive', str, 'none', '', 'none (free motion), speed (the signed angular speed '
              'follows cmd_speed with the first-order lag drive_lag; until the first command it '
              'holds its speed) or torque (cmd_torque about the axis AB, 0 until commanded); '
              'only with mode dynamic', choices=DRIVES, scene=True),
    Parameter('drive_lag', float, 0.1, 's', 'time constant T of the speed drive: '
              'd|omega|/dt = (cmd_speed - omega)/T', 1e-3, 1e3, scene=True),
    Parameter('cmd_timeout', float, 0.5, 's', 'simulated time without a new command after '
              'which the body returns to free motion (0: never)', 0.0, 1e6),
    Parameter('rolling_resistance', float, 0.0, '', 'coefficient mu_r of a torque '
              'mu_r (N_A + N_B) rho about AB against the rolling, rho the distance of G from AB',
              0.0, 1.0, scene=True),
    Parameter('damping', float, 0.0, 'N m s', 'viscous torque -damping * omega; at most '
              '1000/s x mass x max(a, b)^2 (a spin-down no faster than ~1 ms)', 0.0, 1e6,
              scene=True),
    Parameter('friction', float, 0.5, '', 'friction coefficient mu between body and ground '
              '(.inf: no limit); slip where the motion needs more is outside the rolling '
              'model', 0.0, math.inf),
    Parameter('contact_model', str, 'rolling', '', 'rolling (exact rolling throughout; where '
              'it stops holding the rolling solution is published on, marked invalid) or '
              'hybrid (exact rolling while it holds; from the instant a contact would lift off '
              'or slip, a free rigid body with unilateral contacts and Coulomb friction '
              'in MuJoCo, back to exact rolling once both contacts roll again); hybrid needs '
              'mode dynamic, no rolling resistance (slope, damping and the torque drive act '
              'on both: gravity tilted, -c omega and the torque about AB on the engine\'s '
              'body; the speed drive\'s motor is off in the engine) and 0 < friction <= 10',
              choices=CONTACT_MODELS, physics=True),
    Parameter('rate', float, 100.0, 'Hz', 'publishing rate', 1e-3, 1e5, read_only=True),
    Parameter('duration', float, 0.0, 's', 'simulated time, 0 = until stopped', 0.0, 1e7,
              read_only=True),
    Parameter('realtime', bool, True, '', 'true: paced by the clock; false: as fast as '
              'possible, then exit 0', read_only=True),
    Parameter('method', str, 'table', '', 'table (cycle tables, motion in closed form) or '
              'direct (closed forms on the fly, DOP853)', choices=METHODS, physics=True),
    Parameter('tolerance', float, 1e-10, '', 'relative ODE tolerance; a drift of the '
              'invariant (energy, or |omega| in kinematic mode) above it is a WARN',
              1e-13, 1e-3, physics=True),
    Parameter('frame_id', str, 'world', '', 'frame of poses, points, paths and markers, '
              'parent of body_frame on /tf (non-empty, no spaces, no leading /)'),
    Parameter('body_frame', str, 'twodisk_body', '', 'the body frame at G on /tf (child of '
              'frame_id, the orientation of pose); the disk frames on /tf_static are '
              'body_frame_disk_a, body_frame_disk_b (non-empty, no spaces, no leading /, '
              'none of them frame_id)'),
    Parameter('path_length', int, 1000, '', 'poses kept in each Path', 1, 100000),
    Parameter('record', str, '', '', 'MCAP file to record every published message to, '
              "'' = off", read_only=True),
    Parameter('overwrite', bool, False, '', 'replace an existing record file (else the '
              'node refuses to start)', read_only=True),
)

BY_NAME = {p.name: p for p in PARAMETERS}
#: Parameters that only one shape reads: {name: shape}.
SHAPE_ONLY = {'exponent': 'superellipse', 'egg_asymmetry': 'egg', 'shape_file': 'points'}
#: Names the node accepts that belong to rclpy itself (no warning for them).
ROS_OWN = ('use_sim_time', 'start_type_description_service')


def _check_one(parameter, value):
    """Return the value coerced to the parameter's kind, or raise ValueError (one line)."""
    p = parameter
    if p.kind is tuple:
        try:
            items = tuple(float(x) for x in value)
        except (TypeError, ValueError):
            raise ValueError(f'{p.name} must be a list of 3 numbers, got {value!r}') from None
        if len(items) != 3 or not all(math.isfinite(x) and p.low <= x <= p.high
                                      for x in items):
            raise ValueError(f'{p.name} must be 3 numbers with {p.rule}, got {value!r}')
        return items
    if p.kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f'{p.name} must be a number ({p.rule}), got {value!r}')
        value = float(value)
    elif p.kind is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ValueError(f'{p.name} must be an integer ({p.rule}), got {value!r}')
    elif not isinstance(value, p.kind):
        raise ValueError(f'{p.name} must be {p.rule}, got {value!r}')
    if p.choices is not None and value not in p.choices:
        raise ValueError(f'{p.name} must be {p.rule}, got {value!r}')
    if p.low is not None and not (p.low <= value <= p.high and not math.isinf(value)
                                  or value == p.high == math.inf):
        raise ValueError(f'{p.name} must satisfy {p.rule}, got {value!r}')
    return value


def _check_together(s, outline=None):
    """Rules that involve several parameters; raise ValueError (one line).

    ``outline``: a ``points`` run's fitted outline, used instead of reading ``shape_file``
    (a recording's). The lamina's own a and b (:func:`~twodisk_ros.run.shape.axes_of`) obey
    the rules of the parameters a and b.
    """
    if s.shape == 'ellipse':
        a, b, what = s.a, s.b, ''
    else:
        lamina = shapes.lamina_of(s, outline)
        a, b = shapes.axes_of(lamina)
        what = "the outline's " if s.shape == 'points' else ''
        for name, value in (('a', a), ('b', b)):
            p = BY_NAME[name]
            if not p.low <= value <= p.high:
                raise ValueError(f'{what}{name} must satisfy {p.rule}, got {value:.6g} m')
    ratio = b / a
    if not B_OVER_A[0] <= ratio <= B_OVER_A[1]:
        raise ValueError(f'{what}b/a must be in [{B_OVER_A[0]:g}, {B_OVER_A[1]:g}], got '
                         f'b = {b!r} m, a = {a!r} m (b/a = {ratio:.6g})')
    ratio = s.delta / a
    if not DELTA_OVER_A[0] <= ratio <= DELTA_OVER_A[1]:
        raise ValueError(f'delta/a must be in [{DELTA_OVER_A[0]:g}, 1 - 1e-6] (0 < delta < a), '
                         f'got delta = {s.delta!r} m, {what}a = {a!r} m (delta/a = {ratio:.6g})')
    theta_max = shapes.theta_max_of(s, shapes.lamina_of(s, outline))
    if abs(s.theta0) > theta_max:
        raise ValueError(f'theta0 must satisfy |theta0| <= theta_max = {theta_max:.6g} '
                         f'rad for this body, got {s.theta0!r}')
    if not s.realtime and s.duration <= 0:
        raise ValueError('duration must be > 0 s when realtime is false (a batch run needs '
                         f'an end), got {s.duration!r}')
    if s.duration * s.rate > 1e10:
        raise ValueError(f'duration x rate must be <= 1e10 samples, got {s.duration!r} s x '
                         f'{s.rate!r} Hz')
    if 0 < s.gravity < 1e-6:
        raise ValueError(f'gravity must be 0 (no gravity) or in [1e-6, 1000] m/s^2, got '
                         f'{s.gravity!r}')
    check_frame_id(s.frame_id, 'frame_id')   # the parent on /tf: tf2 refuses a leading /
    _check_body_frame(s.body_frame, s.frame_id)
    if s.mass_model == 'custom':
        moments = s.principal_moments
        if min(moments) <= 0:
            raise ValueError('principal_moments must be 3 numbers > 0 kg m^2 for '
                             f'mass_model custom, got {list(moments)!r}')
    if s.shape == 'ellipse':
        s.ellipse_mass_properties()   # custom moments: triangle inequalities; solid: quadrature
    elif s.mass_model == 'custom':
        custom(s.mass, s.principal_moments)   # the triangle inequalities (any shape)
    if s.drive != 'none' and s.mode != 'dynamic':
        raise ValueError(f'drive {s.drive} needs mode dynamic (mode kinematic is the speed '
                         f'drive holding |omega0|), got mode {s.mode!r}')
    damping_limit = DAMPING_RATE * s.mass * max(a, b, s.delta) ** 2
    if s.damping > damping_limit:
        raise ValueError(f'damping must be <= {DAMPING_RATE:g}/s x mass x max(a, b)^2 = '
                         f'{damping_limit:.6g} N m s for this body (a spin-down faster than '
                         f'~1 ms is not simulated), got {s.damping!r}')
    if s.contact_model == 'hybrid' and (s.mode, s.rolling_resistance) != ('dynamic', 0):
        raise ValueError('contact_model hybrid needs mode dynamic and rolling_resistance 0 '
                         '(rolling resistance\'s dead band has no free-body counterpart; '
                         'slope, damping and drives it has), got mode '
                         f'{s.mode}, rolling_resistance {s.rolling_resistance!r}')
    if s.contact_model == 'hybrid' and not 0 < s.friction <= HYBRID_FRICTION_MAX:
        raise ValueError(f'friction must be in (0, {HYBRID_FRICTION_MAX:g}] for contact_model '
                         'hybrid (the engine\'s Coulomb friction; 0 and .inf are exact '
                         f'rolling\'s only), got {s.friction!r}')
    if s.shape == 'superellipse' and s.mass_model == 'solid' and s.exponent > SOLID_EXPONENT:
        raise ValueError(f'exponent must be <= {SOLID_EXPONENT:g} for mass_model solid (the '
                         'hull of sharper corners is not resolved in floating point; laminae '
                         f'and custom take up to 100), got {s.exponent!r}')


def _check_body_frame(body_frame, frame_id):
    """The body's frame names are usable tf2 frame ids below ``frame_id``; else ValueError.

    tf2 refuses an empty frame id and one with a leading ``/``; a space breaks the tools that
    take frames on a command line, a control character the message (CDR strings end at NUL);
    a name equal to ``frame_id`` would make the world frame its own child (a loop in the TF
    tree). :func:`twodisk_ros.model.frames.check_frame_id` is the rule the URDF applies.
    """
    check_frame_id(body_frame)
    if not body_frame.isprintable():
        raise ValueError(f'body_frame must not hold control characters, got {body_frame!r}')
    names = (body_frame,) + tuple(body_frame + suffix for suffix in DISK_SUFFIXES)
    if frame_id in names:
        raise ValueError(f'body_frame must differ from frame_id: the body\'s frames '
                         f'{", ".join(names)} include frame_id {frame_id!r}')


class _SettingsMethods:
    def checked(self, outline=None):
        """Return self if every value is allowed, else raise ValueError (one line).

        ``outline``: for shape points, the fitted outline to check instead of reading
        ``shape_file`` (a recording's, :func:`~twodisk_ros.run.shape.outline_from_metadata`).
        """
        for p in PARAMETERS:
            _check_one(p, getattr(self, p.name))
        _check_together(self, outline)
        return self

    def with_values(self, **values):
        """A checked-type copy with some parameters changed (unknown names: ValueError)."""
        unknown = sorted(set(values) - set(BY_NAME))
        if unknown:
            raise ValueError(f'unknown parameter {unknown[0]!r}')
        return replace(self, **{k: _check_one(BY_NAME[k], v) for k, v in values.items()})

    def ellipse_mass_properties(self):
        """The :class:`~twodisk_ros.physics.mass.models.MassProperties` of ellipse settings:
        the closed forms of a, b, delta. Other shapes: the run's body's
        (:attr:`twodisk_ros.run.description.RunDescription.mass`)."""
        if self.shape != 'ellipse':
            raise ValueError(f'ellipse_mass_properties is for shape ellipse, not {self.shape}: '
                             'the mass of another shape is RunDescription(settings).mass')
        moments = self.principal_moments if self.mass_model == 'custom' else None
        return mass_properties(self.mass_model, self.a, self.b, self.delta, self.mass,
                               principal_moments=moments)

    def as_strings(self):
        """Every parameter as text (the recording's metadata; read by :func:`parse_recorded`)."""
        return {p.name: (str(list(getattr(self, p.name))) if p.kind is tuple
                         else str(getattr(self, p.name))) for p in PARAMETERS}

    def physics_differs(self, other):
        """True if a parameter that shapes the motion differs (the motion restarts).

        A parameter that only another shape reads (:data:`SHAPE_ONLY`: ``exponent`` of an
        ellipse run) does not count; ``a`` and ``b`` of two ``points`` runs do not either.
        """
        unread = {name for name, shape in SHAPE_ONLY.items()
                  if self.shape != shape and other.shape != shape}
        if self.shape == other.shape == 'points':
            unread |= {'a', 'b'}
        return any(getattr(self, p.name) != getattr(other, p.name)
                   for p in PARAMETERS if p.physics and p.name not in unread)

    def scene_differs(self, other):
        """True if a parameter that changes the scene but continues the motion differs
        (``drive``, ``drive_lag``, ``rolling_resistance``, ``damping``)."""
        return any(getattr(self, p.name) != getattr(other, p.name)
                   for p in PARAMETERS if p.scene)


#: Settings of the node (SI units): a frozen dataclass with one field per parameter.
RollerSettings = make_dataclass(
    'RollerSettings', [(p.name, p.kind, p.default) for p in PARAMETERS],
    bases=(_SettingsMethods,), frozen=True, namespace={'__doc__': __doc__.split('\n')[0]})
RollerSettings.__module__ = __name__

DEFAULTS = RollerSettings()

_REQUIRED_RECORDED = ('a', 'b', 'delta', 'mass', 'gravity', 'omega0')
_NUMBER = re.compile(r'[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?inf|nan')


def _from_text(parameter, text):
    p = parameter
    if p.kind is bool:
        lowered = text.strip().lower()
        if lowered not in ('true', 'false'):
            raise ValueError(f'parameter {p.name} = {text!r} is not true or false')
        return lowered == 'true'
    if p.kind is tuple:
        return tuple(float(x) for x in _NUMBER.findall(text))
    if p.kind is str:
        return text
    try:
        value = p.kind(float(text)) if p.kind is float else int(text)
    except ValueError:
        raise ValueError(f'parameter {p.name} = {text!r} is not a number') from None
    return value


def parse_recorded(strings):
    """Settings from a recording's ``twodisk_ros`` metadata (every value as text).

    A recording without the shape parameters (made before them) is an ellipse run. One of
    shape points is checked with the fitted outline it holds (``outline``), never by reading
    its ``shape_file``.

    Returns
    -------
    (RollerSettings or None, list of str)
        The settings (missing optional parameters take their defaults) and the problems
        found, one line each; None if the values define no valid run.
    """
    problems, values = [], {}
    for name in _REQUIRED_RECORDED:
        if name not in strings:
            problems.append(f'parameter {name} is missing')
    for p in PARAMETERS:
        if p.name not in strings:
            continue
        try:
            values[p.name] = _check_one(p, _from_text(p, strings[p.name]))
        except ValueError as error:
            problems.append(str(error))
    if problems:
        return None, problems
    if values.get('mass_model', DEFAULTS.mass_model) != 'custom':
        values.pop('principal_moments', None)
    settings = replace(DEFAULTS, **values)
    try:
        outline = (shapes.outline_from_metadata(strings) if settings.shape == 'points'
                   else None)
    except ValueError as error:
        return None, [str(error)]
    try:
        _check_together(settings, outline)
    except (ValueError, RuntimeError) as error:
        return None, [f'the recorded parameters define no valid run: {error}']
    return settings, []


def markdown_table():
    """The README's parameter table, generated from :data:`PARAMETERS`."""
    rows = ['| name | type | default | unit | allowed | read-only | meaning |',
            '| --- | --- | --- | --- | --- | --- | --- |']
    kinds = {float: 'double', int: 'int', bool: 'bool', str: 'string', tuple: 'double[3]'}
    for p in PARAMETERS:
        default = (f"'{p.default}'" if p.kind is str
                   else str(list(p.default)) if p.kind is tuple
                   else str(p.default).lower() if p.kind is bool else repr(p.default))
        rows.append(f'| `{p.name}` | {kinds[p.kind]} | {default} | {p.unit or "-"} | '
                    f'{_cell(p.rule)} | {"yes" if p.read_only else "no"} | '
                    f'{_cell(p.description)} |')
    return '\n'.join(rows)


def _cell(text):
    """Text for a Markdown table cell (a literal | escaped)."""
    return text.replace('|', '\\|')


if __name__ == '__main__':
    import argparse
    argparse.ArgumentParser(
        prog='python -m twodisk_ros.run.parameters',
        description="Print the roller node's parameter table (Markdown, as in the README)."
    ).parse_args()
    import os
    import sys
    try:
        print(markdown_table(), flush=True)   # the README's table
    except BrokenPipeError:   # `| head`: the reader left; no traceback (Python docs' recipe)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())

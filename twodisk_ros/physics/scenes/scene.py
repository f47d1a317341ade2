"""The scene the body rolls in: ground plane, gravity, drive and dissipation (ROS-free).

Every addition is off by default: ``Scene()`` is the flat, free, conservative scene,
and the motion of such a scene is the plain :class:`~twodisk_ros.physics.motion.simulate.MotionStream`
(docs/physics.md#scenes).

Frames (all right-handed, metres):

* the **cycle frame** of :class:`~twodisk_ros.physics.bodies.cycle.RollingCycle`: origin at A for
  u = 0, X along disk 1's tangent there, Z the ground normal. The mean travel of one cycle
  (its ``displacement.shift``) points along +X for increasing u;
* the **slope frame** S: z the ground normal (up out of the ground), x straight downhill
  (the steepest descent direction in the ground), y = z × x across the slope. A point of the
  cycle frame maps to S by the rotation R_z(φ0) about the normal, φ0 = heading0 − arg(shift),
  so the mean travel (for increasing u) heads at ``heading0`` from downhill, positive
  towards +y;
* the **gravity frame** W (the published ``frame_id``): Z up against gravity, X the
  horizontal projection of downhill, Y = y. A slope-frame point p maps to R_y(β) p, β the
  slope angle: x → (cos β, 0, −sin β), z → (sin β, 0, cos β). At β = 0 all three coincide
  up to the heading rotation, and with heading0 = 0 and β = 0 not even that (φ0 = 0 for the
  bodies whose shift is along +X, which is every body of two congruent laminae).

Gravity is g = (0, 0, −g) in W, g (sin β, 0, −cos β) in S: G's height along gravity is
z_W = h cos β − s sin β, h G's height above the ground and s its downhill coordinate.
"""

from dataclasses import dataclass
import math

import numpy as np

__all__ = ['Scene', 'DRIVES', 'SLOPE_LIMIT', 'command_error', 'quaternion_product']

DRIVES = ('none', 'speed', 'torque')
#: |slope| must stay below this (rad): at π/2 the ground is a wall
SLOPE_LIMIT = 0.5 * math.pi


def _number(name, value, rule, allowed):
    if isinstance(value, (str, bytes, bool)):
        raise ValueError(f'{name} must be a number {rule}, got {value!r}')
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f'{name} must be a number {rule}, got {value!r}') from None
    if not allowed(number):
        raise ValueError(f'{name} must be {rule}, got {value!r}')
    return number


@dataclass(frozen=True)
class Scene:
    """Ground, gravity, drive and dissipation of one run (SI units).

    Attributes
    ----------
    slope : float
        β (rad), the ground's inclination, |β| < π/2; 0 is the horizontal ground.
    heading0 : float
        Heading (rad) of the body's mean direction of travel (for increasing u) from straight
        downhill, measured in the ground towards the slope's +y. ±π/2: across the slope.
    gravity : float
        g (m/s²), ≥ 0; must equal the gravity of the dynamics it is used with.
    drive : {'none', 'speed', 'torque'}
        'none': free motion; 'speed': the signed rolling speed Ω (|Ω| = |ω|, Ω > 0 for
        increasing u) follows ``command`` (rad/s) by the first-order lag
        dΩ/dt = (command − Ω)/``lag``; 'torque': a torque ``command`` (N m) about the
        instantaneous axis AB, positive in the sense of ω for increasing u (ω_u·ê > 0).
    command : float
        The drive's command (rad/s or N m); ignored if drive is 'none'.
    lag : float
        Time constant (s, > 0) of the speed drive's first-order lag.
    rolling_resistance : float
        μ_r ≥ 0 (dimensionless): a resisting torque μ_r (N_A + N_B) ρ about AB, ρ the
        distance of G from AB (for a wheel ρ is its radius: the usual law F = μ_r N).
    damping : float
        c ≥ 0 (N m s): a viscous torque −c ω.
    friction : float
        μ ≥ 0 of the ground (inf: never slips); used to report slip, not in the motion.
    speed_limit, torque_limit : float
        Largest |command| (rad/s, N m; > 0, inf allowed) the speed and torque drives accept
        (:func:`command_error`).
    """

    slope: float = 0.0
    heading0: float = 0.0
    gravity: float = 9.81
    drive: str = 'none'
    command: float = 0.0
    lag: float = 0.1
    rolling_resistance: float = 0.0
    damping: float = 0.0
    friction: float = math.inf
    speed_limit: float = 100.0
    torque_limit: float = 10.0

    def __post_init__(self):
        checks = [
            ('slope', f'finite with |slope| < pi/2 rad',
             lambda x: math.isfinite(x) and abs(x) < SLOPE_LIMIT),
            ('heading0', 'finite (rad)', math.isfinite),
            ('gravity', 'finite and >= 0 m/s^2', lambda x: math.isfinite(x) and x >= 0),
            ('command', 'finite (rad/s or N m)', math.isfinite),
            ('lag', 'finite and > 0 s', lambda x: math.isfinite(x) and x > 0),
            ('rolling_resistance', 'finite and >= 0', lambda x: math.isfinite(x) and x >= 0),
            ('damping', 'finite and >= 0 N m s', lambda x: math.isfinite(x) and x >= 0),
            ('friction', '>= 0 (inf allowed)', lambda x: x >= 0),
            ('speed_limit', '> 0 rad/s (inf allowed)', lambda x: x > 0),
            ('torque_limit', '> 0 N m (inf allowed)', lambda x: x > 0),
        ]
        for name, rule, allowed in checks:
            object.__setattr__(self, name, _number(name, getattr(self, name), rule, allowed))
        if self.drive not in DRIVES:
            raise ValueError(f'drive must be one of {", ".join(map(repr, DRIVES))}, '
                             f'got {self.drive!r}')
        if self.drive != 'none':
            why = self.command_error(self.drive, self.command)
            if why:
                raise ValueError('command ' + why.split(' ignored: ', 1)[1])

    def command_error(self, drive, value):
        """'' if ``value`` is a command the ``drive`` ('speed' or 'torque') accepts, else
        one line saying what was wrong and what is allowed (the node logs it as a WARN and
        keeps the previous command)."""
        limit = {'speed': self.speed_limit, 'torque': self.torque_limit}.get(drive)
        return command_error(drive, value, limit)

    # -- what the scene needs ------------------------------------------------------------
    @property
    def dissipative(self):
        """True if rolling resistance or damping is on."""
        return self.rolling_resistance > 0 or self.damping > 0

    @property
    def conservative(self):
        """True if E = T + V is conserved: no drive and no dissipation."""
        return self.drive == 'none' and not self.dissipative

    @property
    def flat_free(self):
        """True for the flat free scene: horizontal ground, no drive, no dissipation."""
        return self.slope == 0.0 and self.conservative

    # -- frames ----------------------------------------------------------------------------
    @property
    def slope_to_gravity(self):
        """R_y(β): slope-frame vectors → gravity frame (3 × 3)."""
        c, s = math.cos(self.slope), math.sin(self.slope)
        return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])

    @property
    def slope_to_gravity_quaternion(self):
        """R_y(β) as a quaternion (x, y, z, w)."""
        return np.array([0.0, math.sin(0.5 * self.slope), 0.0, math.cos(0.5 * self.slope)])

    @property
    def gravity_in_slope_frame(self):
        """The gravity vector g (sin β, 0, −cos β) (m/s²) in the slope frame."""
        return self.gravity * np.array([math.sin(self.slope), 0.0, -math.cos(self.slope)])

    def cycle_rotation(self, shift):
        """φ0 (rad): the rotation about the normal from the cycle frame to the slope frame.

        ``shift`` is the cycle's mean travel per cycle (complex, m); if it vanishes
        (no mean travel) φ0 = heading0.
        """
        shift = complex(shift)
        return self.heading0 - (math.atan2(shift.imag, shift.real) if shift != 0 else 0.0)

    def describe(self):
        """One line: what the scene adds to the flat free one."""
        parts = []
        if self.slope:
            parts.append(f'slope {self.slope:g} rad, heading0 {self.heading0:g} rad')
        if self.drive == 'speed':
            parts.append(f'speed drive {self.command:g} rad/s (lag {self.lag:g} s)')
        elif self.drive == 'torque':
            parts.append(f'torque drive {self.command:g} N m')
        if self.rolling_resistance:
            parts.append(f'rolling resistance {self.rolling_resistance:g}')
        if self.damping:
            parts.append(f'damping {self.damping:g} N m s')
        return ', '.join(parts) if parts else 'flat, free, conservative'


def command_error(drive, value, limit):
    """'' if ``value`` is a valid command for ``drive``, else one line: why it is rejected.

    ``drive`` is 'speed' (rad/s) or 'torque' (N m); a valid command is a finite real number
    (not a bool or a string) with |value| ≤ ``limit``. NaN, ±inf and values beyond the limit
    are rejected, never raised: the caller keeps its previous command.
    """
    units = {'speed': 'rad/s', 'torque': 'N m'}
    if drive not in units:
        return f'cmd_{drive} ignored: no such drive (allowed: speed, torque)'
    name = f'cmd_{drive}'
    if isinstance(value, (str, bytes, bool)) or value is None:
        return f'{name} ignored: must be a number in {units[drive]}, got {value!r}'
    try:
        number = float(value)
    except (TypeError, ValueError):
        return f'{name} ignored: must be a number in {units[drive]}, got {value!r}'
    if not math.isfinite(number):
        return f'{name} ignored: must be finite, got {number!r}'
    if not abs(number) <= limit:
        return (f'{name} ignored: |{number:g}| {units[drive]} is beyond the limit '
                f'{limit:g} {units[drive]}')
    return ''


def quaternion_product(p, q):
    """Hamilton product p ⊗ q of quaternions (x, y, z, w), broadcast over leading axes."""
    p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    px, py, pz, pw = np.moveaxis(p, -1, 0)
    qx, qy, qz, qw = np.moveaxis(q, -1, 0)
    return np.stack([pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx,
                     pw * qz + px * qy - py * qx + pz * qw,
                     pw * qw - px * qx - py * qy - pz * qz], axis=-1)

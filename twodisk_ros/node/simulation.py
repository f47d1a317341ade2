"""The node's settings and the physics objects they build (no rclpy here).

:class:`RollerSettings` holds every parameter of the ``roller`` node, checks them, and
builds a :class:`Simulation`: body, mass model, dynamics, equilibria and a motion stream.
"""

from dataclasses import asdict, dataclass, field, replace
import math

import numpy as np

from ..physics.body import TwoDiskBody
from ..physics.dynamics import RollingDynamics
from ..physics.mass_models import MODELS, mass_properties
from ..physics.motion import METHODS, MODES, MotionStream

__all__ = ['RollerSettings', 'Simulation', 'DEFAULTS']


@dataclass(frozen=True)
class RollerSettings:
    """Parameters of the ``roller`` node (SI units). Defaults: the oloid of radius 0.1 m."""

    a: float = 0.1                 #: semi-axis along the common axis (m)
    b: float = 0.1                 #: other semi-axis (m)
    delta: float = 0.05            #: half the distance between the disk centres (m)
    mass: float = 1.0              #: total mass (kg)
    gravity: float = 9.81          #: g (m/s²)
    mass_model: str = 'laminae'    #: 'laminae' | 'solid' | 'custom'
    principal_moments: tuple = (0.0, 0.0, 0.0)  #: kg m², about G along e1, e2, e3 (custom)
    mode: str = 'dynamic'          #: 'dynamic' | 'kinematic'
    theta0: float = 0.3            #: initial θ (rad)
    branch: int = 1                #: +1 paper's branch, −1 mirror
    omega0: float = 3.0            #: initial signed angular speed (rad/s)
    rate: float = 100.0            #: publishing rate (Hz)
    duration: float = 0.0          #: simulated seconds; 0 = until stopped
    realtime: bool = True          #: paced by the clock, else as fast as possible
    method: str = 'table'          #: 'table' | 'direct'
    tolerance: float = 1e-10       #: ODE rtol; also the energy-drift WARN level
    frame_id: str = 'world'        #: frame of poses, points, paths and markers
    path_length: int = 1000        #: poses kept in each Path
    record: str = ''               #: MCAP file to record to ('' = off)

    def checked(self):
        """Return self if every value is allowed, else raise ValueError (one line)."""
        _choice('mass_model', self.mass_model, MODELS)
        _choice('mode', self.mode, MODES)
        _choice('method', self.method, METHODS)
        body = TwoDiskBody(self.a, self.b, self.delta)
        _finite('gravity', self.gravity, 0.0, 1e3, '0 <= gravity <= 1000 m/s^2')
        _finite('rate', self.rate, 0.0, 1e5, '0 < rate <= 100000 Hz', open_low=True)
        _finite('duration', self.duration, 0.0, math.inf, 'duration >= 0 s')
        if not self.realtime and self.duration <= 0:
            raise ValueError('duration must be > 0 s when realtime is false '
                             f'(a batch run needs an end), got {self.duration!r}')
        _finite('tolerance', self.tolerance, 0.0, 1.0, '0 < tolerance < 1', open_low=True)
        _finite('omega0', self.omega0, -math.inf, math.inf, 'a finite number (rad/s)')
        if self.branch not in (1, -1):
            raise ValueError(f'branch must be +1 or -1, got {self.branch!r}')
        if not (math.isfinite(self.theta0) and abs(self.theta0) <= body.theta_max):
            raise ValueError(f'theta0 must satisfy |theta0| <= theta_max = {body.theta_max:.6g} '
                             f'rad for this body, got {self.theta0!r}')
        if self.path_length < 1:
            raise ValueError(f'path_length must be >= 1, got {self.path_length!r}')
        if not self.frame_id:
            raise ValueError('frame_id must not be empty')
        self.mass_properties()
        return self

    def mass_properties(self):
        moments = self.principal_moments if self.mass_model == 'custom' else None
        return mass_properties(self.mass_model, self.a, self.b, self.delta, self.mass,
                               principal_moments=moments)

    def as_strings(self):
        """Every parameter as text (for the recording's metadata)."""
        return {k: (str(list(v)) if isinstance(v, tuple) else str(v))
                for k, v in asdict(self).items()}

    def with_values(self, **values):
        """A copy with some parameters changed (types coerced as the node declares them)."""
        coerced = {}
        for key, value in values.items():
            kind = type(getattr(DEFAULTS, key))
            if kind is tuple:
                coerced[key] = tuple(float(x) for x in value)
            elif kind is float:
                coerced[key] = float(value)
            else:
                coerced[key] = kind(value)
        return replace(self, **coerced)

    #: parameters that only move the physics when they change (the motion restarts)
    PHYSICS = ('a', 'b', 'delta', 'mass', 'gravity', 'mass_model', 'principal_moments', 'mode',
               'theta0', 'branch', 'omega0', 'method', 'tolerance')


DEFAULTS = RollerSettings()


def _choice(name, value, allowed):
    if value not in allowed:
        raise ValueError(f'{name} must be one of {", ".join(allowed)}, got {value!r}')


def _finite(name, value, low, high, rule, open_low=False):
    ok = math.isfinite(value) and value <= high and (value > low if open_low else value >= low)
    if not ok:
        raise ValueError(f'{name} must satisfy {rule}, got {value!r}')


@dataclass
class Simulation:
    """Physics objects built from settings: the node advances ``stream`` and reads the rest."""

    settings: RollerSettings
    body: TwoDiskBody = field(init=False)

    def __post_init__(self):
        s = self.settings.checked()
        self.body = TwoDiskBody(s.a, s.b, s.delta)
        self.dynamics = RollingDynamics(self.body, s.mass_properties(), s.gravity)
        u0 = float(self.body.phase_from_theta(s.theta0, s.branch))
        u_dot0 = self.dynamics.initial_phase_rate(u0, s.omega0)
        self.stream = MotionStream(self.dynamics, u0, u_dot0, mode=s.mode, method=s.method,
                                   tolerance=s.tolerance)
        self.equilibria = self.dynamics.equilibria_with_periods()
        self.energy0 = self.stream.initial_energy

    def sample(self, t):
        """Everything published at simulated times t (s, increasing array)."""
        u, u_dot = self.stream.sample(t)
        state = self.dynamics.cycle.state(u)
        dtheta, dpsi = self.body.phase_angle_rates(u)
        energy = self.dynamics.energy(u, u_dot)
        return Sample(t=np.asarray(t, float), phase=u, phase_rate=u_dot, state=state,
                      theta_rate=dtheta * u_dot, psi_rate=dpsi * u_dot, energy=energy)

    def energy_drift(self, energy):
        """|E − E₀| relative to M g × size (dimensionless)."""
        return abs(float(energy) - self.energy0) / self.dynamics.energy_scale

    def disk_outlines(self, rotation, position_g, points=64):
        """World points (m) of both disk outlines for one pose: two arrays (points + 1, 3)."""
        a, b, d = self.body.a, self.body.b, self.body.delta
        s = np.linspace(0.0, 2 * np.pi, points + 1)
        disk1 = np.stack([b * np.sin(s), -d - a * np.cos(s), 0 * s], -1)
        disk2 = np.stack([0 * s, d + a * np.cos(s), b * np.sin(s)], -1)
        return disk1 @ rotation.T + position_g, disk2 @ rotation.T + position_g


@dataclass
class Sample:
    """Published quantities at a batch of simulated times (arrays over the batch)."""

    t: np.ndarray
    phase: np.ndarray
    phase_rate: np.ndarray
    state: object
    theta_rate: np.ndarray
    psi_rate: np.ndarray
    energy: np.ndarray

"""The MJCF (MuJoCo's XML) of a rolling body: its plates or hull, mass model, μ and contacts.

Frames: MuJoCo's world is the package's world (Z up, the ground the plane z = 0); the body's
frame is the package's body frame G e1 e2 e3 (docs/physics.md) with origin G, the centre of
mass (:func:`~twodisk_ros.physics.mass.models.centred_on_mass`), so a rolling pose is copied
into MuJoCo's free joint as it is (:mod:`~twodisk_ros.engine.state`).

Geometry: the meshes of :func:`~twodisk_ros.model.mesh.mesh_parts`, one MuJoCo mesh geom per
part: the two plates (``laminae``, ``custom``: closed prisms ``thickness`` thick over the
rims) or the convex hull of the rims (``solid``). MuJoCo collides the convex hull of each
mesh with the ground plane. Mass and inertia are the mass model's (``<inertial>`` about G,
``inertiafromgeom`` off): the meshes only collide. Contacts are ``condim 3``: Coulomb
friction μ in the contact plane, no torsional or rolling friction (the ideal body has none).

Contact parameters (:class:`ContactParameters`), defaults from the convergence measurement
of ``benchmarks/engine_convergence.py`` (the oloid of config/oloid.yaml handed over in its
exact rolling state at θ0 = 0.3 rad, ω0 = 3 rad/s, G compared with the package's exact motion
over 1 s, one parameter changed at a time; docs/physics.md#the-free-body-engine). With the
defaults G ends 2.9 mm off the exact path (of 0.23 m travelled), almost all of it a lag along
the path: the polygonal plates lose energy at each vertex they roll over (2.7 mJ of 0.78 J
after 1 s), so the error falls slowly with n (64: 14 mm, 128: 6.2, 256: 3.6, 512: 2.9,
1024: 2.2, 2048: 1.5) and hardly with the step (5e-4 → 1e-4 s: 3.6 → 3.2 mm at n = 256).

``resolution`` 512
    Mesh resolution n of the plates' rims: the limiting parameter (above); 512 is the
    largest n that costs < 0.1 s of engine per simulated second (0.06 s measured).
``timestep`` 5e-4 s, ``time_constant`` 5e-3 s, ``damping_ratio`` 1
    MuJoCo's soft contact is a damped spring reaching its reference in ``time_constant``
    (solref); G sinks 1.4e-5 m into the ground. Softer contacts are worse (1e-2 s: 6.4 mm,
    2e-2 s, MuJoCo's default: 8.4 mm at n = 256); stiffer ones need a finer step (MuJoCo
    needs time_constant ≥ 2 timestep) and gain little (2.5e-4 s, 1e-3 s: 4.3 mm).
``integrator`` implicitfast, ``cone`` elliptic
    Euler and RK4 differ by < 0.2 mm (RK4 7x slower); the pyramidal cone lets the contacts
    creep 3x faster (slip 2.3 mm/s against 0.8).
``thickness`` 1e-3 of the body's size
    The plates' faces stand ``thickness``/2 off the disk planes (G lower by up to that
    where a rim edge touches); 1e-2 … 1e-4 change the error by < 0.9 mm.
"""

from dataclasses import dataclass
import math

import numpy as np

from twodisk_ros.model.mesh import mesh_parts

__all__ = ['ContactParameters', 'INTEGRATORS', 'CONES', 'IMPEDANCE', 'engine_xml', 'build_model',
           'contact_metadata', 'gravity_vector', 'landing_depth_factor']

#: MuJoCo integrators accepted (its names).
INTEGRATORS = ('implicitfast', 'Euler', 'implicit', 'RK4')
#: Friction cones accepted (its names).
CONES = ('elliptic', 'pyramidal')
#: Allowed time steps (s): finer steps are slower than useful, coarser ones unstable for
#: contacts stiff enough to keep penetration below a tenth of a millimetre.
TIMESTEP_RANGE = (1e-5, 5e-3)
#: (d0, dmax, width m): MuJoCo's default solimp, which :func:`engine_xml` leaves in force: the
#: impedance d rises from d0 at the surface to dmax at ``width`` deep
IMPEDANCE = (0.9, 0.95, 0.001)


def _number(name, value, low, high, unit):
    if isinstance(value, (bool, str, bytes)) or not np.isscalar(value):
        raise ValueError(f'{name} must be a number of {unit} in [{low:g}, {high:g}], '
                         f'got {value!r}')
    value = float(value)
    if not (math.isfinite(value) and low <= value <= high):
        raise ValueError(f'{name} must be a number of {unit} in [{low:g}, {high:g}], '
                         f'got {value!r}')
    return value


@dataclass(frozen=True)
class ContactParameters:
    """The engine's contact and integration settings (defaults: module docstring).

    Attributes
    ----------
    mu : float
        Coulomb friction coefficient (> 0, ≤ 10), the same as the rolling model's μ.
    timestep : float
        Integration step (s), in :data:`TIMESTEP_RANGE`.
    time_constant : float
        The soft contact's time constant (s, MuJoCo's solref[0]), ≥ 2 × timestep.
    damping_ratio : float
        Its damping ratio (MuJoCo's solref[1]; 1 critical), in (0, 10].
    integrator, cone : str
        One of :data:`INTEGRATORS` and :data:`CONES`.
    resolution : int
        Mesh resolution n of :func:`~twodisk_ros.model.mesh.mesh_parts` (multiple of 4, ≥ 8).
    thickness : float
        Plate thickness as a fraction of the body's size, in (0, 0.1].
    """

    mu: float = 0.5
    timestep: float = 5e-4
    time_constant: float = 5e-3
    damping_ratio: float = 1.0
    integrator: str = 'implicitfast'
    cone: str = 'elliptic'
    resolution: int = 512
    thickness: float = 1e-3

    def __post_init__(self):
        if isinstance(self.mu, (bool, str, bytes)) or not np.isscalar(self.mu) \
                or not (math.isfinite(float(self.mu)) and 0 < float(self.mu) <= 10):
            raise ValueError(f'mu must be a friction coefficient in (0, 10], got {self.mu!r}')
        step = _number('timestep', self.timestep, *TIMESTEP_RANGE, 's')
        _number('time_constant', self.time_constant, 2 * step, 10.0, 's')
        _number('damping_ratio', self.damping_ratio, 1e-3, 10.0, '(1 is critical)')
        _number('thickness', self.thickness, 1e-6, 0.1, 'body sizes')
        if self.integrator not in INTEGRATORS:
            raise ValueError(f'integrator must be one of {", ".join(INTEGRATORS)}, '
                             f'got {self.integrator!r}')
        if self.cone not in CONES:
            raise ValueError(f'cone must be one of {", ".join(CONES)}, got {self.cone!r}')
        n = self.resolution
        if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) \
                or n < 8 or n % 4 or n > 4096:
            raise ValueError(f'resolution must be an integer multiple of 4 in [8, 4096], '
                             f'got {n!r}')


def _fmt(values):
    return ' '.join(f'{x:.17g}' for x in np.ravel(values))


def gravity_vector(gravity, slope=0.0):
    """Gravity (m/s², (3,)) in the engine's world, the slope frame (x straight downhill in
    the ground, z the ground's normal, up; docs/physics.md "Scenes"): g (sin β, 0, −cos β)
    for a slope β (rad, |β| < π/2; 0: the level ground's (0, 0, −g))."""
    gravity = _number('gravity', gravity, 0.0, 1e3, 'm/s^2')
    slope = _number('slope', slope, -0.5 * math.pi + 1e-9, 0.5 * math.pi - 1e-9, 'rad')
    if slope == 0.0:
        return np.array([0.0, 0.0, -gravity])
    return np.array([gravity * math.sin(slope), 0.0, -gravity * math.cos(slope)])


def engine_xml(body, mass_properties, gravity=9.81, parameters=None, slope=0.0):
    """The MJCF of ``body`` on the ground plane, as a string.

    Parameters
    ----------
    body : RollingBody
        Its body frame's origin must be the centre of mass (as from
        :func:`~twodisk_ros.physics.mass.models.centred_on_mass`).
    mass_properties : MassProperties
        Mass (kg) and inertia about G (kg m², body frame); its ``model`` picks the geometry
        (``solid``: the hull; otherwise the two plates).
    gravity : float
        g (m/s²), ≥ 0.
    parameters : ContactParameters, optional
        Defaults if None.
    slope : float
        β (rad): the ground is the plane z = 0 of the slope frame and gravity is tilted in it
        (:func:`gravity_vector`); 0 gives the level ground's model, unchanged.

    Returns
    -------
    str
        The body is ``<body name="body">`` with one free joint ``free``; the plates are the
        geoms ``disk_a``, ``disk_b`` (or the one geom ``hull``); the ground is ``ground``.
    """
    p = ContactParameters() if parameters is None else parameters
    if not isinstance(p, ContactParameters):
        raise ValueError(f'parameters must be a ContactParameters, got {type(p).__name__}')
    tilted = gravity_vector(gravity, slope)
    gravity = _number('gravity', gravity, 0.0, 1e3, 'm/s^2')
    gravity_text = f'0 0 {-gravity!r}' if slope == 0.0 else _fmt(tilted)
    if np.max(np.abs(mass_properties.center_of_mass)) > 1e-9 * body.size:
        raise ValueError('mass_properties.center_of_mass must be G, the body-frame origin '
                         '(use centred_on_mass)')
    parts = mesh_parts(body, mass_properties, p.resolution, p.thickness * body.size)
    meshes = ''.join(f'<mesh name="{name}" vertex="{_fmt(mesh.vertices)}"/>'
                     for name, mesh in parts.items())
    geoms = ''.join(f'<geom name="{name}" type="mesh" mesh="{name}"/>' for name in parts)
    i = mass_properties.inertia
    full = _fmt([i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]])
    return f"""<mujoco model="twodisk">
  <compiler inertiafromgeom="false" angle="radian"/>
  <option timestep="{p.timestep!r}" integrator="{p.integrator}" cone="{p.cone}"
          gravity="{gravity_text}"/>
  <default><geom condim="3" friction="{float(p.mu)!r} 0 0"
    solref="{p.time_constant!r} {p.damping_ratio!r}" margin="0"/></default>
  <asset>{meshes}</asset>
  <worldbody>
    <geom name="ground" type="plane" size="0 0 1"/>
    <body name="body">
      <freejoint name="free"/>
      <inertial pos="0 0 0" mass="{mass_properties.mass!r}" fullinertia="{full}"/>
      {geoms}
    </body>
  </worldbody>
</mujoco>"""


def build_model(body, mass_properties, gravity=9.81, parameters=None, slope=0.0):
    """MuJoCo's compiled ``MjModel`` of :func:`engine_xml` (same arguments)."""
    import mujoco
    return mujoco.MjModel.from_xml_string(engine_xml(body, mass_properties, gravity, parameters,
                                                     slope))


def landing_depth_factor(damping_ratio):
    """f(ζ): the largest penetration of a landing at normal speed v is v τ f(ζ) (m, τ the
    time constant, s) while d = dmax.

    MuJoCo's soft contact drives the penetration x (m) to a = −d b ẋ − d k x + (1 − d) a0
    with b = 2 / (dmax τ), k = d / (dmax² τ² ζ²): at d = dmax a damped spring of natural
    frequency ω0 = 1 / (τ ζ) and damping ratio ζ. From x(0) = 0, ẋ(0) = v its largest x is
    (v / ω0) exp(−ζ φ / s) with s = √|1 − ζ²| and φ = atan(s / ζ) (ζ < 1) or artanh(s / ζ)
    (ζ > 1); ζ = 1: v τ / e. Nearer the surface than ``width`` d < dmax softens the spring by
    d / dmax: at most dmax / d0 more (:data:`IMPEDANCE`). Gravity's (1 − d) a0 adds what the
    body sinks from rest (G 1.4e-5 m with the defaults, module docstring).
    """
    zeta = _number('damping_ratio', damping_ratio, 1e-3, 10.0, '(1 is critical)')
    if zeta == 1.0:
        return math.exp(-1.0)
    s = math.sqrt(abs(1.0 - zeta * zeta))
    phase = math.atan2(s, zeta) if zeta < 1.0 else math.atanh(s / zeta)
    return zeta * math.exp(-zeta * phase / s)


def contact_metadata(parameters=None):
    """{key: text}: the engine's contact parameters for a recording's metadata (the
    inspector's landing depth bound, inspector/engine_stretches.py); ``parameters`` a
    :class:`ContactParameters` (None: the defaults, the node's)."""
    p = ContactParameters() if parameters is None else parameters
    return {'engine_time_constant': repr(float(p.time_constant)),
            'engine_damping_ratio': repr(float(p.damping_ratio)),
            'engine_timestep': repr(float(p.timestep)),
            'engine_impedance': ' '.join(repr(float(x)) for x in IMPEDANCE)
            + ' (MuJoCo solimp d0 dmax width m)'}

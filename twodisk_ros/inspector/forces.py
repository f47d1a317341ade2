"""Contact forces of a recording: recomputed from the poses, read from the wrenches, exact.

Newton–Euler with both contacts on the ground (docs/contact_forces.md), in the world frame:
with a_G and ω̇ by finite differences of the recorded poses (:mod:`.differences`), M and
I_G (body frame, about G) from the recorded mass model, R the body → world rotation,

    F = F_A + F_B = M a_G + M g e_z,
    L_G = R (I Rᵀω̇ + (Rᵀω) × I Rᵀω) = (A − G) × F_A + (B − G) × F_B + τ ê,

τ ê a drive moment about AB (kinematic mode; 0 in a free motion). With d = B − A = |AB| ê
and L_A = L_G − (A − G) × F the moments about A, d × F_B + τ ê = L_A, so the part of F_B
perpendicular to AB is F_B⊥ = (L_A × d) / |d|² and τ = ê·L_A. With p = e_z × ê the
determinate components are N_A = F_A·e_z, N_B = F_B·e_z, T_A = F_A·p, T_B = F_B·p and the
total along AB, S = F·ê; the split of S between A and B is free (an internal squeeze).

The recorded wrenches give the same components (and the split); the exact forces of the
model at a state (u, u̇) come from :class:`~twodisk_ros.physics.forces.contact.
ContactForceModel`. Invalid stretches (lift-off, slip) are found by :func:`invalid_stretches`.
Units: N, N m, s.
"""

from dataclasses import dataclass, field
import math

import numpy as np

from ..physics.forces.contact import squeeze_split

__all__ = ['ForceComponents', 'Stretch', 'exact_components', 'invalid_stretches',
           'newton_euler', 'recorded_components']

_UP = np.array([0.0, 0.0, 1.0])


def _dot(x, y):
    return np.sum(x * y, axis=-1)


@dataclass
class ForceComponents:
    """The determinate ground forces at K samples (N; N m for the drive torque).

    ``along_a`` (F_A·ê of a split) is known for recorded wrenches only (None otherwise);
    ``drive_torque`` (τ = ê·L_A) for forces recomputed from poses or exact (None for recorded
    wrenches, which carry no torque).
    """

    total: np.ndarray           #: F_A + F_B (K, 3), world
    normal_a: np.ndarray        #: N_A
    normal_b: np.ndarray        #: N_B
    tangential_a: np.ndarray    #: T_A = F_A·p, p = e_z × ê
    tangential_b: np.ndarray    #: T_B = F_B·p
    along_ab: np.ndarray        #: S = (F_A + F_B)·ê
    along_a: np.ndarray | None = None
    drive_torque: np.ndarray | None = None

    @property
    def mu_required(self):
        """The least friction coefficient for these forces (inf where a contact lifts off)."""
        return squeeze_split(self.normal_a, self.normal_b, self.tangential_a,
                             self.tangential_b, self.along_ab)[3]

    @property
    def rule_split(self):
        """F_A·ê of the split needing the least friction (S/2 where a contact lifts off)."""
        return squeeze_split(self.normal_a, self.normal_b, self.tangential_a,
                             self.tangential_b, self.along_ab)[0]


def _directions(contact_a, contact_b, normal=_UP):
    """ê (unit vector from A to B in the ground) and p = n × ê, world frame; ``normal`` n is
    the ground's unit normal (e_z on flat ground)."""
    d = np.asarray(contact_b, dtype=float) - np.asarray(contact_a, dtype=float)
    e = d - _dot(d, normal)[..., None] * normal
    e = e / np.linalg.norm(e, axis=-1, keepdims=True)
    return e, np.cross(normal, e)


def newton_euler(mass, gravity, position_g, rotation, contact_a, contact_b, acceleration,
                 omega, omega_dot, normal=_UP):
    """The determinate ground forces that a rigid motion needs (module docstring).

    Parameters
    ----------
    mass : MassProperties
        M (kg) and I (kg m², body frame, about G).
    gravity : float
        g (m/s²).
    position_g, contact_a, contact_b : numpy.ndarray, shape (K, 3)
        G, A and B (m, world).
    rotation : scipy.spatial.transform.Rotation, K rotations
        Body → world.
    acceleration, omega, omega_dot : numpy.ndarray, shape (K, 3)
        a_G (m/s²), ω (rad/s), ω̇ (rad/s²), world frame.
    normal : numpy.ndarray, shape (3,)
        The ground's unit normal (e_z on flat ground; gravity stays along −e_z).

    Returns
    -------
    ForceComponents
        With ``drive_torque`` τ = ê·L_A (N m), the moment about AB the motion needs.
    """
    total = mass.mass * (acceleration + gravity * _UP)
    body_omega = rotation.inv().apply(omega)
    body_omega_dot = rotation.inv().apply(omega_dot)
    inertia = mass.inertia
    moment_g = rotation.apply(body_omega_dot @ inertia.T
                              + np.cross(body_omega, body_omega @ inertia.T))
    moment_a = moment_g - np.cross(contact_a - position_g, total)
    d = contact_b - contact_a
    force_b = np.cross(moment_a, d) / _dot(d, d)[:, None]       # F_B⊥
    e, p = _directions(contact_a, contact_b, normal)
    return ForceComponents(total, _dot(total - force_b, normal), _dot(force_b, normal),
                           _dot(total - force_b, p), _dot(force_b, p), _dot(total, e),
                           drive_torque=_dot(moment_a, e))


def recorded_components(force_a, force_b, contact_a, contact_b, normal=_UP):
    """The components of recorded forces at A and at B (world, N), with their split;
    ``normal``: the ground's unit normal."""
    e, p = _directions(contact_a, contact_b, normal)
    total = force_a + force_b
    return ForceComponents(total, _dot(force_a, normal), _dot(force_b, normal),
                           _dot(force_a, p), _dot(force_b, p), _dot(total, e),
                           along_a=_dot(force_a, e))


def exact_components(model, phase, phase_rate, phase_acceleration=None):
    """The model's forces at the phases u (rad) and rates u̇ (rad/s) of a recording.

    Dynamic mode: the free motion through (u, u̇); kinematic mode: the drive holding
    |ω| = |omega0|; with ``phase_acceleration`` ü (rad/s², a scene's), the forces on flat
    ground that this ü needs (in the frame of the model's poses: for the FD error).
    ``model`` is a :class:`~twodisk_ros.inspector.model.RecordedModel`.
    """
    forces_model = model.forces
    if phase_acceleration is not None:
        forces = forces_model.forces(phase, phase_rate, phase_acceleration)
    elif model.mode == 'kinematic':
        forces = forces_model.kinematic(phase, abs(model.omega0))
    else:
        forces = forces_model.dynamic(phase, phase_rate)
    return ForceComponents(forces.force_a + forces.force_b, forces.normal_a, forces.normal_b,
                           forces.tangential_a, forces.tangential_b, forces.along_ab,
                           along_a=forces.along_a, drive_torque=forces.drive_torque)


@dataclass
class Stretch:
    """A run of consecutive samples where the rolling model fails (lift-off or slip)."""

    start_s: float              #: time of the first invalid sample (s)
    end_s: float                #: time of the last invalid sample (s)
    samples: int
    kinds: list                 #: 'slip', 'lift-off A', 'lift-off B', in order of appearance
    reason: str                 #: what fails first, check_validity's wording
    worst: dict = field(default_factory=dict)   #: worst N_A, N_B (N), μ_required, with times

    def describe(self):
        """One line: the times, the first failure and the worst values."""
        worst = '; '.join(f'{name} = {value:.4g}{unit} at t = {time:.6g} s'
                          for name, (value, time, unit) in self.worst.items())
        return (f't = {self.start_s:.6g} … {self.end_s:.6g} s ({self.samples} samples, '
                f'{", ".join(self.kinds)}): {self.reason}; worst {worst}')

    def as_dict(self):
        """JSON-ready description."""
        return {'start_s': self.start_s, 'end_s': self.end_s, 'samples': self.samples,
                'kinds': list(self.kinds), 'reason': self.reason,
                'worst': {name: {'value': value, 't': time, 'unit': unit.strip()}
                          for name, (value, time, unit) in self.worst.items()}}


def _sample_kinds(normal_a, normal_b, need, mu):
    lift_a, lift_b = normal_a < 0, normal_b < 0
    slip = ~(lift_a | lift_b) & (need > mu)
    return lift_a, lift_b, slip


def _reason(t, normal_a, normal_b, need, mu):
    """check_validity's sentence for one invalid sample."""
    if normal_a < 0 or normal_b < 0:
        name, value = ('A', normal_a) if normal_a <= normal_b else ('B', normal_b)
        return f'contact {name} would lift off at t = {t:.6g} s: N_{name} = {value:.4g} N'
    return f'the body would slip at t = {t:.6g} s: mu_required = {need:.4g} > mu = {mu:g}'


def invalid_stretches(t, normal_a, normal_b, need, mu):
    """Runs of samples where N_A < 0, N_B < 0 (lift-off) or μ_required > μ (slip).

    Parameters
    ----------
    t : numpy.ndarray
        Sample times (s), increasing.
    normal_a, normal_b : numpy.ndarray
        N_A, N_B (N).
    need : numpy.ndarray
        μ_required (inf where a contact lifts off).
    mu : float
        Friction coefficient (inf: no slip limit).

    Returns
    -------
    list of Stretch
    """
    lift_a, lift_b, slip = _sample_kinds(normal_a, normal_b, need, mu)
    bad = lift_a | lift_b | slip
    edges = np.diff(np.concatenate([[0], bad.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    stretches = []
    for start, end in zip(starts, ends):
        part = slice(start, end)
        kinds = []
        for k in range(start, end):
            for name, flag in (('slip', slip), ('lift-off A', lift_a), ('lift-off B', lift_b)):
                if flag[k] and name not in kinds:
                    kinds.append(name)
        worst = {}
        for name, values, mask in (('N_A', normal_a, lift_a), ('N_B', normal_b, lift_b)):
            if np.any(mask[part]):
                j = start + int(np.argmin(values[part]))
                worst[name] = (float(values[j]), float(t[j]), ' N')
        contact = np.isfinite(need[part])
        if np.any(slip[part]) and np.any(contact):
            j = start + int(np.argmax(np.where(contact, need[part], -math.inf)))
            worst['mu_required'] = (float(need[j]), float(t[j]), '')
        stretches.append(Stretch(float(t[start]), float(t[end - 1]), int(end - start), kinds,
                                 _reason(t[start], normal_a[start], normal_b[start],
                                         need[start], mu), worst))
    return stretches

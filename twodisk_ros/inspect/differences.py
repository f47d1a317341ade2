"""Velocities and angular velocities of recorded poses, by central finite differences."""

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .series import STAMP_TOLERANCE

__all__ = ['Motion', 'finite_differences', 'kinetic_energy', 'motion_of']

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
class Motion:
    """Velocities of the recorded poses and of the model's poses at the recorded phases."""

    index: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    model_velocity: np.ndarray
    model_angular_velocity: np.ndarray
    model_state: object
    step: float


def motion_of(samples, model, step):
    """Finite differences of the recorded poses and of the model's poses at the same phases."""
    phase = np.unwrap(samples.angles[:, 2])
    state = model.dynamics.cycle.state(phase)
    index, velocity, omega = finite_differences(samples.t, samples.position_g,
                                                samples.rotation, step)
    model_rotation = Rotation.from_matrix(state.rotation)
    _, model_velocity, model_omega = finite_differences(samples.t, state.position_g,
                                                        model_rotation, step)
    return Motion(index, velocity, omega, model_velocity, model_omega, state, step)


def kinetic_energy(mass, velocity, omega, rotation):
    """½ M |v|² + ½ ωᵀ (R I Rᵀ) ω, with ω in the world frame (J)."""
    body_omega = rotation.inv().apply(omega)
    spin = np.einsum('ni,ij,nj->n', body_omega, mass.inertia, body_omega)
    return 0.5 * mass.mass * np.sum(velocity * velocity, axis=1) + 0.5 * spin

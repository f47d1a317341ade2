"""Velocities and accelerations of recorded poses, by central finite differences.

Both derivatives use the five samples t − 2h ... t + 2h (fourth order). For the rotation
the differenced quantity is φ(τ) = log(R(t + τ) R(t)ᵀ), the rotation vector of the turn
from t to t + τ (world frame). With R(t + τ) = exp([φ(τ)]×) R(t) the world angular
velocity is ω(t + τ) = J(φ) φ′(τ), J(φ) = I + ½ [φ]× + O(|φ|²) the left Jacobian of
SO(3); at τ = 0, φ = 0, so ω(t) = φ′(0) and, differentiating once more,
ω̇(t) = φ″(0) + ½ φ′(0) × φ′(0) = φ″(0). Both are derivatives at 0 of one smooth vector
function, so the five-point first and second differences of φ give ω and ω̇ to fourth
order (tests/test_inspect_forces.py checks this against R = Rz(α) Ry(β) Rx(γ)).
"""

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .series import STAMP_TOLERANCE

__all__ = ['Motion', 'finite_differences', 'kinetic_energy', 'motion_of', 'second_differences']

_STENCIL = np.arange(-2, 3)


def _stencils(t, step):
    """Samples with four regular intervals around them, their neighbours and offsets."""
    t = np.asarray(t, dtype=float)
    if t.size < 5:
        return None
    regular = np.abs(np.diff(t) - step) <= STAMP_TOLERANCE * step
    usable = regular[:-3] & regular[1:-2] & regular[2:-1] & regular[3:]
    index = np.nonzero(usable)[0] + 2
    if index.size == 0:
        return None
    around = index[:, None] + _STENCIL[None, :]
    offsets = (t[around] - t[index][:, None]) / step            # ≈ -2 ... 2
    return index, around, offsets


def _weights(offsets, order, step):
    """Weights of the five-point stencils at ``offsets`` for the derivative of ``order``.

    Exact for polynomials of degree 4: Σ_n w_n p(x_n) = p^(order)(0) (order! for the monomial
    x^order), divided by step^order.
    """
    powers = offsets[:, None, :] ** np.arange(5)[None, :, None]  # (K, degree, node)
    unit = np.zeros((offsets.shape[0], 5, 1))
    unit[:, order] = float(np.prod(np.arange(1, order + 1)))
    return np.linalg.solve(powers, unit)[..., 0] / step**order


def _turns(rotation, index):
    """φ_k = rotation vector of R(t_{i+k}) R(t_i)ᵀ for k = −2 ... 2, shape (K, 5, 3)."""
    reference_inverse = rotation[index].inv()
    return np.stack([(rotation[index + k] * reference_inverse).as_rotvec()
                     for k in _STENCIL], axis=1)


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
    return _differences(t, position, rotation, step, order=1)


def _differences(t, position, rotation, step, order):
    """(index, d^order x / dt^order, d^order φ / dτ^order at τ = 0) on the five-point stencils."""
    found = _stencils(t, step)
    if found is None:
        return np.zeros(0, dtype=int), np.zeros((0, 3)), np.zeros((0, 3))
    index, around, offsets = found
    weights = _weights(offsets, order, step)
    displacement = position[around] - position[index][:, None, :]
    return (index, np.einsum('kn,knj->kj', weights, displacement),
            np.einsum('kn,knj->kj', weights, _turns(rotation, index)))


def second_differences(t, position, rotation, step):
    """Fourth-order central second differences: acceleration and angular acceleration.

    Same samples and parameters as :func:`finite_differences`.

    Returns
    -------
    index : numpy.ndarray of int
        The samples used (those of :func:`finite_differences`).
    acceleration : numpy.ndarray, shape (K, 3)
        d²x/dt² (m/s²) from x at t_{i-2} ... t_{i+2}.
    angular_acceleration : numpy.ndarray, shape (K, 3)
        dω/dt, world frame (rad/s²): the second derivative at τ = 0 of the rotation vector
        φ(τ) of R(t + τ) R(t)ᵀ (module docstring: ω̇ = φ″(0) exactly).

    Notes
    -----
    For equal intervals the weights are (−1, 16, −30, 16, −1) / 12h², error ~ h⁴/90 × the
    sixth derivative: ~ (ω h)⁴ relative to the accelerations of a body turning at ω.
    """
    return _differences(t, position, rotation, step, order=2)


@dataclass
class Motion:
    """Derivatives of the recorded poses and of the model's poses at the recorded phases.

    Velocities (m/s, rad/s) and accelerations (m/s², rad/s²) in the world frame, at the
    samples ``index`` (first and second differences use the same five samples).
    """

    index: np.ndarray
    velocity: np.ndarray
    angular_velocity: np.ndarray
    model_velocity: np.ndarray
    model_angular_velocity: np.ndarray
    model_state: object
    step: float
    acceleration: np.ndarray = None
    angular_acceleration: np.ndarray = None
    model_acceleration: np.ndarray = None
    model_angular_acceleration: np.ndarray = None


def motion_of(samples, model, step, breaks=()):
    """Finite differences of the recorded poses and of the model's poses at the same phases.

    ``breaks``: stamps (int ns) at which a new stretch of the run begins (the node's events:
    a reset, a command, a pause); no stencil reaches across one, so each stretch is
    differenced on its own.
    """
    phase = np.unwrap(samples.angles[:, 2])
    state = model.dynamics.cycle.state(phase)
    index, velocity, omega = finite_differences(samples.t, samples.position_g,
                                                samples.rotation, step)
    _, acceleration, omega_dot = second_differences(samples.t, samples.position_g,
                                                    samples.rotation, step)
    model_rotation = Rotation.from_matrix(state.rotation)
    _, model_velocity, model_omega = finite_differences(samples.t, state.position_g,
                                                        model_rotation, step)
    _, model_acceleration, model_omega_dot = second_differences(
        samples.t, state.position_g, model_rotation, step)
    keep = _within_stretches(samples.stamp_ns, index, breaks)
    return Motion(index[keep], velocity[keep], omega[keep], model_velocity[keep],
                  model_omega[keep], state, step, acceleration[keep], omega_dot[keep],
                  model_acceleration[keep], model_omega_dot[keep])


def _within_stretches(stamps, index, breaks):
    """True for the samples whose stencil (i − 2 … i + 2) lies inside one stretch: no break
    stamp b with stamp[i − 2] < b ≤ stamp[i + 2]."""
    keep = np.ones(index.shape, dtype=bool)
    if index.size == 0:
        return keep
    low, high = stamps[index - 2], stamps[index + 2]
    for b in breaks:
        keep &= ~((low < b) & (b <= high))
    return keep


def kinetic_energy(mass, velocity, omega, rotation):
    """½ M |v|² + ½ ωᵀ (R I Rᵀ) ω, with ω in the world frame (J)."""
    body_omega = rotation.inv().apply(omega)
    spin = np.einsum('ni,ij,nj->n', body_omega, mass.inertia, body_omega)
    return 0.5 * mass.mass * np.sum(velocity * velocity, axis=1) + 0.5 * spin

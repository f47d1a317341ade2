"""The body's orientation as a unit quaternion that is a continuous function of the phase u.

Convention: quaternions are (x, y, z, w), scalar last (ROS, scipy), and rotate body → world.
The pose at phase u is ``R = R_z(α) C(u)`` (docs/physics.md#orientation-as-a-quaternion):
``C(u)``, with rows t1, m = n × t1 and n (body frame), maps the contact frame onto the world
axes, and ``R_z(α)`` turns it about the world's Z by the heading α. Both factors are lifted
to quaternions continuously in u:

* q_z(α) = (0, 0, sin(α/2), cos(α/2)), continuous since α(u) is;
* q_c(u), tabulated over one cycle, made continuous node by node, with w > 0 at u = 0.
  After one cycle C returns to itself and q_c to ``ε q_c`` with a sign ε = ±1 fixed by the
  shape (the loop C(u) in SO(3) is or is not contractible); ``q_c(u + 2πk) = ε^k q_c(u)``.

Then q(u) = q_z(α(u)) ⊗ q_c(u) is continuous in u over any number of cycles, for negative u
too, and q(0) = q_c(0) has w > 0.
"""

import numpy as np

from ..numerics.analytic import complex_step_jet
from ..numerics.spectral import spectral_derivative

__all__ = ['contact_quaternion_samples', 'pure_product', 'quaternion_from_matrix',
           'CONTINUITY_MIN_DOT']

#: Neighbouring nodes of the tabulated quaternion must agree at least this well (q_j·q_{j+1});
#: the nodes turn by ≪ 1 rad, so the dot product is ≈ 1 and its sign unambiguous.
CONTINUITY_MIN_DOT = 0.5


def pure_product(vector, quaternion):
    """Hamilton product (v, 0) ⊗ q of a pure quaternion and q = (x, y, z, w).

    Parameters
    ----------
    vector : ndarray, shape (..., 3)
    quaternion : ndarray, shape (..., 4), (x, y, z, w)

    Returns
    -------
    ndarray, shape (..., 4): (w v + v × q_xyz, −v · q_xyz)
    """
    xyz, w = quaternion[..., :3], quaternion[..., 3:]
    return np.concatenate([w * vector + np.cross(vector, xyz),
                           -np.sum(vector * xyz, axis=-1, keepdims=True)], axis=-1)


def quaternion_from_matrix(matrix):
    """Unit quaternions (x, y, z, w) of rotation matrices, one of the two signs each.

    Markley's method (J. Guid. Control Dyn. 31(2), 2008, 440–442), as in scipy's
    ``Rotation.from_matrix``: of the four equivalent formulas, the one whose pivot
    (1 + trace, or 1 − trace + 2 R_ii) is largest, so no component comes from a
    difference of nearly equal numbers. Written in numpy because the node needs only this
    of ``scipy.spatial``, whose import costs half a second of every node start.

    Parameters
    ----------
    matrix : ndarray, shape (..., 3, 3)
        Rotation matrices (orthonormal, det +1, up to rounding).

    Returns
    -------
    ndarray, shape (..., 4)
        q with R = R(q), normalised; its sign is not fixed (q and −q are one rotation).
    """
    r = np.asarray(matrix, dtype=float)
    diagonal = np.diagonal(r, axis1=-2, axis2=-1)
    trace = np.sum(diagonal, axis=-1)
    pivots = np.concatenate([diagonal, trace[..., None]], axis=-1)
    choice = np.argmax(pivots, axis=-1)
    q = np.empty(r.shape[:-2] + (4,))
    for i in range(3):                           # pivot on x, y or z: 1 − tr + 2 R_ii
        j, k = (i + 1) % 3, (i + 2) % 3
        at = choice == i
        ra = r[at]
        q[at, i] = 1.0 - trace[at] + 2.0 * ra[:, i, i]
        q[at, j] = ra[:, j, i] + ra[:, i, j]
        q[at, k] = ra[:, k, i] + ra[:, i, k]
        q[at, 3] = ra[:, k, j] - ra[:, j, k]
    at = choice == 3                             # pivot on w: 1 + tr
    ra = r[at]
    q[at, 0] = ra[:, 2, 1] - ra[:, 1, 2]
    q[at, 1] = ra[:, 0, 2] - ra[:, 2, 0]
    q[at, 2] = ra[:, 1, 0] - ra[:, 0, 1]
    q[at, 3] = 1.0 + trace[at]
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def contact_quaternion_samples(t1, normal):
    """q_c, q_c′ and q_c″ at the nodes u_j = 2πj/N of one cycle, continuous, and the sign ε.

    Parameters
    ----------
    t1, normal : ndarray, complex, shape (N, 3)
        Unit tangent of disk 1 at A and unit ground normal (body frame) evaluated at
        u_j + i·:data:`~twodisk_ros.physics.numerics.analytic.COMPLEX_STEP` (their derivatives in u
        come from the imaginary parts).

    Returns
    -------
    values, first, second : ndarray, shape (N, 4)
        q_c = quaternion of C = [t1; n × t1; n] (body → contact-aligned axes), (x, y, z, w),
        and its first and second derivatives in u (per rad). Node 0 has w > 0 and
        consecutive nodes have positive dot products.
    sign : float
        ε = ±1: the continuation of the nodes reaches ε q_c(0) at u = 2π.

    Notes
    -----
    With C′ Cᵀ = [W]× (W: angular velocity of C per unit u, contact-aligned axes),
    q′ = ½ (W, 0) ⊗ q and q″ = ½ ((W′, 0) ⊗ q + (W, 0) ⊗ q′); W is periodic, so W′ is its
    spectral derivative.
    """
    (t1, dt1), (n, dn) = complex_step_jet((t1, normal))
    m = np.cross(n, t1)
    dm = np.cross(dn, t1) + np.cross(n, dt1)
    c = np.stack([t1, m, n], axis=-2)
    dc = np.stack([dt1, dm, dn], axis=-2)
    q = quaternion_from_matrix(c)
    dots = np.sum(q[1:] * q[:-1], axis=-1)
    if np.min(np.abs(dots)) < CONTINUITY_MIN_DOT:
        raise ValueError('contact frame turns too far between nodes to follow its sign')
    flips = np.concatenate([[1.0], np.cumprod(np.sign(dots))])
    q = q * flips[:, None]
    if q[0, 3] < 0:
        q = -q
    closing = float(np.dot(q[-1], q[0]))
    if abs(closing) < CONTINUITY_MIN_DOT:
        raise ValueError('contact frame turns too far between the last node and u = 2π')
    sign = 1.0 if closing > 0 else -1.0
    skew = np.einsum('...ij,...kj->...ik', dc, c)                  # C′ Cᵀ = [W]×
    omega = 0.5 * np.stack([skew[..., 2, 1] - skew[..., 1, 2],
                            skew[..., 0, 2] - skew[..., 2, 0],
                            skew[..., 1, 0] - skew[..., 0, 1]], axis=-1)
    first = 0.5 * pure_product(omega, q)
    second = 0.5 * (pure_product(spectral_derivative(omega), q) + pure_product(omega, first))
    return q, first, second, sign

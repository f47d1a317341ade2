"""The ellipse body's contact angle θ as a function of the regular phase u.

u sweeps the eccentric anomaly η of A on disk 1 sinusoidally: η = η_max sin u, with A at
(b sin η, −a cos η) from the centre of disk 1, so tan θ = (b/a) tan η. Sharp features of thin
ellipses (b/a → 0 or ∞) then have width ~min(a, b)/max(a, b) in u, not its square
(docs/physics.md#the-regular-phase-u). :func:`phase_angles` takes arrays, complex ones too
(complex-step derivatives); an ODE's right-hand side asks for one real phase at a time, where
numpy's per-operation set-up would cost ~70 µs a call, so a real scalar takes
:func:`phase_angles_at`: the same operations in the same order on floats (~2 µs), the same
results bit for bit.
"""

import math

import numpy as np

from ..numerics.analytic import sinc

__all__ = ['phase_angles', 'phase_angles_at']


def phase_angles(u, constants):
    """(θ, cos θ, sin θ, j) at phase u (rad), with cos θ − cos θ_max = j cos²u.

    Analytic in u (complex-step safe); exact near the turning points u = ±π/2. ``constants``:
    (a, b, η_max, θ_max, cos η_max, sin η_max, E_max) as :func:`phase_angles_at` takes them.
    """
    if isinstance(u, (float, np.floating)):
        return phase_angles_at(u, *constants)
    a, b, eta_m, tm, cos_eta_max, sin_eta_max, e_m = constants
    w = np.sin(u)
    sign_w = np.where(w.real < 0, -1.0, 1.0)
    abs_w = w * sign_w
    abs_eta = eta_m * abs_w
    cos_eta, sin_eta = np.cos(abs_eta), np.sin(abs_eta)
    e = np.sqrt(a * a * cos_eta ** 2 + b * b * sin_eta ** 2)
    cos_t = a * cos_eta / e
    sin_abs = b * sin_eta / e
    # v = η_max − |η| = η_max cos²u / (1 + |w|) ≥ 0, exactly
    v_over_c2 = eta_m / (1 + abs_w)
    v = v_over_c2 * np.cos(u) ** 2
    x = a * a * cos_eta * cos_eta_max + b * b * sin_eta * sin_eta_max
    # tan((θ_max − |θ|)/2) = a b sin v / (E E_m + X), denominator > 0 over the whole cycle
    denom = e * e_m + x
    t = a * b * np.sin(v) / denom
    # |θ| = θ_max − 2 arctan t, exact near the turning points; away from them (|η| < 1,
    # cos η > 0) the direct tan θ = (b/a) tan η has no cancellation near θ = 0
    near_axis = abs_eta.real < 1.0
    tan_eta = np.tan(np.where(near_axis, abs_eta, 0.0))
    abs_theta = np.where(near_axis, np.arctan(b * tan_eta / a), tm - 2 * np.arctan(t))
    j = (2 * np.sin((tm + abs_theta) / 2) / np.sqrt(1 + t * t)
         * a * b * v_over_c2 * sinc(v) / denom)
    return sign_w * abs_theta, cos_t, sign_w * sin_abs, j


def phase_angles_at(u, a, b, eta_m, tm, cos_eta_max, sin_eta_max, e_max):
    """:func:`phase_angles` at one real phase u (rad), in floats.

    ``a``, ``b`` the semi-axes (m); ``eta_m`` η_max and ``tm`` θ_max (rad); ``cos_eta_max``,
    ``sin_eta_max`` their cosine and sine of η_max; ``e_max`` √(a² cos²η_max + b² sin²η_max)
    (m), as :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody` holds them.
    """
    a, b, eta_m, tm = float(a), float(b), float(eta_m), float(tm)
    cos_eta_max, sin_eta_max, e_max = float(cos_eta_max), float(sin_eta_max), float(e_max)
    w = math.sin(u)
    sign_w = -1.0 if w < 0 else 1.0
    abs_w = w * sign_w
    abs_eta = eta_m * abs_w
    cos_eta, sin_eta = math.cos(abs_eta), math.sin(abs_eta)
    e = math.sqrt(a * a * (cos_eta * cos_eta) + b * b * (sin_eta * sin_eta))
    cos_t = a * cos_eta / e
    sin_abs = b * sin_eta / e
    v_over_c2 = eta_m / (1 + abs_w)
    cos_u = math.cos(u)
    v = v_over_c2 * (cos_u * cos_u)
    x = (a * a * cos_eta * cos_eta_max
         + b * b * sin_eta * sin_eta_max)
    denom = e * e_max + x
    t = a * b * math.sin(v) / denom
    if abs_eta < 1.0:
        abs_theta = math.atan(b * math.tan(abs_eta) / a)
    else:
        abs_theta = tm - 2 * math.atan(t)
    v2 = v * v
    sinc_v = math.sin(v) / v if abs(v) >= 1e-3 else \
        1.0 - v2 / 6.0 + v2 * v2 / 120.0 - v2 * v2 * v2 / 5040.0
    j = (2 * math.sin((tm + abs_theta) / 2) / math.sqrt(1 + t * t)
         * a * b * v_over_c2 * sinc_v / denom)
    return sign_w * abs_theta, cos_t, sign_w * sin_abs, j

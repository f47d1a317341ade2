"""A scene's motion at sample times, and the pieces of dense output it is read from.

:class:`SceneSamples` is what :mod:`~twodisk_ros.physics.scenes.motion` returns;
:func:`samples_from` builds it from the regular state (u, w) (w = |ω_u| u̇ the angular speed
about AB), so that it holds where the body stops turning in u; :class:`Piece` is one stretch
of DOP853's dense output in the regularised time τ (dt/dτ = |ω_u|), read at times t.
"""

from dataclasses import dataclass

import numpy as np

from ..numerics.dense import dense_reader
from .terms import DW, STOPPED

__all__ = ['Piece', 'SceneSamples', 'samples_from']


@dataclass
class SceneSamples:
    """A scene's motion at sample times (arrays over ``t``; SI units)."""

    t: np.ndarray                   #: s
    phase: np.ndarray               #: u (rad)
    phase_rate: np.ndarray          #: u̇ (rad/s)
    phase_acceleration: np.ndarray  #: ü (rad/s²)
    energy: np.ndarray              #: E = T + V (J), V along gravity (0 at A's start height)
    dissipated: np.ndarray          #: W (J): work done by damping and rolling resistance
    drive_work: np.ndarray          #: W_d (J): work done by the drive
    drive_torque: np.ndarray        #: τ about AB (N m) (0 without drive)
    power: np.ndarray               #: drive power τ ê·ω (W)
    rolling_speed: np.ndarray       #: Ω = w = |ω_u| u̇ (rad/s), signed: finite everywhere
    #: ẇ (rad/s²), the angular acceleration about AB (finite where the body stops turning
    #: in u, unlike ü); forces from (u, w, ẇ): SceneTerms.forces(..., turning=True)
    angular_acceleration: np.ndarray = None

    @property
    def balance(self):
        """E + W − W_d (J): constant (= E₀) along any motion."""
        return self.energy + self.dissipated - self.drive_work


class Piece:
    """One stretch [start, end] of the motion: dense output of the state, or rest.

    ``sol`` is scipy's dense output in the regularised time τ (``steps``: the solver's
    (τ, t) nodes, t the last state component), inverted by safeguarded Newton (dt/dτ =
    |ω_u| from ``rate``); ``start_of`` a callable for the closed-form start from a stop."""

    def __init__(self, start, end, sol=None, rest=None, steps=None, rate=None, start_of=None):
        self.start, self.end, self.rest = start, end, rest
        self.sol = None if sol is None else dense_reader(sol)
        self.steps, self.rate, self.start_of = steps, rate, start_of

    def __call__(self, t):
        if self.start_of is not None:
            return self.start_of(t)
        if self.sol is None:
            return np.repeat(np.asarray(self.rest, dtype=float)[:, None], len(t), axis=1)
        tau_nodes, t_nodes = self.steps
        i = np.clip(np.searchsorted(t_nodes, t, side='right') - 1, 0, len(t_nodes) - 2)
        low, high = tau_nodes[i], tau_nodes[i + 1]
        tau = low + (high - low) * np.clip((t - t_nodes[i]) / np.maximum(
            t_nodes[i + 1] - t_nodes[i], 1e-300), 0.0, 1.0)
        floor = 4e-16 * max(1.0, abs(float(t_nodes[-1])))
        for _ in range(60):
            y = self.sol(tau)
            gap = y[-1] - t
            later = gap >= 0
            low, high = np.where(later, low, tau), np.where(later, tau, high)
            if np.all(np.abs(gap) <= floor) or np.all(high - low <= 1e-15 * np.abs(tau)):
                break
            slope = self.rate(y[0])
            with np.errstate(divide='ignore', invalid='ignore'):
                guess = tau - gap / slope
            inside = (guess > low) & (guess < high) & np.isfinite(guess)
            tau = np.where(inside, guess, 0.5 * (low + high))
        return self.sol(tau)[:-1]


def samples_from(terms, t, u, w, w_tau, rate, dissipated, drive_work, q_drive):
    """:class:`SceneSamples` from (u, w) and dw/dτ = |ω_u| ẇ: u̇ = w/|ω_u|,
    ü = (ẇ − |ω_u|′ u̇²)/|ω_u| (inf and nan where |ω_u| = 0, w ≠ 0), τ = Q_drive/|ω_u|."""
    slope = terms.rows(u)[..., DW]
    stopped = rate <= STOPPED * terms.turn_scale
    with np.errstate(divide='ignore', invalid='ignore'):
        u_dot = np.where(stopped & (w == 0), 0.0, w / rate)
        w_dot = np.where(stopped & (w_tau == 0), 0.0, w_tau / rate)
        u_ddot = np.where(stopped & (w == 0) & (w_tau == 0), 0.0,
                          (w_dot - slope * u_dot**2) / rate)
        torque = q_drive / rate
    return SceneSamples(t=t, phase=u, phase_rate=u_dot, phase_acceleration=u_ddot,
                        energy=terms.energy_turning(u, w), dissipated=dissipated,
                        drive_work=drive_work, drive_torque=torque, power=torque * w,
                        rolling_speed=w, angular_acceleration=w_dot)

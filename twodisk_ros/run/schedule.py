"""The sample schedule the node and ``twodisk-view`` share (no rclpy here).

Sample (tick) k of a run is at simulated time t = k / rate (s) and is stamped
``T0 + round(k × 1e9 / rate)`` ns, the same on every topic, where T0 (ns) is the system clock
when the run starts (README, "Stamps and simulated time"). A run of ``duration`` s (> 0) has
the ticks 0 … ⌊duration × rate⌋ (the end included, to 1e-9 of a tick); 0 runs until stopped.
"""

import math

import numpy as np

__all__ = ['last_tick', 'stamps']


def stamps(start_ns, ticks, rate):
    """Stamps (int64 ns) of the ticks k: ``start_ns + round(k × 1e9 / rate)``.

    Parameters
    ----------
    start_ns : int
        T0, the stamp of tick 0 (ns).
    ticks : array_like of int
        Global tick indices k.
    rate : float
        Samples per second of simulated time (Hz).
    """
    return int(start_ns) + np.round(np.asarray(ticks) * (1e9 / rate)).astype(np.int64)


def last_tick(duration, rate):
    """The last tick of a run of ``duration`` s at ``rate`` Hz, or None for 0 (until stopped)."""
    if duration <= 0:
        return None
    return int(math.floor(duration * rate + 1e-9))

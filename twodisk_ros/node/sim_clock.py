"""``/clock``: the node's simulated time, for nodes that run with ``use_sim_time:=true``.

The rule for stamps (both modes): sample k of a run is stamped ``T0 + k / rate`` (integer
nanoseconds, ``round(k * 1e9 / rate)``), where T0 is the system clock when the run starts
(realtime: at the first tick; batch: when the node is built). Stamps are therefore the
simulated time since start plus one wall-clock offset, the same on every topic.

- Real time (``realtime:=true``): samples are published when the wall clock reaches their
  stamp, so stamps follow the system clock (within a tick) and ``/clock`` is redundant for
  nodes on the system clock; it still lets a ``use_sim_time`` node follow.
- Batch (``realtime:=false``): samples are published as fast as they are computed, so
  stamps run ahead of the system clock, faster than real time. A node with
  ``use_sim_time:=true`` takes its ``now()`` from ``/clock`` and follows the simulation at
  that speed (its timers, tf2 buffer and message filters see the simulated time).

``/clock`` carries the stamp of a published sample, sent just before that sample's messages
(so a follower's ``now()`` is never behind the data it receives), at every sample up to
:data:`CLOCK_MAX_RATE` of simulated time and every ``ceil(rate / CLOCK_MAX_RATE)``-th tick
above it (tick 0 always). QoS as ``rclcpp::ClockQoS`` (best effort, keep last 1), like
simulators publish it; nothing is built when nobody subscribes. ``/clock`` is not recorded:
a recording's log times are the stamps, and ``ros2 bag play --clock`` publishes them.

The node itself cannot follow a clock it publishes: ``use_sim_time:=true`` on the roller is
refused (:func:`check_use_sim_time`), at start-up and at run time.
"""

import math

import numpy as np
from rclpy.qos import QoSProfile, ReliabilityPolicy

from ..recordings import cdr

__all__ = ['CLOCK_MAX_RATE', 'CLOCK_QOS', 'CLOCK_TOPIC', 'USE_SIM_TIME', 'check_use_sim_time', 'clock_step',
           'encode_clock_column']

CLOCK_TOPIC = '/clock'
#: Hz of simulated time: /clock is published at every sample up to this rate.
CLOCK_MAX_RATE = 1000.0
#: rclcpp::ClockQoS: best effort, keep last 1 (what rclpy's time source subscribes with)
CLOCK_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)
USE_SIM_TIME = 'use_sim_time'
_REFUSAL = ('use_sim_time must be false for roller: it is the source of the simulated time '
            '(it publishes /clock); give use_sim_time:=true to the nodes that follow it')


def check_use_sim_time(value):
    """Raise ValueError (one line) if the roller is asked to follow /clock."""
    if value is True:
        raise ValueError(_REFUSAL)


def clock_step(rate):
    """Ticks between two /clock messages at ``rate`` Hz: 1 up to :data:`CLOCK_MAX_RATE`."""
    return max(1, math.ceil(rate / CLOCK_MAX_RATE - 1e-9))


def encode_clock_column(first_tick, stamps, step):
    """CDR ``rosgraph_msgs/Clock`` of the samples of a block whose tick is a multiple of step.

    Parameters
    ----------
    first_tick : int
        Global tick of the block's first sample.
    stamps : ndarray of int64, shape (n,)
        The block's stamps (ns).
    step : int
        :func:`clock_step` of the rate.

    Returns
    -------
    list
        One entry per sample: the message's bytes, or None where no /clock is sent.
    """
    if step == 1:
        return cdr.encode_clock(stamps)
    column = [None] * len(stamps)
    chosen = np.flatnonzero((first_tick + np.arange(len(stamps))) % step == 0)
    for i, data in zip(chosen.tolist(), cdr.encode_clock(stamps[chosen])):
        column[i] = data
    return column

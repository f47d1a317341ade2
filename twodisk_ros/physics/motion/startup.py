"""What building a body's tables will cost, known before paying it (for the node's log).

Every table of a body (cycle, dynamics, contact forces, equilibria) is sampled on a grid
proportional to :attr:`RollingCycle.resolution <twodisk_ros.physics.bodies.cycle.RollingCycle>`,
which grows as the body's functions of the phase get sharper features: 512 nodes for the
Oloid, 32 768 for b/a = 0.01 or 100, 65 536 for b/a = 0.01 with Δ/a = 1e-3 (the costliest
allowed body). The grid is found cheaply first (:meth:`RollingCycle.required_resolution`),
so the cost can be announced while it is paid.
"""

from dataclasses import dataclass

from ..bodies.cycle import RollingCycle

__all__ = ['SECONDS_PER_NODE', 'NOTICE_SECONDS', 'StartupEstimate', 'startup_estimate']

#: CPU seconds of the node's start-up per node of the cycle's grid: cycle, dynamics and
#: contact-force tables, equilibria, motion and the first block of samples (measured on the
#: 2-core development machine: 4.0 s at 65 536 nodes, 1.2–1.7 s at 32 768, 0.8 s at 16 384)
SECONDS_PER_NODE = 6e-5
#: estimates above this (s) come with a message to log
NOTICE_SECONDS = 2.0


@dataclass(frozen=True)
class StartupEstimate:
    """The expected cost of building a body's tables."""

    resolution: int      #: nodes of the cycle's spectral grid
    seconds: float       #: expected CPU time (s) on the development machine
    message: str | None  #: one line to log if ``seconds`` > NOTICE_SECONDS, else None


def startup_estimate(body):
    """The :class:`StartupEstimate` of a :class:`~twodisk_ros.physics.bodies.protocol.RollingBody`.

    Costs ~1 % of the build itself (0.04 s at the costliest allowed body).
    """
    resolution = RollingCycle.required_resolution(body)
    seconds = SECONDS_PER_NODE * resolution
    message = None
    if seconds > NOTICE_SECONDS:
        message = (f'building tables for an extreme body ({body.resolution_cause()}: '
                   f'{resolution} nodes per cycle): about {seconds:.0f} s')
    return StartupEstimate(resolution, seconds, message)

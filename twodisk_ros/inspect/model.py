"""The body, mass model and mode that a recording's parameters describe.

The recorded parameters are read with the node's own contract
(:func:`twodisk_ros.node.parameters.parse_recorded`), so the inspector accepts exactly what
the node accepts.
"""

from dataclasses import dataclass

from ..node.parameters import parse_recorded
from ..physics.body import TwoDiskBody
from ..physics.dynamics import RollingDynamics

__all__ = ['RecordedModel', 'build_model']


@dataclass
class RecordedModel:
    """What the recorded parameters define: body, dynamics, mode, rates and tolerance."""

    body: TwoDiskBody
    dynamics: RollingDynamics
    mode: str
    omega0: float
    rate: float | None
    solver_tolerance: float


def build_model(parameters, problems):
    """The body, mass model and mode the recorded parameters describe, or None.

    Problems found (one line each) are appended to ``problems``.
    """
    settings, found = parse_recorded(parameters)
    problems.extend(found)
    if settings is None:
        return None
    try:
        body = TwoDiskBody(settings.a, settings.b, settings.delta)
        dynamics = RollingDynamics(body, settings.mass_properties(), settings.gravity)
    except (ValueError, TypeError, RuntimeError) as error:
        problems.append(f'the recorded parameters define no body: {error}')
        return None
    rate = settings.rate if 'rate' in parameters else None
    return RecordedModel(body, dynamics, settings.mode, settings.omega0, rate,
                         settings.tolerance)

"""The body, mass model and mode that a recording's parameters describe.

The recorded parameters are read with the node's own contract, through the run description
(:meth:`twodisk_ros.run.description.RunDescription.from_recorded`), so the inspector accepts
exactly what the node accepts and builds the body the node built: a recording without the
shape parameters (made before them) is an ellipse run, and one of shape points is rebuilt from
the fitted outline it holds, not from its shape file.
"""

from dataclasses import dataclass, field

import numpy as np

from ..physics.dynamics import RollingDynamics
from ..physics.rolling_body import RollingBody
from ..node.scene_simulation import flat_free, ground_normal
from ..run.description import RunDescription

__all__ = ['RecordedModel', 'build_model']


@dataclass
class RecordedModel:
    """What the recorded parameters define: body, dynamics, mode, rates and tolerance."""

    body: RollingBody
    dynamics: RollingDynamics
    mode: str
    omega0: float
    rate: float | None
    solver_tolerance: float
    shape: str = ''          #: one line on the shape, for the report
    #: the ground's unit normal in frame_id: (sin slope, 0, cos slope), z up on flat ground
    ground_normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    #: True if the recorded scene is not today's flat, free, conservative one
    scene: bool = False


def build_model(parameters, problems):
    """The body, mass model and mode the recorded parameters describe, or None.

    Problems found (one line each) are appended to ``problems``.
    """
    run, found = RunDescription.from_recorded(parameters)
    problems.extend(found)
    if run is None:
        return None
    settings = run.settings
    try:
        dynamics = run.dynamics
    except (ValueError, TypeError, RuntimeError) as error:
        problems.append(f'the recorded parameters define no body: {error}')
        return None
    rate = settings.rate if 'rate' in parameters else None
    return RecordedModel(run.body, dynamics, settings.mode, settings.omega0, rate,
                         settings.tolerance, run.shape_line, ground_normal(settings.slope),
                         not flat_free(settings))

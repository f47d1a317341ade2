"""The body, mass model and mode that a recording's parameters describe.

The recorded parameters are read with the node's own contract, through the run description
(:meth:`twodisk_ros.run.description.RunDescription.from_recorded`), so the inspector accepts
exactly what the node accepts and builds the body the node built: a recording without the
shape parameters (made before them) is an ellipse run, and one of shape points is rebuilt from
the fitted outline it holds, not from its shape file.

Models are cached by the recorded parameters (a few at a time): inspecting many recordings of
one body (or damaged copies of one recording) builds its dynamics tables and contact-force
tables once. A model is frozen and its tables are only read, never written, by the checks.
"""

from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np

from ..physics.motion.dynamics import RollingDynamics
from ..physics.bodies.protocol import RollingBody
from ..run.scene_simulation import flat_free, ground_normal
from ..run.description import RunDescription

__all__ = ['RecordedModel', 'build_model', 'clear_model_cache']


@dataclass(frozen=True)
class RecordedModel:
    """What the recorded parameters define: body, dynamics, mode, rates and tolerance.

    Shared between inspections of recordings with the same parameters: read only.
    """

    body: RollingBody
    dynamics: RollingDynamics
    mode: str
    omega0: float
    rate: float | None
    solver_tolerance: float
    shape: str = ''          #: one line on the shape, for the report
    #: the ground's unit normal in frame_id: (sin slope, 0, cos slope), z up on flat ground
    ground_normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    #: True if the recorded scene is not the flat, free, conservative one
    scene: bool = False

    @cached_property
    def forces(self):
        """The :class:`~twodisk_ros.physics.forces.contact.ContactForceModel` of the dynamics
        (its tables built when first read)."""
        from ..physics.forces.contact import ContactForceModel
        return ContactForceModel(self.dynamics)


def build_model(parameters, problems):
    """The body, mass model and mode the recorded parameters describe, or None.

    Problems found (one line each) are appended to ``problems``. The same parameters give
    the same (cached, frozen) model.
    """
    try:
        key = tuple(sorted(parameters.items()))
        hash(key)
    except TypeError:           # not a mapping of hashable values: build without the cache
        return _build(parameters, problems)
    model, found = _cached(key)
    problems.extend(found)
    return model


def clear_model_cache():
    """Forget the cached models."""
    _cached.cache_clear()


@lru_cache(maxsize=4)
def _cached(key):
    found = []
    return _build(dict(key), found), tuple(found)


def _build(parameters, problems):
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

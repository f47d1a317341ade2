"""The description of a run: checked settings → lamina, body, mass model, dynamics, motion.

Read by the node (:class:`~twodisk_ros.run.simulation.Simulation`, the start-up estimate),
the inspector (:func:`~twodisk_ros.inspector.model.build_model`) and the tools that rebuild a
run from its parameters, so that every reader builds the same body:

- ``shape`` ellipse: :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody` (a, b, delta), the closed
  forms, and the closed-form mass models of a, b, delta (``settings.ellipse_mass_properties()``), bit for bit;
- any other shape: :class:`~twodisk_ros.physics.bodies.lamina_body.LaminaBody` (lamina, delta,
  arrangement) on the lamina of :func:`~twodisk_ros.run.shape.lamina_of`, with the mass model
  of :func:`twodisk_ros.physics.mass.models.centred_on_mass` (imported when first needed):
  the body is moved (``LaminaBody.about``) so that its origin is the mass model's centre of
  mass, as RollingDynamics needs. Only the solid hull of an egg in the parallel arrangement
  has its centre of mass off the laminae's centroid G (2.7e-3 m for config/egg.yaml's
  shape); its run's pose, recording and drawing are those of that point P = ``body.origin``.

Bodies and mass models are cached by their lamina and parameters (a few at a time), so that
checking settings, describing the URDF and building the simulation pay for a body once.
"""

from functools import cached_property, lru_cache

from .parameters import parse_recorded
from ..physics.bodies.ellipse import EllipseBody
from ..physics.motion.dynamics import RollingDynamics
from ..physics.motion.simulate import MotionStream
from . import shape as shapes

__all__ = ['RunDescription', 'clear_caches']


@lru_cache(maxsize=4)
def _lamina_body(lamina, delta, arrangement):
    from ..physics.bodies.lamina_body import LaminaBody
    return LaminaBody(lamina, delta, arrangement)


@lru_cache(maxsize=8)
def _centred(body, model, mass, moments):
    from ..physics.mass.models import centred_on_mass
    return centred_on_mass(model, body, mass, moments)


def clear_caches():
    """Forget the cached bodies and mass models (and the laminae and their cycles' limits)."""
    _lamina_body.cache_clear()
    _centred.cache_clear()
    shapes.clear_caches()


class RunDescription:
    """What checked settings describe (attributes are built once, when first read).

    Parameters
    ----------
    settings : RollerSettings
        The run's settings (checked here; ValueError, one line, if not allowed).
    outline : Outline, optional
        For shape points: the fitted outline (a recording's), instead of reading
        ``shape_file``.

    Attributes
    ----------
    settings : RollerSettings
    lamina : Lamina
        The shape of each disk (an Ellipse for ``ellipse``).
    laminae_body : RollingBody
        The body with its origin at the laminae's centroid G: EllipseBody for ``ellipse``,
        LaminaBody otherwise (built here, so a shape that defines no body is refused here).
    body : RollingBody
        The body the run moves: ``laminae_body`` moved to the mass model's centre of mass
        (the same object unless that lies off G; built with the mass model, when first read).
    mass : MassProperties
        The mass model, centre of mass at the body's origin.
    """

    def __init__(self, settings, outline=None):
        s = self.settings = settings.checked(outline)
        self.outline = outline if s.shape == 'points' else None
        if s.shape == 'ellipse':
            self.laminae_body = EllipseBody(s.a, s.b, s.delta)
            self.lamina = self.laminae_body.lamina
        else:
            self.lamina = shapes.lamina_of(s, self.outline)
            self.laminae_body = _lamina_body(self.lamina, s.delta, s.arrangement)

    @classmethod
    def from_recorded(cls, strings):
        """(RunDescription or None, problems) of a recording's ``twodisk_ros`` metadata.

        The parameters are read with the node's contract
        (:func:`~twodisk_ros.run.parameters.parse_recorded`): a recording without the shape
        parameters is an ellipse run; one of shape points is rebuilt from the outline it
        holds, without its shape file. Problems are one line each.
        """
        settings, problems = parse_recorded(strings)
        if settings is None:
            return None, problems
        try:
            outline = (shapes.outline_from_metadata(strings) if settings.shape == 'points'
                       else None)
            return cls(settings, outline), []
        except (ValueError, TypeError, RuntimeError, ArithmeticError) as error:
            return None, [f'the recorded parameters define no body: '
                          f'{" ".join(str(error).split())}']

    @property
    def shape_line(self):
        """One line on the shape (``superellipse a = 0.1 m, ... , delta = 0.05 m, parallel``)."""
        return shapes.describe_shape(self.settings, self.lamina)

    @cached_property
    def _body_and_mass(self):
        s = self.settings
        if s.shape == 'ellipse':      # the centre of mass is G by the ellipses' symmetries
            return self.laminae_body, s.ellipse_mass_properties()
        moments = s.principal_moments if s.mass_model == 'custom' else None
        return _centred(self.laminae_body, s.mass_model, s.mass, moments)

    @property
    def body(self):
        """The run's :class:`~twodisk_ros.physics.bodies.protocol.RollingBody`, its origin at
        the centre of mass (G, or P = ``body.origin`` for the solid parallel egg)."""
        return self._body_and_mass[0]

    @property
    def mass(self):
        """The :class:`~twodisk_ros.physics.mass.models.MassProperties` of the run (centre of
        mass at the body's origin)."""
        return self._body_and_mass[1]

    @cached_property
    def dynamics(self):
        """:class:`~twodisk_ros.physics.motion.dynamics.RollingDynamics` of body, mass and gravity."""
        return RollingDynamics(self.body, self.mass, self.settings.gravity)

    def start(self):
        """The :class:`~twodisk_ros.physics.motion.dynamics.PhaseState` of theta0, branch and omega0:
        u0 (rad), the angular speed w0 = omega0 about AB (rad/s: the regular chart, well
        defined also at a flat vertex, where the body does not turn in u) and u̇0 = w0/|ω_u(u0)|
        (rad/s; infinite there)."""
        s = self.settings
        u0 = float(self.body.phase_from_theta(s.theta0, s.branch))
        return self.dynamics.initial_state(u0, s.omega0)

    def stream(self):
        """A new :class:`~twodisk_ros.physics.motion.simulate.MotionStream` of the run from t = 0
        (started from w0, as :func:`~twodisk_ros.physics.simulate` does: u̇0 is infinite where
        the body does not turn in u)."""
        s = self.settings
        start = self.start()
        return MotionStream(self.dynamics, start.phase, start.phase_rate, mode=s.mode,
                            method=s.method, tolerance=s.tolerance,
                            angular_speed=start.angular_speed)

    def metadata(self):
        """{key: text}: the recording's ``twodisk_ros`` metadata of the run.

        Every parameter (:meth:`as_strings`), and for shape points the fitted outline
        (:func:`~twodisk_ros.run.shape.outline_metadata`), so the recording is checked
        without the shape file; under ``contact_model`` hybrid the engine's contact
        parameters (:func:`~twodisk_ros.engine.model.contact_metadata`: the inspector's
        landing depth bound).
        """
        values = self.settings.as_strings()
        if self.settings.shape == 'points':
            values.update(shapes.outline_metadata(self.lamina))
        if self.settings.contact_model == 'hybrid':
            from ..engine.model import contact_metadata    # (the node's engine: defaults)
            values.update(contact_metadata())
        return values

"""What the cycle, dynamics, equilibria and contact forces need of a body: one protocol.

Two implementations:

* :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody` (two ellipses): the paper's closed forms, the
  exact and fast path, analytic in the phase u;
* :class:`~twodisk_ros.physics.bodies.lamina_body.LaminaBody` (two congruent laminae of any shape of
  :mod:`~twodisk_ros.physics.laminae.shapes`): the contact solved from the lamina, tabulated over one
  cycle and evaluated spectrally.

Frames and units as in bodies/ellipse.py: body frame G e1 e2 e3 (metres), e2 the common axis, disk 1 in
the plane x3 = 0, disk 2 in the plane x1 = 0. The **phase** u (rad) is a regular,
2π-periodic parameter of the one-parameter family of resting poses (docs/physics.md#the-
regular-phase-u): u = 0 is θ = 0 on branch +1, u = π/2 the turning point θ = +θ_max, u = π
is θ = 0 on branch −1, u = 3π/2 the turning point θ = −θ_max. What u is between these
landmarks is the implementation's choice (the eccentric anomaly of A swept sinusoidally for
ellipses); everything below is smooth in it.

**Complex-step contract.** :meth:`phase_vectors`, :meth:`phase_height` and
:meth:`phase_rates` accept complex phases u + i h (h ≤ 1e-20, the package uses
:data:`~twodisk_ros.physics.numerics.analytic.COMPLEX_STEP`) and return f(u) + i h f′(u) to rounding,
so callers take first derivatives in u by complex step (:func:`~twodisk_ros.physics.numerics.analytic.
complex_step`) whatever the body. The closed forms are analytic; a tabulated body returns its
value and its (spectral) derivative in that form (forward-mode differentiation carried by
complex numbers). Everything computed from those outputs by analytic operations (products,
cross products, norms, arctan) then carries its exact first derivative too.
"""

import abc
from dataclasses import dataclass

import numpy as np

from .contact_solver import ContactSolver
from .rulings import Drawable

__all__ = ['PhaseGeometry', 'RollingBody', 'check_rolling_body']


@dataclass(frozen=True)
class PhaseGeometry:
    """Body-frame geometry at cycle phases ``u`` (arrays broadcast with ``u``).

    Vectors have shape ``u.shape + (3,)`` and are in the body frame (metres or unit).
    """

    phase: np.ndarray           #: u (rad)
    theta: np.ndarray           #: θ (rad), contact angle on disk 1
    psi: np.ndarray             #: ψ (rad), contact angle on disk 2
    branch: np.ndarray          #: +1 / −1 (sign of cos u; +1 at the turning points)
    signed_sqrt_q: np.ndarray   #: σ√Q (m⁴)
    contact_a: np.ndarray       #: r1 = GA (m)
    contact_b: np.ndarray       #: r2 = GB (m)
    ground_normal: np.ndarray   #: n, unit, the world's up direction seen in the body frame
    tangent_a: np.ndarray       #: unit tangent of disk 1 at A (direction of increasing θ)
    height: np.ndarray          #: z_G = −r1·n (m), the potential energy per unit M g
    tilt: np.ndarray            #: φ (rad), angle between the plane of disk 1 and the ground


class RollingBody(Drawable, abc.ABC):
    """A rigid body of two congruent laminae in perpendicular planes rolling on a plane.

    Attributes (read-only)
    ----------------------
    theta_max : float
        Largest |θ| (rad), θ the polar angle of A about C1 from −e2 towards +e1.
    psi_max : float
        Largest |ψ| (rad), ψ the polar angle of B about C2 from +e2 towards −e3.
    delta : float
        Half the distance between the disk centres (m).
    size : float
        The largest distance of a disk point from G (m); relative errors are quoted to it.
    lamina : Lamina
        The shape of both disks (laminae/shapes.py), in disk 1's lamina coordinates.
    arrangement : str
        'parallel' or 'swapped' (bodies/contact_solver.py; the same body for symmetric laminae).
    feature_width : float
        Width (rad of u) of the sharpest feature of the functions of u, in (0, 1]: finite-
        difference steps and table resolutions scale with it.
    """

    # -- geometry in the phase u -------------------------------------------------------------
    @abc.abstractmethod
    def phase_geometry(self, u):
        """:class:`PhaseGeometry` at real phase(s) u (rad, any real).

        ``signed_sqrt_q`` is the ellipse's σ√Q (m⁴); NaN for bodies without one.
        """

    @abc.abstractmethod
    def phase_vectors(self, u):
        """Tuple whose first five entries are r1 = GA, r2 = GB (m), the unit ground normal n
        (up), the unit tangent t1 of disk 1 at A (θ increasing) and z_G (m), body frame,
        vectors u.shape + (3,). Complex-safe (module docstring)."""

    @abc.abstractmethod
    def phase_height(self, u):
        """z_G(u) (m): G's height above the ground. Complex-safe."""

    @abc.abstractmethod
    def phase_rates(self, u):
        """(ds/du, dα/du): the rate of A's arc length along the ground trace (m per rad of u,
        signed) and of the heading α of t1 in the world (rad per rad, ≥ 0). Complex-safe."""

    @abc.abstractmethod
    def phase_angular_velocity(self, u):
        """ω_u (rad per rad of u, body frame, u.shape + (3,)): the angular velocity per u̇."""

    def phase_angular_velocity_and_contact(self, u):
        """(ω_u, r1): :meth:`phase_angular_velocity` and ``phase_geometry(u).contact_a`` at
        real phase(s) u, what the kinetic energy needs (bodies may share the evaluations)."""
        return self.phase_angular_velocity(u), self.phase_geometry(u).contact_a

    @abc.abstractmethod
    def phase_angles_with_rates(self, u):
        """(θ, ψ, dθ/du, dψ/du) at real phase(s) u."""

    # -- the paper's (θ, branch) chart -------------------------------------------------------
    @abc.abstractmethod
    def phase_from_theta(self, theta, branch=1):
        """The phase u ∈ [−π/2, 3π/2) of contact angle θ (rad) on a branch (±1)."""

    @abc.abstractmethod
    def contact_angle_psi(self, theta, branch=1):
        """ψ(θ) (rad) on a branch."""

    #: True if the body turns in u at every phase (|ω_u| > 0 over the whole cycle), so that u
    #: is a regular chart of every motion (physics/motion/integrate.py). False unless the body
    #: knows it (a body that may stop turning is stepped in the regularised time).
    turns_everywhere = False

    def solve_equilibria(self, search, closed_forms):
        """The equilibria by the solver that applies to this body: ``search(self)``, the roots
        of dz_G/du with a certificate that none is missed (any body; stability/equilibria.py).
        A body whose equilibria sit at known phases returns ``closed_forms(self)`` instead."""
        return search(self)

    def flat_vertex_phases(self):
        """The phases u ∈ [0, 2π) (rad, sorted) where a contact sits on a flat vertex of the
        lamina (zero curvature): the body does not turn there (|ω_u| = 0) and z_G is flat to
        high order. Here from the lamina's vertices on −y and ±x whose radius of curvature is
        infinite, the phases where A sits on them (``phase_from_theta`` of θ = 0, ±π/2 on
        both branches; B's are then not known); a body that knows all of them overrides it.
        Empty for the ellipse."""
        thetas = []
        for axis, theta in (('-y', (0.0,)), ('+x', (0.5 * np.pi, -0.5 * np.pi))):
            try:
                flat = np.isinf(self.lamina.vertex(axis).radius)
            except ValueError as error:     # Lamina.vertex: flat, no order of contact given
                flat = 'flat' in str(error)
            if flat:
                thetas.extend(t for t in theta if abs(t) <= self.theta_max)
        phases = [float(self.phase_from_theta(t, branch)) for t in thetas for branch in (1, -1)]
        phases = [0.0 if abs(p) < 1e-300 else p for p in phases]   # θ = 0 gives a subnormal
        return np.unique(np.mod(np.array(phases, dtype=float), 2 * np.pi))

    # -- words -------------------------------------------------------------------------------
    @abc.abstractmethod
    def describe(self):
        """One line naming the body by its parameters (lengths in m), for titles and logs."""

    # -- the exact contact geometry (drawings) ------------------------------------------------
    @property
    def contact_solver(self):
        """The :class:`~twodisk_ros.physics.bodies.contact_solver.ContactSolver` of the
        body's lamina, Δ and arrangement: its contact geometry solved from the support
        function, whose rims every drawing of the body takes (built once)."""
        solver = self.__dict__.get('_contact_solver')
        if solver is None:
            solver = ContactSolver(self.lamina, self.delta, self.arrangement)
            self.__dict__['_contact_solver'] = solver
        return solver

    @property
    def origin(self):
        """The body-frame origin from the midpoint O of the disk centres (m, body frame)."""
        return self.contact_solver.centroid

    @property
    def offset(self):
        """The body-frame origin's offset from G along e2 (m): 0 unless the body was moved
        (:meth:`~twodisk_ros.physics.bodies.lamina_body.LaminaBody.about`)."""
        return 0.0

    def centred_on(self, center_of_mass):
        """(body, centre of mass (m) from its origin) for ``center_of_mass`` from this one's:
        here itself, G being the centre of mass by symmetry (ellipses); LaminaBody moves."""
        return self, center_of_mass

    def resolution_cause(self):
        """What sets the resolution of the body's tables, for the start-up notice of an
        extreme body (:mod:`~twodisk_ros.physics.motion.startup`): its feature width."""
        return f'{self!r}, feature width {self.feature_width:.3g} rad'


def check_rolling_body(body, what='body'):
    """``body`` if it implements :class:`RollingBody`, else TypeError naming what it got."""
    if not isinstance(body, RollingBody):
        raise TypeError(f'{what} must be a rolling body (EllipseBody or LaminaBody), got '
                        f'{type(body).__name__}')
    return body

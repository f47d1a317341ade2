"""The equation of motion of the rolling body: one degree of freedom in the cycle phase u.

With no slip at A and B the body turns about the line AB, so its motion is fixed by u(t)
(docs/physics.md#dynamics). Kinetic and potential energy (SI units):

    T = ½ m(u) u̇²,   m(u) = ω_uᵀ I_G ω_u + M |ω_u × r1|²,   V(u) = M g z_G(u),

ω_u being the angular velocity per unit u̇ (body frame, rad) and I_G the inertia about G.
Lagrange's equation: m ü + ½ m′ u̇² + V′ = 0; energy E = T + V is conserved.

:class:`RollingDynamics` holds these functions twice: as closed forms (the ``direct``
method) and as periodic tables of one cycle (the ``table`` method); the motion itself is
solved in :mod:`twodisk_ros.physics.motion.simulate`.
"""

import math
from typing import NamedTuple

import numpy as np

from ..numerics.analytic import complex_step
from ..bodies.cycle import RollingCycle, TWO_PI
from ..stability.equilibria import equilibria, NEUTRAL, STABLE
from ..mass.models import MassProperties
from ..bodies.protocol import check_rolling_body
from ..numerics.spectral import spectral_derivative
from ..numerics.tables import HermiteTable
from ..numerics.vectors import cross
from ..stability.wells import LocalWell, TabulatedWell

__all__ = ['PhaseState', 'RollingDynamics']

_FD_STEP = 1e-3   # rad: step of the 5-point difference of m(u), times the feature width


class PhaseState(NamedTuple):
    """A state of the motion in both charts (SI units).

    ``angular_speed`` w = |ω_u| u̇ (rad/s, signed as u̇: + for increasing phase) is the body's
    angular speed about the contact line AB: finite wherever the body is, also where it stops
    turning in u (|ω_u| = 0: a contact on a superellipse's flat vertex), so it is the state
    the motion starts from and continues from. ``phase_rate`` u̇ (rad/s) is derived from it:
    infinite where |ω_u| = 0 (at a flat vertex's phase |ω_u| is rounding, ~1e-13, and u̇ ~1e13
    rad/s stands for that infinity; nothing is computed from it there).
    """

    phase: float            #: u (rad)
    phase_rate: float       #: u̇ (rad/s)
    angular_speed: float    #: w = |ω_u| u̇ (rad/s)


class RollingDynamics:
    """The equation of motion of one body with one mass model.

    Parameters
    ----------
    body : RollingBody
    mass_properties : MassProperties
        Mass (kg) and inertia about G (kg m², body frame); the centre of mass must be G.
    gravity : float
        g (m/s²), finite and ≥ 0.
    cycle : RollingCycle, optional
        Reused if given (it holds the kinematic tables).
    """

    def __init__(self, body, mass_properties, gravity=9.81, cycle=None):
        check_rolling_body(body)
        if not isinstance(mass_properties, MassProperties):
            raise TypeError('mass_properties must be a MassProperties')
        gravity = float(gravity)
        if not (math.isfinite(gravity) and gravity >= 0):
            raise ValueError(f'gravity must be finite and >= 0 m/s^2, got {gravity!r}')
        if np.max(np.abs(mass_properties.center_of_mass)) > 1e-9 * body.size:
            raise ValueError('mass_properties.center_of_mass must be G (the origin)')
        self.body = body
        self.mass = mass_properties
        self.gravity = gravity
        self.cycle = cycle if cycle is not None else RollingCycle(body)
        self._feature_width = body.feature_width
        self._build_tables(4 * self.cycle.resolution)
        self._equilibria = None
        self._local_wells = {}
        self._inertia_table = None

    # -- closed forms (the direct method) ---------------------------------------------------
    def effective_mass(self, u):
        """m(u) (kg m²/rad²): T = ½ m(u) u̇²."""
        u = np.asarray(u, dtype=float)
        omega, r1 = self.body.phase_angular_velocity_and_contact(u)
        v = cross(omega, r1)
        inertia = self.mass.inertia
        return (np.einsum('...i,ij,...j->...', omega, inertia, omega)
                + self.mass.mass * np.sum(v * v, axis=-1))

    def contact_line_inertia(self, u):
        """J(u) = êᵀ I_G ê + M |ê × r1|² (kg m²): the moment of inertia about the contact
        line AB (ê its unit direction), so that T = ½ J γ̇², γ̇ = |ω_u| u̇ the body's angular
        speed. m = J |ω_u|²; unlike m, J stays positive where the body does not turn in u."""
        geo = self.body.phase_geometry(np.asarray(u, dtype=float))
        d = geo.contact_b - geo.contact_a
        e = d / np.linalg.norm(d, axis=-1)[..., None]
        v = cross(e, geo.contact_a)
        return (np.einsum('...i,ij,...j->...', e, self.mass.inertia, e)
                + self.mass.mass * np.sum(v * v, axis=-1))

    def angular_speed_per_phase(self, u):
        """|ω_u| (rad of body rotation per rad of u)."""
        return np.linalg.norm(self.body.phase_angular_velocity(u), axis=-1)

    def potential(self, u):
        """V(u) = M g z_G(u) (J)."""
        return self.mass.mass * self.gravity * self.body.phase_height(u)

    def potential_slope(self, u):
        """dV/du (J/rad), by complex step of the closed form."""
        return self.mass.mass * self.gravity * complex_step(self.body.phase_height, u)

    def effective_mass_slope(self, u):
        """dm/du (kg m²/rad³): 5-point difference of :meth:`effective_mass`.

        The step is 1e-3 rad times the width of the sharpest feature of the body's functions
        of u, min(1, b/a, a/b, 2√(Δ/a)) (body module docstring).
        """
        return self.effective_mass_jet(u)[1]

    def effective_mass_jet(self, u):
        """(m, dm/du) at u: :meth:`effective_mass` and its 5-point slope, in one evaluation."""
        u = np.asarray(u, dtype=float)
        h = _FD_STEP * self._feature_width
        m = self.effective_mass(u[..., None] + h * np.arange(-2.0, 3.0))
        m = np.moveaxis(m, -1, 0)
        return m[2], (m[0] - 8 * m[1] + 8 * m[3] - m[4]) / (12 * h)

    # -- tables (the table method) ----------------------------------------------------------
    def _build_tables(self, n):
        u = TWO_PI * np.arange(n) / n
        m = self.effective_mass(u)
        w = self.angular_speed_per_phase(u)
        v = self.potential(u)
        dv = self.potential_slope(u)
        first = np.column_stack([spectral_derivative(m), dv, spectral_derivative(w)])
        second = spectral_derivative(first)
        self._table = HermiteTable.periodic(np.column_stack([m, v, w]), first, second)
        # m alone, for the energy with V's (the same columns, so the same bits: one column at
        # a time costs a third of three columns broadcast together)
        self._mass_table = HermiteTable.periodic(m, first[:, 0], second[:, 0])
        # V alone, for the level searches of oscillations (a third of the work)
        self._potential = HermiteTable.periodic(v, dv, second[:, 1])
        self.table_size = n
        self.potential_range = (float(v.min()), float(v.max()))
        #: max |ω_u| over the table's nodes (rad per rad of u)
        self.peak_turn_rate = float(w.max())

    def tabulated_inertia(self, u, derivative=0):
        """J(u) (kg m², :meth:`contact_line_inertia`) or J′(u) from a periodic table (built on
        first use, on the grid of the other tables)."""
        if self._inertia_table is None:
            n = self.table_size
            j = self.contact_line_inertia(TWO_PI * np.arange(n) / n)
            first = spectral_derivative(j)
            self._inertia_table = HermiteTable.periodic(j, first, spectral_derivative(first))
        return self._inertia_table(np.mod(np.asarray(u, dtype=float), TWO_PI), derivative)

    def contact_line_inertia_jet(self, u):
        """(J, dJ/du) at u: :meth:`contact_line_inertia` and its 5-point slope (the step of
        :meth:`effective_mass_jet`)."""
        u = np.asarray(u, dtype=float)
        h = _FD_STEP * self._feature_width
        j = np.moveaxis(self.contact_line_inertia(u[..., None] + h * np.arange(-2.0, 3.0)),
                        -1, 0)
        return j[2], (j[0] - 8 * j[1] + 8 * j[3] - j[4]) / (12 * h)

    def regular_centre(self, u_star):
        """False if the body does not turn in u at the equilibrium u* (|ω_u| = 0) or z_G is
        not quadratic there: no libration model in u (the ODE in τ is used instead)."""
        for eq, _ in self.equilibria_with_periods():
            if abs(math.remainder(u_star - eq.phase, TWO_PI)) < 1e-9:
                return eq.order == 2.0 and eq.phase_curvature != 0.0
        return True

    def tabulated(self, u, derivative=0):
        """(m, V, |ω_u|) at phase(s) u from the tables, shape u.shape + (3,)."""
        u = np.asarray(u, dtype=float)
        return self._table(np.mod(u, TWO_PI), derivative)

    def tabulated_potential(self, u, derivative=0):
        """V(u) (J) or V′(u) (J/rad) from the tables."""
        return self._potential(np.mod(np.asarray(u, dtype=float), TWO_PI), derivative)

    # -- derived quantities -----------------------------------------------------------------
    def energy(self, u, u_dot):
        """E = ½ m(u) u̇² + V(u) (J), from the tables."""
        rest = np.mod(np.asarray(u, dtype=float), TWO_PI)
        return 0.5 * self._mass_table(rest) * np.asarray(u_dot) ** 2 + self._potential(rest)

    @property
    def energy_scale(self):
        """M g L (J), L = body size: the scale of relative energy drifts (g → 1 m/s² if g = 0)."""
        g = self.gravity if self.gravity > 0 else 1.0
        return self.mass.mass * g * self.body.size

    def equilibria_with_periods(self):
        """[(Equilibrium, small-oscillation period in s or None)] for all the equilibria.

        T = 2π √(J(u*) / (M g d²z_G/dγ²)) at the stable ones, in the body's turn γ about AB
        (:meth:`contact_line_inertia`): the same as 2π √(m(u*) / V″(u*)) in u where the body
        turns in u (m = J |ω_u|², V″ = M g |ω_u|² d²z_G/dγ²), and it holds also where it does not
        (m = V″ = 0 there). None where z_G − z* ~ |γ|^q with q < 2 (a flat vertex): the
        period then depends on the amplitude (docs/physics.md#equilibria-of-any-body).
        Computed once per dynamics object.
        """
        if self._equilibria is None:
            result = []
            for eq in equilibria(self.body):
                period = None
                stiffness = self.mass.mass * self.gravity * eq.gamma_curvature
                if eq.has_linear_period and stiffness > 0:
                    period = TWO_PI * math.sqrt(
                        float(self.contact_line_inertia(eq.phase)) / stiffness)
                result.append((eq, period))
            self._equilibria = result
        return list(self._equilibria)

    def small_oscillation_periods(self):
        """[(Equilibrium, period in s)] for every stable equilibrium (T = 2π √(m / V″))."""
        return [(eq, period) for eq, period in self.equilibria_with_periods()
                if period is not None]

    def well(self, u):
        """(u*, u_low, u_high): the minimum of V in the well holding phase u, between maxima."""
        found = sorted((eq.phase, eq.stability) for eq, _ in self.equilibria_with_periods())
        maxima = np.array([p for p, kind in found if kind != STABLE])
        minima = np.array([p for p, kind in found if kind == STABLE])
        if len(maxima) == 0 or len(minima) == 0:
            raise RuntimeError('V has no wells (neutral body): no oscillation')
        base = TWO_PI * math.floor(u / TWO_PI)
        edges = np.concatenate([maxima - TWO_PI, maxima, maxima + TWO_PI]) + base
        i = np.searchsorted(edges, u, side='right')
        low, high = edges[i - 1], edges[i]
        centres = np.concatenate([minima - TWO_PI, minima, minima + TWO_PI]) + base
        inside = centres[(centres > low) & (centres < high)]
        return float(inside[0]), float(low), float(high)

    def well_rim(self, u):
        """V (J) at the lower of the two maxima bounding the well holding phase u.

        Below it a motion oscillates in that well (about its minimum); from it up to
        :attr:`barrier` it crosses the lower maximum and swings over several wells between
        two turning points (unequal maxima: a parallel egg, V(0) ≠ V(π/2)); above the barrier
        it rolls over. For the ellipse both maxima are at the same height.
        """
        _, low, high = self.well(u)
        return float(np.min(self.tabulated_potential(np.array([low, high]))))

    @property
    def has_wells(self):
        """True if V has wells: g > 0 and some equilibrium is stable."""
        return self.gravity > 0 and any(eq.stability == STABLE
                                        for eq, _ in self.equilibria_with_periods())

    @property
    def flat(self):
        """True if V is constant: g = 0, or z_G constant (every equilibrium neutral)."""
        return self.gravity == 0 or all(eq.stability == NEUTRAL
                                        for eq, _ in self.equilibria_with_periods())

    @property
    def barrier(self):
        """max V (J): V at the highest maximum among the equilibria (the separatrix energy).

        The maximum over the table nodes (``potential_range``) falls short of it by up to
        ½ V″ h² (h the node spacing: ~2e-6 M g L for b/a = 2).
        """
        tops = [eq.phase for eq, _ in self.equilibria_with_periods() if eq.stability != STABLE]
        top = float(np.max(self.tabulated_potential(np.array(tops)))) if tops else -math.inf
        return max(top, self.potential_range[1])

    def local_well(self, u_star):
        """The :class:`~twodisk_ros.physics.stability.wells.LocalWell` about the stable equilibrium u*.

        Built once per equilibrium from the closed forms (both methods use it for small
        amplitudes).
        """
        key = round(float(u_star), 12)
        if key not in self._local_wells:
            self._local_wells[key] = LocalWell(self, u_star)
        return self._local_wells[key]

    def tabulated_well(self, u_star):
        """The :class:`~twodisk_ros.physics.stability.wells.TabulatedWell` about u* (the tables)."""
        return TabulatedWell(self, u_star, self.potential_curvature(u_star))

    def potential_curvature(self, u):
        """d²V/du² (J/rad²) at an equilibrium phase u (spectral, as in the equilibria)."""
        for eq, _ in self.equilibria_with_periods():
            gap = abs(math.remainder(u - eq.phase, TWO_PI))
            if gap < 1e-9:
                return self.mass.mass * self.gravity * eq.phase_curvature
        raise ValueError(f'u = {u!r} rad is not an equilibrium phase')

    def is_equilibrium(self, u):
        """True if phase u (rad) is one of the equilibria (within 1e-9 rad), or V′(u) vanishes
        there to rounding (z_G constant: the neutral case)."""
        phases = np.array([eq.phase for eq, _ in self.equilibria_with_periods()])
        gap = np.abs(np.remainder(u - phases + math.pi, TWO_PI) - math.pi)
        if np.min(gap) <= 1e-9:
            return True
        return abs(float(self.potential_slope(u))) <= 1e-13 * self.energy_scale

    def initial_phase_rate(self, u0, omega0):
        """u̇₀ (rad/s) giving the body the signed angular speed ``omega0`` (rad/s) at u0
        (±inf where the body does not turn in u: :meth:`initial_state` is the regular form)."""
        with np.errstate(divide='ignore', invalid='ignore'):
            return float(np.float64(omega0) / np.float64(self.angular_speed_per_phase(u0)))

    def initial_state(self, u0, omega0):
        """The :class:`PhaseState` at phase u0 (rad) with the signed angular speed ``omega0``
        (rad/s): w0 = omega0, u̇0 = :meth:`initial_phase_rate`."""
        return PhaseState(float(u0), self.initial_phase_rate(u0, omega0), float(omega0))

    def energy_turning(self, u, angular_speed):
        """E = ½ J(u) w² + V(u) (J) from the tables, w = |ω_u| u̇ (rad/s): the energy in the
        regular chart (J = m/|ω_u|², :meth:`tabulated_inertia`), finite also where the body
        stops turning in u; equal to :meth:`energy` elsewhere (to the tables' rounding)."""
        return (0.5 * self.tabulated_inertia(u) * np.square(angular_speed)
                + self.tabulated_potential(u))

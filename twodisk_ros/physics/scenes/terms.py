"""The functions of the phase u a scene's equation of motion needs: potential on a slope,
contact forces with tilted gravity, poses in the gravity frame (docs/physics.md#scenes).

Frames as in :mod:`~twodisk_ros.physics.scenes.scene`. Rolling stays exact on a tilted plane, so
the body's configuration in the slope frame is the cycle's (z along the ground normal),
turned by φ0 about the normal; what changes is gravity, g_S = g (sin β, 0, −cos β):

* V(u) = M g (h(u) cos β − s(u) sin β) (J), h = z_G above the ground, s G's downhill
  coordinate, s(u) = Re(e^{iφ0} Z_G(u)), Z_G = X_G + i Y_G in the cycle frame. Its slope
  V′ = M g (h′ cos β − Re(e^{i(λu + φ0)} p(u)) sin β), with dG/du = e^{iλu} p(u) in the
  cycle frame, λ = turn/2π, p(u) = e^{iα_p(u)} (c·t1 + i c·m) periodic (c = dG/du in the body
  frame, α = λu + α_p the heading of t1);
* the ground must supply F_A + F_B = M a_G − M g. In the body frame −M g = M g cos β n −
  M g sin β d̂, d̂ = cos ϑ t1 − sin ϑ m the downhill direction, ϑ = α + φ0. Every contact
  quantity (N_A, N_B, T_A, T_B, S, τ) is linear in (cos β, sin β cos ϑ, sin β sin ϑ, u̇², ü)
  with coefficients of u alone: Q = M g [cos β C_n − sin β Re(e^{i(λu + φ0)} K)] + u̇² C_2 +
  ü C_ü, K = e^{iα_p} (C_t + i C_m), C_v the quantities for a unit required force v at G
  (moments about A as in :mod:`~twodisk_ros.physics.forces.contact`, whose public
  ``'general'`` coefficients give C_2 and C_ü).

All periodic parts are tabulated once per cycle in one quintic Hermite table (spectral
derivatives), like the dynamics' tables; the non-periodic parts are the phase factors.
"""

from copy import copy
from dataclasses import dataclass, replace
import math

import numpy as np

from ..forces.contact import ContactForceModel, squeeze_split
from ..forces.terms import ForceTerms
from ..bodies.cycle import TWO_PI
from .scene import Scene, quaternion_product
from ..numerics.spectral import spectral_derivative
from ..numerics.tables import HermiteTable

__all__ = ['SceneTerms', 'SceneForces', 'SceneEquilibrium', 'STOPPED']

#: |ω_u| below this fraction of its largest value is a stop (the body does not turn in u)
STOPPED = 1e-9
#: a cycle's turn within this fraction of 2π is 2π (V periodic plus a drift per cycle)
TURN_FLOOR = 1e-9

# columns of the table
# m, m′, |ω_u|, |ω_u|′, h, h′, p (Re, Im), k = |dG/du|
M, DM, W, DW, H, DH, P, K_G = 0, 1, 2, 3, 4, 5, 6, 8
CN, KRE, KIM, C2, CU, EDGE = 9, 15, 21, 27, 33, 39
# per unit turn γ (regular where the body stops turning in u): ρ = |dG/dγ| (the distance of
# G from AB), c·n and e^{iα_p}(c·t1 + i c·m) (c = dG/dγ), the quantities per ẇ and per w²
# (forces.terms' Q_a and P) and J, J′
RHO, CGN, CGP, QA, PW, J, DJ = 41, 42, 43, 45, 51, 57, 58
WIDTH = 59


@dataclass
class SceneForces:
    """Ground forces at A and B over states (gravity frame W, N; arrays over the states)."""

    force_a: np.ndarray         #: F_A (N), (..., 3)
    force_b: np.ndarray         #: F_B (N), (..., 3)
    direction_ab: np.ndarray    #: ê, unit from A to B, (..., 3)
    normal_a: np.ndarray        #: N_A (N), along the ground normal
    normal_b: np.ndarray        #: N_B (N)
    tangential_a: np.ndarray    #: T_A (N), along the ground normal × ê
    tangential_b: np.ndarray    #: T_B (N)
    along_ab: np.ndarray        #: S (N), the total along ê
    mu_required: np.ndarray     #: least friction coefficient for rolling (inf on lift-off)
    torque: np.ndarray          #: τ (N m): the external moment τ ê this ü needs
    weight: float               #: M g (N)

    @property
    def lift_off(self):
        """True where a contact would need the ground to pull."""
        return (self.normal_a < 0) | (self.normal_b < 0)


@dataclass(frozen=True)
class SceneEquilibrium:
    """A rest pose on the slope (V′ = 0) and what holds it."""

    phase: float            #: u* (rad) in [0, 2π)
    stable: bool            #: (dV/dγ)′(u*) > 0 (V″ > 0 where the body turns in u)
    period: float           #: small-oscillation period 2π √(m/V″) (s); nan if unstable
    normal_a: float         #: N_A at rest (N)
    normal_b: float         #: N_B at rest (N)
    mu_required: float      #: least friction coefficient that holds it


class SceneTerms:
    """The scene's functions of u for one dynamics (body, mass, gravity) and one scene.

    Parameters
    ----------
    dynamics : RollingDynamics
    scene : Scene
        Its gravity must equal ``dynamics.gravity``.
    model : ContactForceModel, optional
        Reused if given (its ``'general'`` coefficients give the inertial force terms).
    """

    def __init__(self, dynamics, scene, model=None):
        if not isinstance(scene, Scene):
            raise TypeError(f'scene must be a Scene, got {type(scene).__name__}')
        if scene.gravity != dynamics.gravity:
            raise ValueError(f'scene gravity {scene.gravity!r} m/s^2 differs from the '
                             f'dynamics gravity {dynamics.gravity!r} m/s^2')
        self.dynamics, self.scene, self.cycle = dynamics, scene, dynamics.cycle
        self.model = model if model is not None else ContactForceModel(dynamics)
        self.mass = dynamics.mass.mass
        self.weight = self.mass * scene.gravity
        self.cos_b, self.sin_b = math.cos(scene.slope), math.sin(scene.slope)
        self.turn_rate = self.cycle.displacement.turn / TWO_PI        # λ
        self.phi0 = scene.cycle_rotation(self.cycle.displacement.shift)
        self._build(self.model.nodes)

    def _build(self, n):
        self.table_nodes = n            #: nodes of the tables over one cycle
        body = self.dynamics.body
        u = TWO_PI * np.arange(n) / n
        r1, r2, normal, t1 = (np.real(x) for x in body.phase_vectors(u)[:4])
        m_axis = np.cross(normal, t1)
        w = body.phase_angular_velocity(u)
        c = -np.cross(w, r1)                                     # dG/du, body frame
        d = r2 - r1
        length2 = np.sum(d * d, -1)
        e = d / np.sqrt(length2)[:, None]
        p_axis = np.cross(normal, e)

        def unit_force(v):                    # the 6 quantities for a required force v at G
            moment_a = -np.cross(r1, v)
            f_b = np.cross(moment_a, d) / length2[:, None]
            dot = lambda x, y: np.sum(x * y, -1)
            return np.stack([dot(v, normal) - dot(f_b, normal), dot(f_b, normal),
                             dot(v, p_axis) - dot(f_b, p_axis), dot(f_b, p_axis), dot(v, e),
                             dot(moment_a, e)], axis=-1)
        alpha_p = self.cycle.heading(u) - self.turn_rate * u
        rot = np.exp(1j * alpha_p)[:, None]
        general = self.model.coefficients(u, 'general')
        turn = self.model.terms if self.model.terms.regular else ForceTerms(
            body, self.dynamics.mass.inertia, self.mass, self.dynamics.gravity, n,
            phase_only=True)
        axis = turn.sense * e                                   # ω̂
        c_turn = -np.cross(axis, r1)                            # dG/dγ, body frame
        inertia_line = turn.inertia_line
        p_turn = rot[:, 0] * (np.sum(c_turn * t1, -1) + 1j * np.sum(c_turn * m_axis, -1))
        m_u = self.dynamics.effective_mass(u)
        speed = np.linalg.norm(w, axis=-1)
        height = np.real(body.phase_height(u))
        p = rot[:, 0] * (np.sum(c * t1, -1) + 1j * np.sum(c * m_axis, -1))
        k = rot * (unit_force(t1) + 1j * unit_force(m_axis))
        edge = rot[:, 0] * (np.sum(e * t1, -1) + 1j * np.sum(e * m_axis, -1))
        columns = np.column_stack([
            m_u, spectral_derivative(m_u), speed, spectral_derivative(speed), height,
            spectral_derivative(height), p.real, p.imag, np.linalg.norm(c, axis=-1),
            unit_force(normal),
            k.real, k.imag, general[:, 6:12], general[:, 12:18], edge.real, edge.imag,
            np.linalg.norm(c_turn, axis=-1), np.sum(c_turn * normal, -1), p_turn.real,
            p_turn.imag, turn.q_a, turn.p, inertia_line, spectral_derivative(inertia_line)])
        first = spectral_derivative(columns)
        self._table = HermiteTable.periodic(columns, first, spectral_derivative(first))
        self.turn_scale = float(np.max(speed))      #: max |ω_u| over the cycle
        self._equilibria = None
        self._energy_columns = (u, m_u, height, speed, inertia_line)
        self._build_energy(*self._energy_columns)
        # a cycle that turns by T ≠ 2π (an egg: the path curves) has no drift: G circles the
        # fixed point C = shift/(1 − e^{iT}) of the cycle's map, Z_G = C + e^{iλu} q(u) with q
        # periodic; V is then bounded, not periodic plus linear, and is evaluated from q
        turn = self.cycle.displacement.turn
        self.periodic_potential = abs(turn - TWO_PI) <= TURN_FLOOR * TWO_PI
        self._orbit = None
        if not self.periodic_potential:
            g = self.cycle.positions(u)[0]
            self._centre = complex(self.cycle.displacement.shift) / (1 - np.exp(1j * turn))
            q = np.exp(-1j * self.turn_rate * u) * (g[:, 0] + 1j * g[:, 1] - self._centre)
            q = np.column_stack([q.real, q.imag])
            first = spectral_derivative(q)
            self._orbit = HermiteTable.periodic(q, first, spectral_derivative(first))

    def _build_energy(self, u, m_u, height, speed, inertia_line):
        """The narrow table of :meth:`energy_jet` at the nodes u: the only part of the tables
        that depends on φ0 (through V's downhill coordinate)."""
        # V = V_p(u) + drift u/2π: the periodic part tabulated once from G's composed
        # positions, the drift of one cycle composed (exact for a turn of 2π per cycle)
        v = self.weight * (self.cos_b * height - self.sin_b * self.downhill(u))
        self.drift = float(self.weight * (self.cos_b * height[0] - self.sin_b * self.downhill(
            TWO_PI)) - v[0])
        jet = np.column_stack([m_u, v - self.drift * u / TWO_PI])
        slope = spectral_derivative(jet)
        jet = np.column_stack([jet, slope, speed, spectral_derivative(slope), inertia_line,
                               spectral_derivative(inertia_line), spectral_derivative(speed)])
        first = spectral_derivative(jet)
        self._energy_table = HermiteTable.periodic(jet, first, spectral_derivative(first))

    def turned(self, phi0):
        """These terms with the cycle frame turned by φ0 (rad) about the normal in the slope
        frame (a rolling stretch placed at another heading, run/hybrid.py): the wide table is
        shared (its columns are in the cycle frame), V's table is rebuilt (ms, not the
        build's 0.1 s); the scene's heading0 is the one giving φ0."""
        return copy(self)._turn(float(phi0))

    def _turn(self, phi0):
        """Turn this copy (:meth:`turned`) to φ0 (rad); returns it."""
        shift = complex(self.cycle.displacement.shift)
        travel = math.atan2(shift.imag, shift.real) if shift != 0 else 0.0
        self.scene = replace(self.scene, heading0=phi0 + travel)
        self.phi0, self._equilibria = phi0, None
        self._build_energy(*self._energy_columns)
        return self

    # -- the table ----------------------------------------------------------------------------
    def rows(self, u):
        """The tabulated columns at phase(s) u (rad), shape u.shape + (41,)."""
        return self._table(np.mod(np.asarray(u, dtype=float), TWO_PI))

    def phase_factor(self, u):
        """e^{i(λu + φ0)}: turns the periodic parts to the slope frame."""
        return np.exp(1j * (self.turn_rate * np.asarray(u, dtype=float) + self.phi0))

    # -- potential and energy ---------------------------------------------------------------
    def downhill(self, u):
        """s(u) (m): G's downhill coordinate in the slope frame (origin: A at u = 0)."""
        g = self.cycle.positions(u)[0]
        return np.real(np.exp(1j * self.phi0) * (g[..., 0] + 1j * g[..., 1]))

    def potential_exact(self, u):
        """V(u) = M g (h cos β − s sin β) (J) from G's composed positions (slow: ~10 µs)."""
        u = np.asarray(u, dtype=float)
        h = self.rows(u)[..., H]
        return self.weight * (self.cos_b * h - self.sin_b * self.downhill(u))

    def energy_jet(self, u, derivative=0):
        """(m, V, m′, V′, |ω_u|, m″, V″, J, J′, |ω_u|′) at u (``derivative=0``) or their
        derivatives in u (``1``), array u.shape + (10,), from one table of m, of V's periodic
        part (V = V_p + drift u/2π), of |ω_u| and of J = m/|ω_u|² (kg m², the moment of
        inertia about AB, positive also where the body stops turning in u): the narrow table
        the closed forms and the samples read. If the cycle turns by T ≠ 2π
        (``periodic_potential`` False) V and V′ are exact (G's orbit about the cycle map's
        fixed point) but V″ and the derivatives (``1``) are not: the closed forms, which
        need them, are not used then."""
        u = np.asarray(u, dtype=float)
        table = self._energy_table
        jet = table.combine(*table.weights(np.mod(u, TWO_PI), derivative))
        if derivative == 0:
            jet[..., 1] += self.drift * u / TWO_PI
        jet[..., 3 - 2 * derivative] += self.drift / TWO_PI
        if self._orbit is not None and derivative == 0:
            q = self._orbit(np.mod(u, TWO_PI))
            z = self._centre + np.exp(1j * self.turn_rate * u) * (q[..., 0] + 1j * q[..., 1])
            downhill = np.real(np.exp(1j * self.phi0) * z)
            jet[..., 1] = self.weight * (self.cos_b * self.rows(u)[..., H]
                                         - self.sin_b * downhill)
            jet[..., 3] = self.potential_slope(u)
        return jet

    def potential(self, u):
        """V(u) = M g (h cos β − s sin β) (J): G's height along gravity times M g (tables;
        :meth:`potential_exact` from the positions)."""
        return self.energy_jet(u)[..., 1]

    def potential_slope_from(self, u, row):
        """V′(u) (J/rad) from a table row at u."""
        p = row[..., P] + 1j * row[..., P + 1]
        return self.weight * (self.cos_b * row[..., DH]
                              - self.sin_b * np.real(self.phase_factor(u) * p))

    def potential_slope(self, u):
        """V′(u) (J/rad)."""
        return self.potential_slope_from(u, self.rows(u))

    def energy(self, u, u_dot):
        """E = ½ m(u) u̇² + V(u) (J)."""
        u = np.asarray(u, dtype=float)
        return 0.5 * self.rows(u)[..., M] * np.square(u_dot) + self.potential(u)

    def energy_turning(self, u, w):
        """E = ½ J(u) w² + V(u) (J), w = |ω_u| u̇ the angular speed about AB (rad/s): finite
        also where the body stops turning in u."""
        jet = self.energy_jet(np.asarray(u, dtype=float))
        return 0.5 * jet[..., 7] * np.square(w) + jet[..., 1]

    def potential_turn_slope_from(self, u, row):
        """dV/dγ (J/rad) from a table row at u: V′ = |ω_u| dV/dγ, regular where |ω_u| = 0."""
        p = row[..., CGP] + 1j * row[..., CGP + 1]
        return self.weight * (self.cos_b * row[..., CGN]
                              - self.sin_b * np.real(self.phase_factor(u) * p))

    def potential_turn_slope(self, u):
        """dV/dγ (J/rad) at phase(s) u: its roots are the rest poses."""
        return self.potential_turn_slope_from(u, self.rows(u))

    # -- contact forces -----------------------------------------------------------------------
    def quantities_from(self, u, row, u_dot, u_ddot):
        """(N_A, N_B, T_A, T_B, S, τ) at states, array (..., 6), from table rows."""
        k = row[..., KRE:KRE + 6] + 1j * row[..., KIM:KIM + 6]
        gravity = self.weight * (self.cos_b * row[..., CN:CN + 6] - self.sin_b * np.real(
            self.phase_factor(u)[..., None] * k))
        u_dot, u_ddot = (np.asarray(x, dtype=float)[..., None] for x in (u_dot, u_ddot))
        return gravity + u_dot**2 * row[..., C2:C2 + 6] + u_ddot * row[..., CU:CU + 6]

    def quantities_turning_from(self, u, row, w, w_dot):
        """(N_A, N_B, T_A, T_B, S, τ) from the angular speed w and acceleration ẇ about AB
        (rad/s, rad/s²): Q_g + ẇ Q_a + w² P/|ω_u| (±inf where the body stops turning in u
        and w ≠ 0: the force of a flat vertex, unbounded for an instant)."""
        k = row[..., KRE:KRE + 6] + 1j * row[..., KIM:KIM + 6]
        gravity = self.weight * (self.cos_b * row[..., CN:CN + 6] - self.sin_b * np.real(
            self.phase_factor(u)[..., None] * k))
        w, w_dot = (np.asarray(x, dtype=float)[..., None] for x in (w, w_dot))
        s = row[..., W, None]
        stopped = s <= STOPPED * self.turn_scale
        square = w * w * row[..., PW:PW + 6]
        with np.errstate(divide='ignore', invalid='ignore'):
            inertial = np.where(stopped, np.where(square == 0, 0.0, np.copysign(
                np.inf, square)), square / np.where(stopped, 1.0, s))
        return gravity + w_dot * row[..., QA:QA + 6] + inertial

    def forces(self, u, u_dot, u_ddot, *, turning=False):
        """:class:`SceneForces` at states (u (rad), u̇ (rad/s), ü (rad/s²)), broadcast; with
        ``turning=True`` the second and third arguments are w and ẇ (rad/s, rad/s²), the
        angular speed and acceleration about AB (finite where the body stops turning in u)."""
        u, u_dot, u_ddot = np.broadcast_arrays(*(np.asarray(x, dtype=float)
                                                 for x in (u, u_dot, u_ddot)))
        row = self.rows(u)
        q = (self.quantities_turning_from if turning else self.quantities_from)(
            u, row, u_dot, u_ddot)
        along_a, _, _, mu = squeeze_split(*np.moveaxis(q[..., :5], -1, 0))
        edge = self.phase_factor(u) * (row[..., EDGE] + 1j * row[..., EDGE + 1])
        edge = edge / np.abs(edge)
        e = np.stack([edge.real, edge.imag, np.zeros(edge.shape)], axis=-1)
        p = np.stack([-edge.imag, edge.real, np.zeros(edge.shape)], axis=-1)
        z = np.zeros(e.shape)
        z[..., 2] = 1.0
        rotate = self.scene.slope_to_gravity
        force_a = (along_a[..., None] * e + q[..., 2, None] * p + q[..., 0, None] * z)
        force_b = ((q[..., 4] - along_a)[..., None] * e + q[..., 3, None] * p
                   + q[..., 1, None] * z)
        return SceneForces(force_a=force_a @ rotate.T, force_b=force_b @ rotate.T,
                           direction_ab=e @ rotate.T, normal_a=q[..., 0], normal_b=q[..., 1],
                           tangential_a=q[..., 2], tangential_b=q[..., 3], along_ab=q[..., 4],
                           mu_required=mu, torque=q[..., 5], weight=self.weight)

    # -- poses in the gravity frame -----------------------------------------------------------
    def poses(self, u):
        """(G, A, B, q) at phase(s) u: positions (m, gravity frame W) and the orientation
        body → W as quaternions (x, y, z, w), continuous in u (the cycle's, turned)."""
        poses = self.cycle.poses(u)
        turn = np.array([0.0, 0.0, math.sin(0.5 * self.phi0), math.cos(0.5 * self.phi0)])
        q_sw = quaternion_product(self.scene.slope_to_gravity_quaternion, turn)
        rotate = self.scene.slope_to_gravity @ np.array(
            [[math.cos(self.phi0), -math.sin(self.phi0), 0.0],
             [math.sin(self.phi0), math.cos(self.phi0), 0.0], [0.0, 0.0, 1.0]])
        g, a, b = (x @ rotate.T for x in (poses.position_g, poses.contact_a, poses.contact_b))
        return g, a, b, quaternion_product(q_sw, poses.quaternion)

    # -- rest on the slope --------------------------------------------------------------------
    def equilibria(self):
        """The rest poses of one cycle with no drive: V′(u*) = 0 (list of SceneEquilibrium).

        Roots bracketed on the table nodes and refined by Brent's method. V′ is periodic
        (λ = 1 to ~1e-11: the heading turns once per cycle); a slope steeper than the
        tipping limit has none. Computed once (a copy of the list is returned).
        """
        if self._equilibria is None:
            self._equilibria = self._find_equilibria()
        return list(self._equilibria)

    def _find_equilibria(self):
        # roots of dV/dγ, not of V′ = |ω_u| dV/dγ: where the body stops turning in u V′ = 0
        # but, on a slope, the body is not at rest there
        from scipy.optimize import brentq
        n = self._table.last_index + 1
        u = TWO_PI * np.arange(n + 1) / n
        slope = self.potential_turn_slope(u)
        found = []
        for i in np.flatnonzero(np.sign(slope[:-1]) * np.sign(slope[1:]) <= 0):
            if slope[i] == 0 and i > 0 and slope[i - 1] == 0:
                continue
            root = u[i] if slope[i] == 0 else brentq(
                lambda x: float(self.potential_turn_slope(x)), u[i], u[i + 1], xtol=1e-15)
            found.append(self._rest(float(root) % TWO_PI))
        unique = []
        for eq in sorted(found, key=lambda e: e.phase):
            if not unique or abs(eq.phase - unique[-1].phase) > 1e-9:
                unique.append(eq)
        if len(unique) > 1 and abs(unique[0].phase + TWO_PI - unique[-1].phase) <= 1e-9:
            unique.pop()
        return unique

    def _rest(self, u):
        # stable where dV/dγ increases through its root (|ω_u| ≥ 0); the period
        # 2π √(m/V″) = 2π √(J |ω_u| / (dV/dγ)′), nan where the body stops turning in u
        h = 1e-4 * min(1.0, TWO_PI / (self._table.last_index + 1) * 8)
        rise = float(self.potential_turn_slope(u + h) - self.potential_turn_slope(u - h)) / (
            2 * h)
        row = self.rows(u)
        period = TWO_PI * math.sqrt(float(row[J]) * float(row[W]) / rise) \
            if rise > 0 and float(row[W]) > STOPPED * self.turn_scale else math.nan
        f = self.forces(u, 0.0, 0.0)
        return SceneEquilibrium(phase=u, stable=rise > 0, period=period,
                                normal_a=float(f.normal_a), normal_b=float(f.normal_b),
                                mu_required=float(f.mu_required))

    def standing(self):
        """(True, '') if the body can rest on this slope, else (False, why): a stable rest
        pose must exist (the tipping limit) with both contacts pressed and μ_required ≤ μ
        (the friction limit)."""
        stable = [eq for eq in self.equilibria() if eq.stable]
        if not stable:
            return False, (f'no stable rest pose on a slope of {self.scene.slope:g} rad at '
                           f'heading0 {self.scene.heading0:g} rad: the body tips over and rolls')
        held = [eq for eq in stable if eq.normal_a > 0 and eq.normal_b > 0
                and eq.mu_required <= self.scene.friction]
        if not held:
            need = min(eq.mu_required for eq in stable)
            return False, (f'the body slips at rest on a slope of {self.scene.slope:g} rad: '
                           f'it needs mu >= {need:.4g}, friction is {self.scene.friction:g}')
        return True, ''

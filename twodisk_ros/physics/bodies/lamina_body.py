"""Two congruent laminae of any shape as a :class:`~twodisk_ros.physics.bodies.protocol.RollingBody`.

docs/physics.md#the-phase-of-a-general-body. The resting poses are solved to rounding from
the support function (:mod:`~twodisk_ros.physics.bodies.contact_solver`: guarded Newton on the convex
elevation equations, a bracketing root finder on the phase ray) at N equispaced phases of
the regular phase u (:mod:`~twodisk_ros.physics.bodies.regular_phase`), N a power of two doubled
until the spectral tail of every sampled function is below
:data:`~twodisk_ros.physics.numerics.spectral.TAIL_TOLERANCE`. The samples are refined spectrally to
a grid :data:`OVERSAMPLING` times finer, where values, first and second derivatives
(spectral) feed one quintic Hermite table; any real u is evaluated from it.

The phase is built on each lamina's phase parameter (:mod:`~twodisk_ros.physics.laminae.phase_map`:
for superellipses it stops at the vertices or dwells at the corners). :meth:`LaminaBody.
flat_vertex_phases` is the hook for the equilibria search: the exact phases where a contact
sits on a flat vertex (z_G flat to high order there), onto which a root of dz_G/du found
nearby should be snapped.

Complex-step contract (bodies/protocol.py): at u + i h the table returns f(u) + i h f′(u) with
f′ the interpolant's derivative, so callers' complex steps give the spectral derivative.

Frames as in bodies/ellipse.py and bodies/contact_solver.py: body frame with origin G, the centroid of the two
laminae (ContactSolver.centroid); r1 = GA, r2 = GB (m); n the upward ground normal.
:meth:`LaminaBody.about` moves the origin (the reference point P) along e2, sharing the
tables: then r1 = PA, r2 = PB and the height is P's, z_P = z_G + n·(P − G). That is how a
solid whose centre of mass lies off G (an egg in the parallel arrangement) gets a body whose
origin is its centre of mass, as RollingDynamics needs (mass.models.centred_on_mass).
"""

import copy
import dataclasses
import math

import numpy as np

from ..numerics.analytic import COMPLEX_STEP
from .ellipse import PhaseGeometry
from .contact_solver import ARRANGEMENTS, ContactSolver
from ..laminae.shapes import VERTEX_AXES
from .regular_phase import BRANCH_FLIP, COLUMNS, PhaseSolver, THETA_FLIP, unfold
from .protocol import RollingBody
from ..numerics.spectral import TAIL_TOLERANCE, real_spectral_derivative, spectral_tails, upsample
from ..numerics.tables import HermiteTable
from ..numerics.vectors import cross, vector

__all__ = ['LaminaBody', 'MIN_NODES', 'MAX_NODES', 'OVERSAMPLING', 'RESOLVED_TAIL', 'symmetrise']

TWO_PI = 2.0 * math.pi
#: First and largest number of exactly solved phases per cycle (powers of two).
MIN_NODES = 64
MAX_NODES = 1 << 14
#: The Hermite table's grid is this many times finer than the solved nodes (at least
#: MIN_TABLE nodes), so that the cycle's own grids (512 … nodes) fall on table nodes.
OVERSAMPLING = 8
MIN_TABLE = 4096
#: A body whose samples are not resolved to this at MAX_NODES is refused (one line).
RESOLVED_TAIL = 1e-4
#: Stop doubling once the tail is below this and a doubling shrank it by less than half: the
#: samples' rounding noise (a converging spectrum shrinks far faster; spectral.refine_grid).
_NOISE_FLOOR = 1e-12
_STALL = 0.5
# column indices of the table: COLUMNS, then ds/du and dα/du
_R1, _R2, _N, _T1 = (0, 1), (2, 3), (4, 5, 6), (7, 8)
_HEIGHT, _THETA, _PSI, _DS, _DALPHA = 9, 10, 11, 12, 13
#: Parity of every column under u → −u (the mirror x1 → −x1) and u → π − u (x3 → −x3):
#: ds/du = t1·dr1/du is odd about π/2 (A turns back there), dα/du even about both.
_PARITY_ZERO = np.concatenate([THETA_FLIP, [1.0, 1.0]])
_PARITY_HALF = np.concatenate([BRANCH_FLIP, [-1.0, 1.0]])


def symmetrise(values, order):
    """The k-th derivatives (k = ``order``) of the columns at u_j = 2πj/M (M a multiple of 4,
    shape (M, 14)) made exactly symmetric under the body's two mirrors.

    f(−u) = P f(u) gives f⁽ᵏ⁾(−u) = (−1)ᵏ P f⁽ᵏ⁾(u), and likewise about π/2: each mirror's
    average of the node values and their images. The spectral derivatives of the (exactly
    symmetric) samples break the symmetry only by rounding amplified by the wavenumbers
    (~5e-15 m/rad in dz/du); averaged, an odd derivative is exactly 0 at the landmarks
    u = 0, π/2, π, 3π/2, which are then exact critical points of z (at a flat vertex, where
    z − z* ~ (u − u*)⁴, 5e-15 m/rad moved the root of dz/du by 2e-5 rad).
    """
    m = len(values)
    j = np.arange(m)
    sign = (-1.0) ** order
    values = 0.5 * (values + sign * _PARITY_ZERO * values[(-j) % m])
    return 0.5 * (values + sign * _PARITY_HALF * values[(m // 2 - j) % m])


def _rates(samples):
    """ds/du = t1·dr1/du and dα/du = n·e3 · (t1 × dt1/du) at the nodes (spectral)."""
    d = real_spectral_derivative(samples[:, [0, 1, 7, 8]])
    t1x, t1y = samples[:, 7], samples[:, 8]
    ds = t1x * d[:, 0] + t1y * d[:, 1]
    dalpha = samples[:, 6] * (t1x * d[:, 3] - t1y * d[:, 2])
    return np.column_stack([samples, ds, dalpha])


def _flat_vertex_parameters(lamina):
    """Lamina parameters (rad) of the lamina's flat vertices (zero curvature: Vertex.radius
    infinite, or a lamina that refuses to describe one as flat), '+x' also mirrored to −x."""
    found = []
    for axis in VERTEX_AXES:
        try:
            flat = math.isinf(lamina.vertex(axis).radius)
        except ValueError as error:        # Lamina.vertex: flat, no order of contact given
            flat = 'flat' in str(error)
        if flat:
            s = float(lamina.support(np.array(VERTEX_AXES[axis])).parameter)
            found.extend([s, -s] if axis == '+x' else [s])
    return found


class LaminaBody(RollingBody):
    """Two congruent convex laminae in perpendicular planes, centres at ∓Δ along e2.

    Parameters
    ----------
    lamina : Lamina
        The shape of both disks (laminae/shapes.py).
    delta : float
        Half the distance between the centres (m) (limits as in
        :class:`~twodisk_ros.physics.bodies.contact_solver.ContactSolver`).
    arrangement : str
        'parallel' (default) or 'swapped' (bodies/contact_solver.py).

    Attributes
    ----------
    general : ContactSolver
        The exact contact geometry (θ and tilt charts).
    resolution : int
        Exactly solved phases per cycle.
    spectral_tail : float
        Largest relative upper-half spectrum of the sampled functions at that resolution.
    """

    def __init__(self, lamina, delta, arrangement='parallel'):
        if arrangement not in ARRANGEMENTS:
            raise ValueError(f'arrangement must be one of {sorted(ARRANGEMENTS)}, '
                             f'got {arrangement!r}')
        self.general = ContactSolver(lamina, delta, arrangement)
        self._solver = PhaseSolver(self.general)
        self._offset = 0.0
        self._sample()

    def __repr__(self):
        moved = f'.about({self._offset!r})' if self._offset else ''
        return (f'LaminaBody({self.lamina!r}, delta={self.delta!r}, '
                f'arrangement={self.arrangement!r}){moved}')

    def describe(self):
        return f'{self.lamina.describe()}, Δ = {self.delta:.4g} m, {self.arrangement}'

    @property
    def contact_solver(self):
        return self.general

    def about(self, offset):
        """The same body with its reference point (the body-frame origin) moved by offset e2.

        Parameters
        ----------
        offset : float
            Along e2 (m, body frame), from the current reference point; finite, |offset| <
            size. ``about(0.0)`` is the body itself.

        Returns
        -------
        LaminaBody
            Sharing this body's tables and contact geometry: θ, ψ, n, t1, the phase, its
            rates and ω_u are the same; r1, r2 and the height are those of the new point P
            (r_i − offset e2, z + offset n·e2); ``offset`` is P's from G, ``origin`` P's from
            O, ``size`` the largest distance of a disk point from P.
        """
        shift = float(offset) if isinstance(offset, (int, float, np.floating,
                                                     np.integer)) else math.nan
        if not (math.isfinite(shift) and abs(shift) < self.size) or isinstance(offset, bool):
            raise ValueError(f'offset must be a finite number of metres with |offset| < size = '
                             f'{self.size!r}, got {offset!r}')
        if shift == 0.0:
            return self
        moved = copy.copy(self)              # shares the tables and the contact geometry
        state = vars(moved)
        state.pop('_size', None)
        state['_offset'] = self._offset + shift
        return moved

    def centred_on(self, center_of_mass):
        """(this body moved by the centre of mass's e2 part (:meth:`about`), zeros (3,)): its
        e1 and e3 parts vanish by the mirror symmetries (> 1e-12 of the size is refused)."""
        com = center_of_mass
        if max(abs(com[0]), abs(com[2])) > 1e-12 * self.size:
            raise ValueError(f'the centre of mass {com.tolist()} m is off the common axis e2: '
                             'the body cannot be moved onto it along e2')
        return self.about(float(com[1])), np.zeros(3)

    # -- construction ------------------------------------------------------------------------
    def _sample(self):
        n = MIN_NODES
        quarter = self._solver.samples(TWO_PI * np.arange(n // 4 + 1) / n)
        previous = math.inf
        while True:
            samples = _rates(unfold(quarter))
            tail = float(np.max(spectral_tails(samples)))
            if tail < TAIL_TOLERANCE or n >= MAX_NODES:
                break
            if tail <= _NOISE_FLOOR and tail > _STALL * previous:
                break
            previous = tail
            # double: the old nodes are the even ones of the new grid
            new = self._solver.samples(TWO_PI * (2 * np.arange(n // 4) + 1) / (2 * n))
            merged = np.empty((n // 2 + 1, quarter.shape[1]))
            merged[0::2], merged[1::2] = quarter, new
            quarter, n = merged, 2 * n
        if not tail <= RESOLVED_TAIL:
            raise ValueError(f'{self.general!r}: the cycle is not resolved by {n} phases '
                             f'(spectral tail {tail:.1e}); the shape is too sharp')
        self.resolution, self.spectral_tail = n, tail
        spectra = np.abs(np.fft.rfft(samples, axis=0))
        self._spectrum = np.max(spectra / np.maximum(spectra.max(axis=0), 1e-300), axis=1)
        factor = max(OVERSAMPLING, MIN_TABLE // n)
        fine = np.column_stack([upsample(samples[:, k], factor)
                                for k in range(samples.shape[1])])
        first = real_spectral_derivative(fine)
        second = real_spectral_derivative(first)
        self._table = HermiteTable.periodic(*(symmetrise(f, k) for k, f in
                                              enumerate((fine, first, second))))

    # -- table evaluation --------------------------------------------------------------------
    def _values(self, u):
        """The table's columns at phase(s) u: real u → f(u); complex u → f + i Im(u) f′."""
        u = np.asarray(u)
        if np.iscomplexobj(u):
            x = np.mod(u.real, TWO_PI)
            return self._table(x) + 1j * u.imag[..., None] * self._table(x, 1)
        return self._table(np.mod(np.asarray(u, dtype=float), TWO_PI))

    @staticmethod
    def _unit(v):
        return v / np.sqrt(np.sum(v * v, axis=-1, keepdims=True))

    def _vectors(self, f):
        zero = np.zeros_like(f[..., 0])
        g = self._offset
        r1 = vector(f[..., 0], f[..., 1] - g, zero)
        r2 = vector(zero, f[..., 2] - g, f[..., 3])
        n = self._unit(f[..., 4:7])
        t1 = self._unit(vector(f[..., 7], f[..., 8], zero))
        return r1, r2, n, t1, self._height(f, n[..., 1])

    def _height(self, f, n2=None):
        """The reference point's height: z_G + offset n·e2 (m)."""
        if not self._offset:
            return f[..., _HEIGHT]
        if n2 is None:
            n2 = self._unit(f[..., 4:7])[..., 1]
        return f[..., _HEIGHT] + self._offset * n2

    # -- RollingBody -------------------------------------------------------------------------
    def phase_vectors(self, u):
        """(r1, r2, n, t1, z_G) at phase u (body frame, m; complex-safe, module doc)."""
        return self._vectors(self._values(u))

    def phase_height(self, u):
        """z_G(u) (m), the reference point's height. Complex-safe."""
        return self._height(self._values(u))

    def phase_rates(self, u):
        """(ds/du, dα/du) (m/rad, rad/rad) of the trace of A. Complex-safe."""
        f = self._values(u)
        return f[..., _DS], f[..., _DALPHA]

    def phase_geometry(self, u):
        """:class:`~twodisk_ros.physics.bodies.ellipse.PhaseGeometry` at real phase(s) u (no σ√Q: NaN)."""
        u = np.asarray(u, dtype=float)
        f = self._values(u)
        r1, r2, n, t1, height = self._vectors(f)
        return PhaseGeometry(phase=u, theta=f[..., _THETA], psi=f[..., _PSI],
                             branch=np.where(np.cos(u) < 0, -1.0, 1.0),
                             signed_sqrt_q=np.full(u.shape, np.nan), contact_a=r1,
                             contact_b=r2, ground_normal=n, tangent_a=t1, height=height,
                             tilt=np.arctan2(np.hypot(n[..., 0], n[..., 1]), n[..., 2]))

    def phase_angular_velocity(self, u):
        """ω_u (rad per rad of u, body frame): α′ n − ½ Σ b_i × b_i′ over the contact frame
        (t1, n × t1, n), derivatives from the table."""
        u = np.asarray(u, dtype=float)
        return self._angular_velocity(u, self._values(u))

    def phase_angular_velocity_and_contact(self, u):
        """(ω_u, r1): :meth:`phase_angular_velocity` and ``phase_geometry(u).contact_a`` at real
        phase(s) u (RollingBody), from one evaluation of the table at u."""
        u = np.asarray(u, dtype=float)
        f = self._values(u)
        return self._angular_velocity(u, f), self._vectors(f)[0]

    def _angular_velocity(self, u, f):
        """ω_u at real phase(s) u from the table's columns f there."""
        df = self._table(np.mod(u, TWO_PI), 1)
        _, _, n, t1, _ = self._vectors(f + 1j * COMPLEX_STEP * df)
        m = cross(n, t1)
        frame = 0.5 * sum(cross(x.real, x.imag / COMPLEX_STEP) for x in (n, t1, m))
        return f[..., _DALPHA][..., None] * n.real - frame

    def phase_angles_with_rates(self, u):
        """(θ, ψ, dθ/du, dψ/du) at real phase(s) u (rad, rad per rad)."""
        x = np.mod(np.asarray(u, dtype=float), TWO_PI)
        f, df = self._table(x), self._table(x, 1)
        return f[..., _THETA], f[..., _PSI], df[..., _THETA], df[..., _PSI]

    def phase_from_theta(self, theta, branch=1):
        """The phase u ∈ [−π/2, 3π/2) of contact angle θ (rad) on a branch (±1).

        From the A chart: s_A from θ, β_B from the convex elevation equation, u the polar
        angle of (s_A/s_max, β_B/β_0). ψ(θ) ~ √(θ_max − |θ|) makes this lose about half the
        digits within ~1e-8 θ_max of the turning points (the phase itself is regular there).
        """
        theta = np.asarray(theta, dtype=float)
        s = np.abs(self.general.parameter_of_theta(theta))
        branch = np.asarray(branch)
        if not np.all((branch == 1) | (branch == -1)):
            raise ValueError(f'branch must be +1 or -1, got {branch!r}')
        p, q = self._solver.chart_a(s)
        base = np.where(theta < 0, -1.0, 1.0) * np.arctan2(p, q)
        return np.where(branch > 0, base, np.pi - base)

    @property
    def turns_everywhere(self):
        """RollingBody: True if no contact ever sits on a flat vertex of the lamina, the only
        phases where the body stops turning in u (:meth:`flat_vertex_phases` is empty)."""
        return not len(self.flat_vertex_phases())

    def flat_vertex_phases(self):
        """The phases u ∈ [0, 2π) (rad, sorted) where a contact sits on a flat vertex of its
        lamina (zero curvature: a superellipse's four vertices for n > 2), exact to rounding.

        A hook for the equilibria search: z_G is flat to high order there (the body barely
        turns, |ω_u| = 0), so a root of dz_G/du found numerically near one of these phases
        is one of them and should be snapped to it. Each phase comes from the phase charts
        at the vertex's exact lamina parameter (A on disk 1: its polar angle in the
        (p, q) plane; B on disk 2 likewise), not from a root of dz_G/du, and the body's two
        mirrors give the rest (u, −u, π − u, π + u). Empty for laminae without flat vertices.
        """
        cached = self.__dict__.get('_flat_vertex_phases')
        if cached is None:
            flat = _flat_vertex_parameters(self.lamina)
            quarter = self._solver.quarter_phases(flat, flat)
            images = np.concatenate([quarter, -quarter, math.pi - quarter, math.pi + quarter])
            cached = np.unique(np.mod(images, TWO_PI))
            cached.flags.writeable = False
            self.__dict__['_flat_vertex_phases'] = cached
        return cached

    def contact_angle_psi(self, theta, branch=1):
        """ψ(θ) (rad) on a branch (the exact θ chart of bodies/contact_solver.py)."""
        return self.general.contact_angle_psi(theta, branch)

    # -- the paper's θ chart, exact (bodies/contact_solver.py) ----------------------------------------
    def geometry(self, theta, branch=1):
        """:class:`~twodisk_ros.physics.bodies.contact_solver.ContactGeometry` at θ on a branch
        (contact vectors and height of the reference point)."""
        pose = self.general.geometry(theta, branch)
        if not self._offset:
            return pose
        shift = np.array([0.0, self._offset, 0.0])
        return dataclasses.replace(
            pose, contact_a=pose.contact_a - shift, contact_b=pose.contact_b - shift,
            height=pose.height + self._offset * pose.ground_normal[..., 1])

    def height(self, theta):
        """z_G (m) at contact angle θ (rad), the reference point's height."""
        return self.geometry(theta).height

    # -- scalar properties -------------------------------------------------------------------
    @property
    def lamina(self):
        return self.general.lamina

    @property
    def arrangement(self):
        return self.general.arrangement

    @property
    def delta(self):
        return self.general.delta

    @property
    def centroid(self):
        """G, the laminae's centroid, from the midpoint O of the centres (m, body frame):
        (1 + σ) ȳ/2 e2 (also for a moved body: see ``origin``)."""
        return self.general.centroid

    @property
    def phase_map(self):
        """The :class:`~twodisk_ros.physics.laminae.phase_map.PhaseMap` s = w(t) of the contacts'
        lamina parameters on which the phase is built (identity but for superellipses)."""
        return self._solver.map

    @property
    def offset(self):
        """The reference point P (the body-frame origin) from G (m, along e2; :meth:`about`)."""
        return self._offset

    @property
    def origin(self):
        """The reference point P from O (m, body frame): G + offset e2."""
        return self.general.centroid + np.array([0.0, self._offset, 0.0])

    @property
    def theta_max(self):
        return self.general.theta_max

    @property
    def psi_max(self):
        return self.general.psi_max

    @property
    def size(self):
        """Largest distance (m) of a disk point from the reference point."""
        if not self._offset:
            return self.general.size
        cached = self.__dict__.get('_size')
        if cached is None:
            cached = self.__dict__['_size'] = self.general.size_about(float(self.origin[1]))
        return cached

    @property
    def feature_width(self):
        """Width (rad of u) of the sharpest feature, in (0, 1], from the sampled spectrum.

        An analytic function whose nearest complex singularity lies w from the real axis has
        Fourier coefficients ~ e^(−w k): w = ln(1e10)/k₁₀ with k₁₀ the first wavenumber
        beyond which every column's spectrum stays below 1e-10 of its peak.
        """
        envelope = np.maximum.accumulate(self._spectrum[::-1])[::-1]
        beyond = np.nonzero(envelope < 1e-10)[0]
        k10 = int(beyond[0]) if beyond.size else len(envelope)
        return min(1.0, math.log(1e10) / max(k10, 1))

"""The outlines of a body's two laminae, sampled for drawing: any lamina, any body.

Everything that draws the body (meshes, URDF, RViz markers, the Foxglove view, animations)
takes its rims from here, so it draws the real outline of :attr:`body.lamina` (laminae/shapes.py):
an ellipse, a superellipse, an egg or a fitted outline.

**The polygon.** :func:`lamina_outline` inscribes a polygon in the lamina's boundary, in
lamina coordinates (m; x along e1, y along the common axis e2). Its error is measured
exactly with the support function h: a chord P→Q of the counterclockwise boundary, with
outward unit normal ν, misses the arc it cuts off by h(ν) − P·ν (the farthest arc point is
the support point in direction ν). Chords are split at that support point until every
chord misses its arc by at most ``tolerance × lamina.size``, so the vertices gather where
the boundary turns fast (a superellipse's rounded corners at large n) and stay sparse along
its flat sides. The polygon starts at the far tip s = 0 (on −y), reaches the other tip
s = π at index N/2, runs counterclockwise and is exactly symmetric about the common axis
(the half s ∈ [0, π] is refined and mirrored, x → −x). Every vertex is a boundary point of
the lamina (``lamina.point``). :func:`resolution_tolerance` converts a mesh resolution n
(vertices of a regular n-gon) into the equivalent tolerance 1 − cos(π/n).

**In the body.** Body frame G e1 e2 e3 (m). With bodies/contact_solver.py's placement, disk 1's
lamina point (x, y) sits at (x, y − Δ, 0) − G and disk 2's at (0, Δ + σy, x) − G, σ = ±1 the
arrangement ('parallel', 'swapped'); G = ContactSolver(lamina, Δ, arrangement).centroid,
the midpoint of the centres for laminae symmetric along y (ellipses, superellipses). A body
moved by :meth:`LaminaBody.about <twodisk_ros.physics.bodies.lamina_body.LaminaBody.about>` (its
origin P = ``body.origin``, the centre of mass of a solid egg) is drawn about P: every
point above minus ``body.offset`` e2, so that the world pose of P places the laminae. In the
disk frames of :mod:`~twodisk_ros.model.frames` (x towards the disk's far tip along e2, z
normal to the disk) the same points are (−y, x, 0) on disk 1 and (σy, −x, 0) on disk 2.
"""

from dataclasses import dataclass
import math

import numpy as np


__all__ = ['ARRANGEMENTS', 'BodyShape', 'DEFAULT_TOLERANCE', 'body_shape', 'chord_deviation', 'disk_rims',
           'frame_rims', 'lamina_outline', 'resolution_tolerance']

#: Disk 2's orientation: σ, the sign of its lamina y along e2 (bodies/contact_solver.py).
ARRANGEMENTS = {'parallel': 1.0, 'swapped': -1.0}
#: Default polygon error of a drawn outline, as a fraction of the lamina's size: below a
#: pixel for a body 500 pixels wide; a circle gets 64 vertices (error 1.2e-3), as the
#: markers had before.
DEFAULT_TOLERANCE = 2e-3
#: Chords of the first polygon on the half outline s ∈ [0, π].
_FIRST_CHORDS = 8
#: A split point closer than this share of its chord's parameter interval to an end is moved
#: there (it keeps the refinement moving where the support point is ambiguous to rounding).
_SPLIT_MARGIN = 0.05
#: At most this many vertices on a half outline (a tolerance below ~1e-9 is refused).
_MAX_HALF = 1 << 15


def resolution_tolerance(resolution):
    """1 − cos(π/n): the polygon error of a regular n-gon inscribed in a circle (× radius)."""
    return 1.0 - math.cos(math.pi / resolution)


def _tolerance(tolerance):
    if isinstance(tolerance, (bool, str, bytes)) or not np.isscalar(tolerance) \
            or not (math.isfinite(float(tolerance)) and 1e-9 <= float(tolerance) <= 0.1):
        raise ValueError(f'tolerance must be a number in [1e-9, 0.1] (a fraction of the '
                         f'lamina\'s size), got {tolerance!r}')
    return float(tolerance)


def chord_deviation(lamina, start, end):
    """How far the boundary arc cut off by each chord start→end lies beyond it (m).

    ``start``, ``end``: boundary points (..., 2), the chord running counterclockwise. Returns
    (h(ν) − start·ν, the boundary parameter of the support point in direction ν), ν the
    chord's outward unit normal (the chord's direction turned by −90°).
    """
    d = np.asarray(end, dtype=float) - np.asarray(start, dtype=float)
    length = np.hypot(d[..., 0], d[..., 1])
    nu = np.stack([d[..., 1], -d[..., 0]], axis=-1) / length[..., None]
    found = lamina.support(nu)
    return found.height - np.sum(np.asarray(start) * nu, axis=-1), found.parameter


def _half_parameters(lamina, limit):
    """Boundary parameters in [0, π] whose chords all miss their arcs by ≤ ``limit`` (m)."""
    s = np.linspace(0.0, np.pi, _FIRST_CHORDS + 1)
    while True:
        points = lamina.point(s)
        deviation, split = chord_deviation(lamina, points[:-1], points[1:])
        bad = deviation > limit
        if not np.any(bad):
            return s
        low, high = s[:-1][bad], s[1:][bad]
        margin = _SPLIT_MARGIN * (high - low)
        new = np.clip(np.where(np.isfinite(split[bad]), split[bad], 0.5 * (low + high)),
                      low + margin, high - margin)
        s = np.sort(np.concatenate([s, new]))
        if len(s) > _MAX_HALF:
            raise ValueError(f'the outline of {lamina!r} needs more than {2 * _MAX_HALF} '
                             f'points for a polygon error of {limit:.3g} m')


def lamina_outline(lamina, tolerance=DEFAULT_TOLERANCE):
    """Vertices (N, 2) (m, lamina coordinates) of a polygon inscribed in the lamina.

    Counterclockwise from the tip s = 0, the tip s = π at index N/2, symmetric about the
    common axis; every chord misses its arc by ≤ ``tolerance × lamina.size`` (module
    docstring), so for every direction n, max over the vertices of p·n ≥ h(n) − that.
    """
    limit = _tolerance(tolerance) * lamina.size
    s = _half_parameters(lamina, limit)
    half = np.array(lamina.point(s), dtype=float)
    half[[0, -1], 0] = 0.0                      # the tips lie on the common axis
    mirror = half[-2:0:-1] * np.array([-1.0, 1.0])
    return np.concatenate([half, mirror])


@dataclass(frozen=True)
class BodyShape:
    """Where a body's laminae sit: what drawing needs of any body."""

    lamina: object          #: the Lamina of both disks (lamina coordinates, m)
    delta: float            #: half the distance between the centres (m)
    arrangement: str        #: 'parallel' or 'swapped'
    sigma: float            #: +1 or −1: disk 2's lamina y runs along ±e2
    centroid: np.ndarray    #: the body-frame origin from the midpoint O of the centres (m,
    #: along e2): G, or P = ``body.origin`` for a body moved by LaminaBody.about


def body_shape(body):
    """:class:`BodyShape` of a EllipseBody, a LaminaBody or a ContactSolver."""
    arrangement = body.arrangement
    if arrangement not in ARRANGEMENTS:
        raise ValueError(f'arrangement must be one of {sorted(ARRANGEMENTS)}, '
                         f'got {arrangement!r}')
    centroid = np.array(body.origin, dtype=float)     # a moved LaminaBody: P = G + offset e2
    centroid.setflags(write=False)
    return BodyShape(body.lamina, float(body.delta), arrangement, ARRANGEMENTS[arrangement],
                     centroid)


def frame_rims(body, tolerance=DEFAULT_TOLERANCE):
    """The two rims in their disk frames (frames.py): arrays (N, 2) (m), counterclockwise
    about the frame's z (so a fan (centre, p_k, p_k+1) faces +z), each starting at the
    disk's far tip (frame x > 0)."""
    shape = body_shape(body)
    points = lamina_outline(shape.lamina, tolerance)
    x, y = points[:, 0], points[:, 1]
    # disk 1: (−y, x) turns the lamina by +90°: counterclockwise, starting at the tip −y
    rim_1 = np.stack([-y, x], axis=-1)
    # disk 2: (σy, −x): a turn by −90° (σ = +1) or a reflection (σ = −1); start at the tip
    # where σy is largest (s = π for σ = +1, s = 0 for σ = −1)
    rim_2 = np.stack([shape.sigma * y, -x], axis=-1)
    half = len(points) // 2
    rim_2 = np.roll(rim_2, -half, axis=0) if shape.sigma > 0 else rim_2[::-1]
    if shape.sigma < 0:
        rim_2 = np.roll(rim_2, 1, axis=0)       # the tip s = 0 first again
    return rim_1, rim_2

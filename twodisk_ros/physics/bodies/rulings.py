"""The solid hull of any two laminae as a closed triangle mesh, from its rulings.

The convex hull of the two laminae is bounded by a developable surface ruled by the
segments AB between the two contact points of the resting poses (docs/physics.md#mass-
models): each resting pose's ground plane touches the hull along its AB. So the hull's
surface is sampled by rulings and triangulated as strips between consecutive ones.

**Sampling.** :class:`~twodisk_ros.physics.bodies.contact_solver.ContactSolver` gives the
resting poses exactly (bisection to the last bit) in two charts: the contact angle θ of A
(:meth:`geometry`) from θ = 0 to θ_mid, and the tilt of disk 1 (:meth:`geometry_at_tilt`)
from there to the turning point θ_max, where ψ(θ) ~ √(θ_max − θ) and the θ chart is
ill-conditioned; θ_mid is A's pose halfway (in its boundary parameter) between the steepest
pose and the turning point. A quarter cycle (branch +1, θ ≥ 0) is sampled on a chart
parameter p ∈ [0, 1] whose intervals are halved until consecutive rulings' ends A and B are
each at most a chord 2 sin(π/n) L apart (L the body's size, n the resolution: the side of a
regular n-gon) and each chord misses its rim by at most (1 − cos(π/n)) × the lamina's size
(measured with the support function, :func:`~twodisk_ros.physics.bodies.outline.chord_deviation`).

**The other three quarters** follow exactly from the body's two mirror symmetries (every
lamina is symmetric about the common axis): x1 ↦ −x1 takes θ to −θ on the same branch
(B stays), x3 ↦ −x3 takes branch +1 to branch −1 at the same θ (A stays). The cycle of
rulings, θ from −θ_max to θ_max on branch +1 and back on branch −1, is a closed band whose
two edges are A's arc (run forth and back) and B's arc (likewise): with A and B shared
between the branches, the strips close into a surface without boundary, every edge shared
by two triangles, wound outward.
"""

import math

import numpy as np

from .outline import chord_deviation, frame_rims, resolution_tolerance

__all__ = ['Drawable', 'convex_surface', 'hull_rulings', 'ruled_hull']

#: Intervals of each chart before refinement; the refinement halves at most this many times.
_FIRST_INTERVALS, _MAX_LEVELS = 8, 24
_MIRROR_1 = np.array([-1.0, 1.0, 1.0])     # x1 ↦ −x1: θ ↦ −θ, same branch
_MIRROR_3 = np.array([1.0, 1.0, -1.0])     # x3 ↦ −x3: branch ↦ −branch, same θ


class Drawable:
    """What model/mesh.py draws of a body (RollingBody, ContactSolver), from its exact
    geometry; EllipseBody gives both in closed form."""

    def plate_rims(self, resolution):
        """The plates' rims at a resolution n, (disk 1, disk 2) (N, 2) in the disk frames (m):
        the outline polygon of a regular n-gon's error (:func:`.outline.frame_rims`)."""
        return frame_rims(self, resolution_tolerance(resolution))

    def hull_surface(self, resolution):
        """The hull's closed surface at a resolution n: :func:`ruled_hull`."""
        return ruled_hull(self, resolution)


class _Quarter:
    """Poses of branch +1, θ from 0 to θ_max, on the chart parameter p ∈ [0, 1]."""

    def __init__(self, general):
        self.general = general
        s_steep = general.steepest[0]
        s_mid = 0.5 * (s_steep + general.s_max)
        point = general.lamina.point(s_mid)
        self.theta_mid = float(np.arctan2(max(float(point[0]), 0.0), -float(point[1])))
        low, high = general.tilt_range
        self.tilt_mid = float(np.clip(general.geometry(self.theta_mid).tilt, low, np.pi / 2))

    def poses(self, p):
        """(A (k, 3), B (k, 3), A's lamina point (k, 2), B's lamina point (k, 2)) at p."""
        g = self.general
        p = np.asarray(p, dtype=float)
        first = p <= 0.5
        parts = []
        if np.any(first):
            parts.append(g.geometry(np.minimum(2 * p[first] * self.theta_mid, g.theta_max)))
        if np.any(~first):
            tilt = self.tilt_mid + (2 * p[~first] - 1) * (np.pi / 2 - self.tilt_mid)
            parts.append(g.geometry_at_tilt(np.minimum(tilt, np.pi / 2)))
        a = np.concatenate([q.contact_a for q in parts])
        b = np.concatenate([q.contact_b for q in parts])
        # lamina coordinates: A = (x, y − Δ, 0) − G, B = (0, Δ + σy, x) − G
        a_o, b_o = a + g.centroid, b + g.centroid
        a_lamina = np.stack([a_o[:, 0], a_o[:, 1] + g.delta], axis=-1)
        b_lamina = np.stack([b_o[:, 2], g.sigma * (b_o[:, 1] - g.delta)], axis=-1)
        return a, b, a_lamina, b_lamina


def _too_coarse(lamina, ends, lamina_points, step, limit):
    """Intervals between consecutive samples whose chord is longer than ``step`` or misses
    the rim by more than ``limit`` (m), on either orientation of the chord."""
    long_ = np.linalg.norm(np.diff(ends, axis=0), axis=1) > step
    start, end = lamina_points[:-1], lamina_points[1:]
    moved = np.linalg.norm(end - start, axis=1) > 0
    deviation = np.zeros(len(start))
    if np.any(moved):
        forward = chord_deviation(lamina, start[moved], end[moved])[0]
        backward = chord_deviation(lamina, end[moved], start[moved])[0]
        deviation[moved] = np.minimum(forward, backward)
    return long_ | (deviation > limit)


def hull_rulings(body, resolution):
    """The rulings of a quarter cycle: (A, B), arrays (m + 1, 3) (m, body frame from the
    body's origin: G, or P = G + ``body.offset`` e2 of a moved LaminaBody).

    Ruling j joins A[j] and B[j], branch +1, θ increasing from 0 (j = 0) to θ_max (j = m),
    sampled as the module docstring says; :func:`ruled_hull` mirrors them into the cycle.
    """
    general = body.contact_solver
    quarter = _Quarter(general)
    step = 2 * math.sin(math.pi / resolution) * general.size
    limit = resolution_tolerance(resolution) * general.lamina.size
    p = np.linspace(0.0, 1.0, 2 * _FIRST_INTERVALS + 1)
    a, b, a_l, b_l = quarter.poses(p)
    for _ in range(_MAX_LEVELS):
        coarse = (_too_coarse(general.lamina, a, a_l, step, limit)
                  | _too_coarse(general.lamina, b, b_l, step, limit))
        if not np.any(coarse):
            break
        new_p = 0.5 * (p[:-1] + p[1:])[coarse]
        new = quarter.poses(new_p)
        order = np.argsort(np.concatenate([p, new_p]), kind='stable')
        p = np.concatenate([p, new_p])[order]
        a, b, a_l, b_l = (np.concatenate([old, added])[order]
                          for old, added in zip((a, b, a_l, b_l), new))
    # from the body's origin: P = G + offset e2 for a body moved by LaminaBody.about
    shift = np.array([0.0, float(body.offset), 0.0])
    return a - shift, b - shift


def ruled_hull(body, resolution):
    """(vertices (n, 3), faces (f, 3)) of the hull's surface, closed and wound outward.

    Vertices: A's arc θ = −θ_max … θ_max (2m + 1 points), then B on branch +1 (θ = 0 … θ_max,
    m + 1 points, the last B at the turning point) and B on branch −1 (θ = 0 … θ_max
    excluded, m points).
    """
    a_q, b_q = hull_rulings(body, resolution)
    m = len(a_q) - 1
    a_q, b_q = a_q.copy(), b_q.copy()
    # exact symmetry where the quarter meets the mirror planes: A at θ = 0 has x1 = 0 (the
    # tip), B at the turning point has x3 = 0 (the tip of disk 2)
    a_q[0, 0] = 0.0
    b_q[-1, 2] = 0.0
    vertices_a = np.concatenate([a_q[:0:-1] * _MIRROR_1, a_q])
    vertices_b = np.concatenate([b_q, b_q[:-1] * _MIRROR_3])
    vertices = np.concatenate([vertices_a, vertices_b])
    offset = len(vertices_a)
    j = np.arange(m + 1)

    def b_index(jj, branch):
        if branch > 0:
            return offset + jj
        return np.where(jj == m, offset + m, offset + m + 1 + jj)
    # the cycle of rulings: branch +1 θ −θ_max → θ_max, branch −1 θ_max → −θ_max (ends once)
    ring_a = np.concatenate([m - j[::-1], m + j[1:],           # branch +1
                             m + j[-2::-1], m - j[1:-1]])      # branch −1
    ring_b = np.concatenate([b_index(j[::-1], 1), b_index(j[1:], 1),
                             b_index(j[-2::-1], -1), b_index(j[1:-1], -1)])
    a0, b0 = ring_a, ring_b
    a1, b1 = np.roll(ring_a, -1), np.roll(ring_b, -1)
    faces = np.concatenate([np.stack([a0, a1, b1], axis=1), np.stack([a0, b1, b0], axis=1)])
    corners = vertices[faces]
    volume = np.einsum('ij,ij->i', corners[:, 0],
                       np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0
    if volume < 0:
        faces = faces[:, ::-1]
    return vertices, faces


def convex_surface(points):
    """(vertices, faces) of the convex hull (scipy's Qhull) of ``points`` (k, 3) (m): the
    points on it in their order and its triangles, wound outward."""
    from scipy.spatial import ConvexHull
    hull = ConvexHull(points)
    faces = hull.simplices.copy()
    corners = points[faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    inward = np.einsum('ij,ij->i', cross, hull.equations[:, :3]) < 0
    faces[inward] = faces[inward][:, ::-1]
    used = np.unique(faces)
    index = np.full(len(points), -1)
    index[used] = np.arange(len(used))
    return points[used], index[faces]

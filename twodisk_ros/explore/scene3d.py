"""The 3D scene of ``twodisk-explore`` on a viser server: body, ground, traces, AB, forces.

World frame ``frame_id`` of the node (Z up against gravity, m). Everything hangs under the
node ``/world``, which is moved by minus the foot of G on the ground at every frame, so the
body stays in view while the ground slides under it. The body's meshes
(:func:`twodisk_ros.model.mesh.mesh_parts`: the plates of the laminae, or the hull for
``mass_model`` solid) are in the body frame under ``/world/body``, whose pose is the run's
(G and the quaternion body → world). Colours: :mod:`twodisk_ros.model.palette` (disk 1 and A
blue, disk 2 and B orange, AB green, G near-black, forces purple, red when pulling). No
rclpy here.
"""

import math

import numpy as np

from ..model import palette
from ..model.mesh import mesh_parts

__all__ = ['MESH_RESOLUTION', 'Scene3D', 'Traces', 'camera_for', 'rgb255', 'ribbon',
           'simplified', 'wxyz']

#: Rim vertices per disk (and hull steps) of the drawn meshes.
MESH_RESOLUTION = 128
#: Traces: points per chunk; a full chunk is simplified and moved to the finished traces, in
#: groups of TRACE_GROUP chunks (a group's meshes are resent while it fills, never after, and
#: dropped whole when the trace is longer than its length without it).
TRACE_CHUNK, TRACE_GROUP = 64, 4
#: A finished trace node keeps only the points needed to stay within this distance (× body
#: size) of all its samples: about 0.2 px at the default camera on an 800 px high page, and
#: software GL's cost of a frame grows with the segments drawn (docs/benchmarks.md).
TRACE_TOLERANCE = 1e-3
#: Widths (× body size, world units) of the contact segment and of the traces: a trace is a
#: strip of two crossed rectangles (:func:`ribbon`), about 2 px wide at the default camera on
#: an 800 px high page. viser's lines are instanced quads, one instance per segment, and
#: software GL pays for every instance: the traces as lines cost the page most of its frame
#: (docs/benchmarks.md).
SEGMENT_WIDTH, TRACE_WIDTH = 0.015, 0.02
#: Width on screen (px) of the current chunk of a trace, drawn as lines: it is resent at
#: every frame sent, and a line costs the server a quarter of a strip's vertices to build and
#: send (the strips of the finished chunks are sent once a chunk).
TRACE_PX = 2.0
#: The traces' strips run this far (× their width) above the points, so that they stay above
#: the ground (their lower edges 0.35 width below their centre lines).
TRACE_LIFT = 0.4
#: Force arrows: |F| / (M g) × body size long; shaft and head radius, head length (× size).
SHAFT, HEAD, HEAD_LENGTH = 0.008, 0.02, 0.05


def rgb255(colour):
    """(r, g, b) integers 0..255 of a palette colour ``'#rrggbb'``."""
    return tuple(int(round(255 * c)) for c in palette.rgb(colour))


def wxyz(quaternion):
    """viser's (w, x, y, z) of a ROS quaternion (x, y, z, w)."""
    x, y, z, w = (float(c) for c in quaternion)
    return (w, x, y, z)


def camera_for(size):
    """(position, look_at) (m, in the scene after the follow shift) of the default camera:
    3.2 body sizes away, from the side of −y and +x, 35° above the ground."""
    distance = 3.2 * size
    elevation, azimuth = math.radians(35.0), math.radians(-60.0)
    look_at = np.array([0.0, 0.0, 0.4 * size])
    offset = distance * np.array([math.cos(elevation) * math.cos(azimuth),
                                  math.cos(elevation) * math.sin(azimuth), math.sin(elevation)])
    return look_at + offset, look_at


def simplified(points, tolerance):
    """Indices of the points (n, 3) kept by a greedy walk: from a kept point, the next one
    kept is the farthest whose chord (the segment) passes within ``tolerance`` (m) of every
    point between, so a cusp's tip is kept;
    the first and the last points are kept. About 2 ms for a trace node's 64 points."""
    points = np.asarray(points, dtype=float)
    keep, i, n = [0], 0, len(points)
    while i < n - 1:
        j = i + 2
        while j < n:
            chord = points[j] - points[i]
            offsets = points[i + 1:j] - points[i]
            length2 = float(chord @ chord)
            along = (np.clip(offsets @ chord / length2, 0.0, 1.0) if length2 > 0
                     else np.zeros(len(offsets)))          # to the segment, not its line
            if np.max(np.linalg.norm(offsets - along[:, None] * chord, axis=1)) > tolerance:
                break
            j += 1
        i = j - 1
        keep.append(i)
    return np.asarray(keep)


def ribbon(points, normal, width):
    """(vertices (8 (n - 1), 3), faces (4 (n - 1), 3)) of a strip along the polyline
    ``points`` (n, 3) that shows about 0.7 ``width`` wide from any side: each segment is two
    rectangles ``width`` wide crossing on it, at ±45° to the plane of unit ``normal``
    (vertices 8 i + 2 j, 8 i + 2 j + 1 across rectangle j at the segment's start, 8 i + 4 +
    2 j, 8 i + 5 + 2 j at its end: their midpoints are the polyline). A segment along
    ``normal`` or of no length has no width."""
    p = np.asarray(points, dtype=float)
    d = p[1:] - p[:-1]
    side = np.cross(normal, d)
    length = np.linalg.norm(side, axis=1, keepdims=True)
    side = np.divide(side, length, out=np.zeros_like(side), where=length > 0)
    up = np.where(length > 0, np.asarray(normal, dtype=float), 0.0)
    half = 0.5 * width * math.sqrt(0.5)
    across = (half * (side + up), half * (side - up))
    vertices = np.stack([p[:-1] - across[0], p[:-1] + across[0], p[:-1] - across[1],
                         p[:-1] + across[1], p[1:] - across[0], p[1:] + across[0],
                         p[1:] - across[1], p[1:] + across[1]], axis=1)
    k = 8 * np.arange(len(d))[:, None]
    faces = np.concatenate([k + [0, 1, 4], k + [4, 1, 5], k + [2, 3, 6], k + [6, 3, 7]])
    return vertices.reshape(-1, 3), faces


class Traces:
    """Traces of A, B and G in their colours: the current chunk (part ``'now'``, resent at
    every frame: lines, cheap to send) and, as strips (:func:`ribbon`, meshes sent once a
    chunk), the finished chunks of :data:`TRACE_CHUNK` points, simplified,
    in groups of :data:`TRACE_GROUP` (parts ``('done', group)``); the oldest group is dropped
    while the others keep ``length`` points per trace (so up to TRACE_GROUP × TRACE_CHUNK
    more are kept). Software GL pays for every draw call and every line instance
    (docs/benchmarks.md): some 15 meshes draw what took some 45 nodes of line segments, one
    instance per segment."""

    KEYS = (('a', palette.A), ('b', palette.B), ('g', palette.G))

    def __init__(self, scene, size, length, normal=(0.0, 0.0, 1.0)):
        self.scene, self.width = scene, TRACE_WIDTH * size
        self.normal = np.asarray(normal, dtype=float)
        self.lift = TRACE_LIFT * self.width * self.normal
        self.tolerance = TRACE_TOLERANCE * size
        self.length = max(2, int(length))
        self.nodes = []       # [(segments per key, count, group)] finished chunks, oldest first
        self.current = [np.zeros((0, 3)) for _ in self.KEYS]
        self.handles = None   # {part: its meshes, one per trace}
        self.serial = 0

    def clear(self):
        if self.handles is not None:
            for meshes in self.handles.values():
                for h in meshes:
                    h.remove()
        self.nodes, self.handles = [], None
        self.current = [np.zeros((0, 3)) for _ in self.KEYS]

    def extend(self, a, b, g):
        """Append points (n, 3) of A, B and G (m, world) to the current chunk."""
        self.current = [np.concatenate([c, np.asarray(p, dtype=float)])
                        for c, p in zip(self.current, (a, b, g))]

    def _send(self, which, per_key):
        """(Re)send part ``which``: each trace's polyline (segments (k, 2, 3)), the current
        chunk as screen-width lines, a group of finished chunks as a strip."""
        if self.handles is None:
            self.handles = {}
        meshes = []
        for (key, colour), segments in zip(self.KEYS, per_key):
            if which == 'now':
                meshes.append(self.scene.add_line_segments(
                    f'/world/traces/now_{key}', (segments + self.lift).astype(np.float32),
                    rgb255(colour), thickness=TRACE_PX, thickness_units='screen'))
                continue
            points = np.concatenate([segments[:, 0], segments[-1:, 1]]) + self.lift
            vertices, faces = ribbon(points, self.normal, self.width)
            # a node of the same name replaces the old one in the same message
            name = f'done{which[1]}'
            meshes.append(self.scene.add_mesh_simple(
                f'/world/traces/{name}_{key}', vertices.astype(np.float32),
                faces.astype(np.uint32), color=rgb255(colour), side='double',
                cast_shadow=False, receive_shadow=False))
        self.handles[which] = meshes

    def publish(self):
        """Send the current chunk; when it is full, move it (simplified) to the finished
        node, start a new one and drop the oldest chunks."""
        if len(self.current[0]) < 2:
            return
        count = len(self.current[0])
        finished = count >= TRACE_CHUNK
        per_key = []
        for points in self.current:
            if finished:                     # kept for good: only the points needed
                points = points[simplified(points, self.tolerance)]
            per_key.append(np.stack([points[:-1], points[1:]], axis=1))
        if not finished:
            self._send('now', per_key)
            return
        group = self.serial // TRACE_GROUP
        self.nodes.append((per_key, count - 1, group))
        self.serial += 1
        self.current = [c[-1:] for c in self.current]
        kept = sum(node[1] for node in self.nodes)
        while self.nodes[0][2] != group:
            oldest = [node for node in self.nodes if node[2] == self.nodes[0][2]]
            if kept - sum(node[1] for node in oldest) < self.length:
                break
            kept -= sum(node[1] for node in oldest)
            del self.nodes[:len(oldest)]
            for h in self.handles.pop(('done', oldest[0][2])):
                h.remove()
        self._send(('done', group), [np.concatenate([node[0][k] for node in self.nodes
                                                     if node[2] == group])
                                     for k in range(len(self.KEYS))])
        if 'now' in self.handles:            # the finished chunk is in the other part now
            for h in self.handles.pop('now'):
                h.remove()


class Scene3D:
    """The scene nodes of one body on one server (rebuilt when the body changes).

    Parameters
    ----------
    server : viser.ViserServer
    motion : LiveMotion or RecordedMotion
        Its ``body``, ``settings`` (mass_model, slope, path_length) and ``weight``.
    """

    def __init__(self, server, motion):
        self.server, self.scene = server, server.scene
        # software GL draws the environment map and shadow maps 6x slower (docs/benchmarks.md)
        self.scene.configure_environment_map(None)
        self.scene.configure_default_lights(True, cast_shadow=False)
        # without the environment map a face turned from the lights is black: an ambient
        # light keeps both disks' colours on every side
        self.scene.add_light_ambient('/ambient', intensity=1.2)
        self.world = self.scene.add_frame('/world', show_axes=False)
        self.body_node = None
        self.meshes = []
        self.ground, self._ground_key = None, None
        self.contact = self.forces = None
        self.traces = None
        self.rebuild(motion)

    def rebuild(self, motion):
        """Draw a (new) body, its ground and empty traces."""
        s = motion.settings
        self.size, self.weight = float(motion.body.size), float(motion.weight)
        self.normal = motion.ground_normal
        for handle in self.meshes:
            handle.remove()
        if self.body_node is None:
            self.body_node = self.scene.add_frame('/world/body', show_axes=False)
        self.parts = mesh_parts(motion.body, s.mass_model, resolution=MESH_RESOLUTION)
        colours = {'disk_a': palette.A, 'disk_b': palette.B, 'hull': palette.HULL}
        self.meshes = [self.scene.add_mesh_simple(
            f'/world/body/{name}', np.asarray(mesh.vertices, dtype=np.float32),
            np.asarray(mesh.faces, dtype=np.uint32), color=rgb255(colours.get(name, palette.HULL)),
            side='double', cast_shadow=False, receive_shadow=False)
            for name, mesh in self.parts.items()]
        ground = (s.slope, self.size)
        if self.ground is not None and ground != self._ground_key:
            self.ground.remove()
            self.ground = None
        self._ground_key = ground
        half = 0.5 * s.slope
        if self.ground is None:
            self.ground = self.scene.add_grid(
                '/world/ground', width=40 * self.size, height=40 * self.size,
                cell_size=0.25 * self.size, section_size=self.size, infinite_grid=False,
                fade_distance=30 * self.size, wxyz=(math.cos(half), 0.0, math.sin(half), 0.0),
                plane_color=(235, 235, 228), plane_opacity=0.6, shadow_opacity=0.0)
        if self.traces is not None:
            self.traces.clear()
        self.traces = Traces(self.scene, self.size, s.path_length, self.normal)

    def shift(self, position_g):
        """Minus the foot of G on the ground (m): the translation of ``/world``."""
        g = np.asarray(position_g, dtype=float)
        return -(g - float(g @ self.normal) * self.normal)

    def show(self, frame, traces=True):
        """Draw the last sample of a :class:`~twodisk_ros.explore.motion.Frame`; with
        ``traces``, also send the traces (else they are only extended)."""
        i = len(frame) - 1
        g, q = frame.position_g[i], frame.quaternion[i]
        a, b = frame.contact_a[i], frame.contact_b[i]
        with self.server.atomic():
            self.world.position = self.shift(g)
            self.body_node.position = tuple(float(x) for x in g)
            self.body_node.wxyz = wxyz(q)
            segment = np.array([[a, b]], dtype=np.float32)
            if self.contact is None:
                self.contact = self.scene.add_line_segments(
                    '/world/contact', segment, rgb255(palette.AB),
                    thickness=SEGMENT_WIDTH * self.size)
            else:
                self.contact.points = segment
            if frame.force_a is not None:
                self._arrows((a, b), (frame.force_a[i], frame.force_b[i]))
            self.traces.extend(frame.contact_a, frame.contact_b, frame.position_g)
            if traces:
                self.traces.publish()

    def _arrows(self, points, forces):
        scale = self.size / self.weight if self.weight > 0 else 0.0
        ends, colours = [], []
        for point, force in zip(points, forces):
            force = np.asarray(force, dtype=float)
            if not np.all(np.isfinite(force)):
                force = np.zeros(3)
            ends.append([point, np.asarray(point) + scale * force])
            pulling = float(force @ self.normal) < 0
            colours.append(rgb255(palette.FORCE_PULLING if pulling else palette.FORCE))
        ends = np.asarray(ends, dtype=np.float32)
        colours = np.asarray(colours, dtype=np.uint8)
        if self.forces is None:
            self.forces = self.scene.add_arrows(
                '/world/forces', ends, colours, shaft_radius=SHAFT * self.size,
                head_radius=HEAD * self.size, head_length=HEAD_LENGTH * self.size)
        else:
            self.forces.points = ends
            self.forces.colors = colours

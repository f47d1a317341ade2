"""CDR of ``visualization_msgs/msg/MarkerArray`` from arrays, without message objects.

The node's markers (disk outlines and fills, the contact line, force arrows) are plain
geometry: a few hundred points each. Building them as rclpy objects costs a Python object
per point; here each marker is laid out with :class:`~twodisk_ros.io.cdr_layout.Layout` (zero
padding, exact length) and its points are written as one float64 block. The result is
checked byte for byte against :func:`twodisk_ros.io.cdr_generic.serialize` of the same markers in
the tests. Only numpy and the standard library are imported.
"""

from collections import namedtuple
import functools

import numpy as np

from .cdr_layout import ENCAPSULATION, Layout, stamp_columns

__all__ = ['MarkerSpec', 'encode_markers']

#: One marker: namespace, id, type and action (the Marker constants), scale (3,), colour
#: (r, g, b, a), and points (n, 3) in metres in the array's frame; identity pose.
MarkerSpec = namedtuple('MarkerSpec', 'ns id type action scale color points')


def _marker(layout, frame_id, ns, marker_id, count):
    """Append one Marker (Jazzy field order) with ``count`` points to ``layout``."""
    layout.header(frame_id, name=f'stamp{marker_id}')
    layout.string(ns)
    layout.field(f'ints{marker_id}', '<i4', 3)                # id, type, action
    layout.field(f'pose{marker_id}', '<f8', 7)                # position, orientation
    layout.field(f'scale{marker_id}', '<f8', 3)
    layout.field(f'color{marker_id}', '<f4', 4)
    layout.field(f'lifetime{marker_id}', '<i4', 2)            # builtin_interfaces/Duration
    layout.field(f'frame_locked{marker_id}', 'u1')
    layout.u32(count)
    layout.field(f'points{marker_id}', '<f8', 3 * count)
    layout.u32(0)                                             # colors
    layout.string('')                                         # texture_resource
    layout.field(f'texture_stamp{marker_id}', '<i4', 2)       # sensor_msgs/CompressedImage
    layout.string('')                                         # its frame_id
    layout.string('')                                         # format
    layout.u32(0)                                             # data
    layout.u32(0)                                             # uv_coordinates
    layout.string('')                                         # text
    layout.string('')                                         # mesh_resource
    layout.string('')                                         # mesh_file.filename
    layout.u32(0)                                             # mesh_file.data
    layout.field(f'embedded{marker_id}', 'u1')                # mesh_use_embedded_materials


@functools.lru_cache(maxsize=64)
def _layout(frame_id, shape):
    """The layout of a MarkerArray of markers ``shape = ((ns, id, points), ...)``, cached:
    the node's markers keep their structure, only their numbers change."""
    layout = Layout(prefix=ENCAPSULATION)
    layout.u32(len(shape))
    for ns, marker_id, count in shape:
        _marker(layout, frame_id, ns, marker_id, count)
    return layout


def encode_markers(stamp_ns, frame_id, specs):
    """One ``MarkerArray`` (CDR bytes) of the given markers, all stamped ``stamp_ns``.

    Parameters
    ----------
    stamp_ns : int
        Header stamp of every marker, integer nanoseconds.
    frame_id : str
        Header frame id of every marker (the frame of the points).
    specs : sequence of MarkerSpec
        The markers, in order; ids must be distinct.

    Returns
    -------
    bytes
    """
    points = [np.asarray(spec.points, dtype=np.float64).reshape(-1, 3) for spec in specs]
    layout = _layout(frame_id, tuple((spec.ns, spec.id, len(p))
                                     for spec, p in zip(specs, points)))
    stamp = stamp_columns(stamp_ns, 1)
    columns = {}
    for spec, p in zip(specs, points):
        i = spec.id
        columns.update({f'stamp{i}': stamp, f'ints{i}': (i, spec.type, spec.action),
                        f'pose{i}': _IDENTITY, f'scale{i}': spec.scale,
                        f'color{i}': spec.color, f'points{i}': p.reshape(-1)})
    return layout.fill(1, **columns).tobytes()


_IDENTITY = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)   # position, orientation (x, y, z, w)

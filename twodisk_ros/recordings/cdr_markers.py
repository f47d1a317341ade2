"""CDR of ``visualization_msgs/msg/MarkerArray`` from arrays, without message objects.

The node's markers (disk outlines and fills, the contact line, force arrows) are plain
geometry: a few hundred points each. Building them as rclpy objects costs a Python object
per point; here the array is laid out from its message definitions
(:func:`~twodisk_ros.recordings.cdr_schema.message_layout`: zero padding, exact length) and each
marker's points are written as one float64 block. The result is checked byte for byte against
:func:`twodisk_ros.recordings.cdr_generic.serialize` of the same markers in the tests. Only numpy and
the standard library are imported.
"""

from collections import namedtuple
import functools

import numpy as np

from .cdr_layout import stamp_columns
from .cdr_schema import message_layout

__all__ = ['MarkerSpec', 'encode_markers']

MARKER_ARRAY = 'visualization_msgs/msg/MarkerArray'

#: One marker: namespace, id, type and action (the Marker constants), scale (3,), colour
#: (r, g, b, a), and points (n, 3) in metres in the array's frame; identity pose.
MarkerSpec = namedtuple('MarkerSpec', 'ns id type action scale color points')


@functools.lru_cache(maxsize=64)
def _layout(frame_id, shape):
    """The layout of a MarkerArray of markers ``shape = ((ns, id, points), ...)``, from the
    message definitions (cached: the node's markers keep their structure, only their numbers
    change). Every field not set by :func:`encode_markers` keeps its default: identity pose
    (the definition's Quaternion w = 1), no lifetime, empty colours, texture, text and mesh."""
    constants, counts = {}, {'markers': len(shape)}
    for k, (ns, _, count) in enumerate(shape):
        constants[f'markers[{k}].header.frame_id'] = frame_id
        constants[f'markers[{k}].ns'] = ns
        counts[f'markers[{k}].points'] = count
    return message_layout(MARKER_ARRAY, constants, counts)


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
    for k, (spec, p) in enumerate(zip(specs, points)):
        m = f'markers[{k}].'
        columns.update({m + 'header.stamp': stamp, m + 'id': spec.id, m + 'type': spec.type,
                        m + 'action': spec.action, m + 'scale': spec.scale,
                        m + 'color': spec.color})
        if len(p):
            columns[m + 'points'] = p.reshape(-1)
    return layout.fill(1, **columns).tobytes()



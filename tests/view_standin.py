"""Stand-ins for ``twodisk_ros.model.frames`` and ``twodisk_ros.model.mesh`` while they are
not on this branch (another branch writes them); :func:`install` does nothing once they are.

Only their interface matters to ``twodisk-view``: ``disk_frames(body, body_frame)`` →
two objects with ``child_frame_id``, ``translation`` (m) and ``quaternion`` (x, y, z, w,
disk → body), and ``body_mesh(body, mass_model)`` → an object with ``vertices`` (n, 3) m in
the body frame and ``faces`` (m, 3) int.
"""

from dataclasses import dataclass
import importlib
import math
import sys
import types

import numpy as np


@dataclass
class _DiskFrame:
    child_frame_id: str
    translation: np.ndarray
    quaternion: np.ndarray
    parent_frame_id: str


@dataclass
class _Mesh:
    vertices: np.ndarray
    faces: np.ndarray


def _disk_frames(body, body_frame='twodisk_body'):
    half = math.sqrt(0.5)
    return (_DiskFrame(body_frame + '_disk_a', np.array([0.0, -body.delta, 0.0]),
                       np.array([0.0, 0.0, -half, half]), body_frame),
            _DiskFrame(body_frame + '_disk_b', np.array([0.0, body.delta, 0.0]),
                       np.array([-0.5, -0.5, 0.5, 0.5]), body_frame))


def _body_mesh(body, mass_model, resolution=64):
    from scipy.spatial import ConvexHull
    s = np.linspace(0.0, 2.0 * math.pi, resolution, endpoint=False)
    a, b, d = body.a, body.b, body.delta
    rims = np.concatenate([np.stack([b * np.sin(s), -d - a * np.cos(s), 0 * s], -1),
                           np.stack([0 * s, d + a * np.cos(s), b * np.sin(s)], -1)])
    hull = ConvexHull(rims)
    return _Mesh(rims, hull.simplices.astype(np.int64))


def install():
    """Put the stand-ins in ``sys.modules`` if the real modules cannot be imported."""
    for name, attribute, function in (('frames', 'disk_frames', _disk_frames),
                                      ('mesh', 'body_mesh', _body_mesh)):
        full = f'twodisk_ros.model.{name}'
        try:
            importlib.import_module(full)
            continue
        except ImportError:
            pass
        if 'twodisk_ros.model' not in sys.modules:
            sys.modules['twodisk_ros.model'] = types.ModuleType('twodisk_ros.model')
        module = types.ModuleType(full)
        setattr(module, attribute, function)
        sys.modules[full] = module

"""Binary STL of a mesh, and the content-addressed cache the URDF points its viewers to.

Binary STL is the mesh format that both RViz (through its resource retriever and Ogre/assimp
loaders) and Foxglove's 3D panel load from a URDF ``<mesh filename=...>``; it stores float32
coordinates in metres (about 7 significant digits, 6e-8 of the size) and one unit normal per
face. STL carries no colour: the URDF's ``<material>`` gives it.

Where the file lives. The mesh depends on the body's parameters, which change at run time, so
it cannot ship inside the package for a ``package://`` URI (RViz resolves those through the
ament index of an installed package). Instead :func:`cached_stl` writes it once to
``$XDG_CACHE_HOME/twodisk_ros/meshes/<sha256 of the file>.stl`` (``~/.cache/...`` when
``XDG_CACHE_HOME`` is unset, empty or relative, as the XDG base-directory rules say) and the
URDF refers to it by its absolute ``file://`` URI, which RViz and the Foxglove desktop app
open directly on the machine that runs them. The name is the content's hash: the same mesh is
written once and reused by every run and process, a changed body gets a new file (the key is
the mesh itself, so it tells apart every parameter that changes the mesh, the lamina's shape
included: an ellipse and a superellipse of the same a, b, Δ are two files), and an
existing file is never rewritten (its content is its name; nothing the user made is touched,
the cache directory is the package's own). The file is written to a hidden temporary file
beside it and renamed in one step (:func:`twodisk_ros.outputs.temporary_beside`), so a
viewer never reads half a mesh, also when two processes write the same one at once.
"""

import hashlib
import os
from pathlib import Path

import numpy as np

from twodisk_ros.outputs import OutputError, temporary_beside

__all__ = ['stl_bytes', 'cache_directory', 'cached_stl']

_HEADER = b'twodisk_ros body mesh, binary STL, metres, body frame G e1 e2 e3'
_RECORD = np.dtype([('normal', '<f4', (3,)), ('corners', '<f4', (3, 3)),
                    ('attribute', '<u2')])


def stl_bytes(mesh):
    """The binary STL file of ``mesh`` (a :class:`~twodisk_ros.model.mesh.Mesh`), as bytes.

    80-byte header, little-endian uint32 face count, then per face the unit normal and the
    three corners (float32, m, counter-clockwise seen from outside) and a zero uint16.
    """
    records = np.zeros(len(mesh.faces), dtype=_RECORD)
    records['normal'] = mesh.normals
    records['corners'] = mesh.triangles
    header = _HEADER.ljust(80, b' ')
    return header + np.uint32(len(records)).astype('<u4').tobytes() + records.tobytes()


def cache_directory():
    """The mesh cache: ``$XDG_CACHE_HOME/twodisk_ros/meshes``, default ``~/.cache/...``."""
    base = os.environ.get('XDG_CACHE_HOME', '')
    if not base or not os.path.isabs(base):
        base = os.path.join(os.path.expanduser('~'), '.cache')
    return Path(base) / 'twodisk_ros' / 'meshes'


def cached_stl(mesh, directory=None):
    """Path (absolute) of ``mesh``'s binary STL in the cache, written there if missing.

    Parameters
    ----------
    mesh : twodisk_ros.model.mesh.Mesh
    directory : str or os.PathLike, optional
        The cache directory (created with its parents); default :func:`cache_directory`.

    Raises
    ------
    twodisk_ros.outputs.OutputError
        One line, when the directory cannot be created or written.
    """
    data = stl_bytes(mesh)
    directory = Path(cache_directory() if directory is None else directory).absolute()
    path = directory / f'{hashlib.sha256(data).hexdigest()}.stl'
    try:
        if path.is_file() and path.stat().st_size == len(data):
            return path
        directory.mkdir(parents=True, exist_ok=True)
        handle, temporary = temporary_beside(path)
        try:
            with os.fdopen(handle, 'wb') as stream:
                stream.write(data)
            os.replace(temporary, path)
        except BaseException:
            if os.path.exists(temporary):
                os.remove(temporary)
            raise
    except OSError as error:
        raise OutputError(f'{directory}: cannot write the body mesh there '
                          f'({error.strerror or error}); set XDG_CACHE_HOME to a writable '
                          f'directory') from None
    return path

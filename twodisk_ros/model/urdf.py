"""The URDF of the current body, as published on ``robot_description`` (std_msgs/String).

One root link, ``body_frame`` (the body frame G e1 e2 e3 at G, the frame the node broadcasts
on /tf), carries

- ``<inertial>``: the mass model's mass (kg) and its inertia tensor about G (kg m², body
  frame, all six components), at the model's centre of mass (G; the ``solid`` model's
  computed value, zero to rounding). URDF wants the inertia about the centre of mass in the
  frame of ``<origin>`` (rpy 0): that is the mass model's tensor as it is;
- one ``<visual>`` and one ``<collision>`` per mesh part (:func:`~twodisk_ros.model.mesh.
  mesh_parts`): the laminae's plates coloured as disk 1 (blue, contact A) and disk 2
  (orange, contact B), the solid hull grey, each a binary STL referred to by ``file://`` URI
  (:mod:`~twodisk_ros.model.stl` says where the files live and why).

Two child links without geometry, ``{body_frame}_disk_a`` and ``{body_frame}_disk_b``, hang
on fixed joints whose ``<origin>`` is the disk frame of :mod:`~twodisk_ros.model.frames`:
``xyz`` its translation (m), ``rpy`` its rotation as URDF's fixed-axis roll, pitch, yaw
(R = Rz(yaw) Ry(pitch) Rx(roll), rad), read exactly off the 0/±1 rotation matrix. So a
robot_state_publisher fed this URDF would broadcast the same /tf_static as the node.

Numbers are written with Python's shortest round-trip repr, so a parser reads back the
float64 values exactly. (robot_state_publisher's KDL warns that it ignores a root link's
inertia; RViz and Foxglove do not use it. Simulators that need an inertia-free root can add
a dummy parent link.)
"""

import math
from pathlib import Path
from xml.etree import ElementTree

from . import palette

from .frames import check_frame_id, disk_frames
from .mesh import DEFAULT_RESOLUTION, mesh_parts
from .stl import cached_stl

__all__ = ['robot_description', 'body_description', 'mesh_uri', 'rpy', 'PART_COLORS']

#: Colour (#rrggbb, opacity) of each mesh part, as in the package's pictures and markers.
PART_COLORS = {'disk_a': (palette.A, 1.0), 'disk_b': (palette.B, 1.0),
               'hull': (palette.HULL, 1.0), 'body': (palette.HULL, 1.0)}


def _number(value):
    return repr(float(value) + 0.0)     # + 0.0: no '-0.0'


def _triple(values):
    return ' '.join(_number(v) for v in values)


def rpy(axes):
    """URDF (roll, pitch, yaw) (rad) of a 3×3 rotation matrix, R = Rz(yaw) Ry(pitch) Rx(roll).

    Exact for matrices of 0 and ±1 (the disk frames): the angles are atan2 of their entries.
    Away from pitch = ±π/2 (not a disk frame).
    """
    roll = math.atan2(axes[2][1], axes[2][2])
    pitch = math.atan2(-axes[2][0], math.hypot(axes[2][1], axes[2][2]))
    yaw = math.atan2(axes[1][0], axes[0][0])
    return roll, pitch, yaw


def mesh_uri(path):
    """The ``file://`` URI of a mesh file (absolute, percent-encoded where needed)."""
    return Path(path).absolute().as_uri()


def _geometry(parent, uri):
    geometry = ElementTree.SubElement(parent, 'geometry')
    ElementTree.SubElement(geometry, 'mesh', filename=uri)


def robot_description(body, mass, body_frame='twodisk_body', mesh_uris=None, *,
                      robot_name='twodisk'):
    """The URDF (a str, XML with declaration) of ``body`` with the mass properties ``mass``.

    Parameters
    ----------
    body : twodisk_ros.physics.bodies.ellipse.EllipseBody
    mass : twodisk_ros.physics.mass.models.MassProperties
        Mass (kg), centre of mass (m) and inertia about G (kg m²), body frame.
    body_frame : str
        Name of the root link, the body frame (see frames.check_frame_id).
    mesh_uris : str or dict of str to str, optional
        One URI (a single grey visual ``body``), or ``{part: URI}`` with the parts of
        :func:`~twodisk_ros.model.mesh.mesh_parts` (``disk_a``, ``disk_b``, ``hull``), each
        coloured by :data:`PART_COLORS`. None: no visual, no collision.
    robot_name : str
        The ``<robot name=...>``.
    """
    check_frame_id(body_frame)
    if isinstance(mesh_uris, str):
        mesh_uris = {'body': mesh_uris}
    robot = ElementTree.Element('robot', name=str(robot_name))
    link = ElementTree.SubElement(robot, 'link', name=body_frame)
    inertial = ElementTree.SubElement(link, 'inertial')
    ElementTree.SubElement(inertial, 'origin', xyz=_triple(mass.center_of_mass),
                           rpy='0.0 0.0 0.0')
    ElementTree.SubElement(inertial, 'mass', value=_number(mass.mass))
    inertia = mass.inertia
    ElementTree.SubElement(inertial, 'inertia', **{
        f'i{"xyz"[i]}{"xyz"[j]}': _number(inertia[i][j])
        for i, j in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))})
    for part, uri in (mesh_uris or {}).items():
        if part not in PART_COLORS:
            raise ValueError(f'mesh_uris names an unknown part {part!r} (allowed: '
                             f'{", ".join(PART_COLORS)})')
        colour, alpha = PART_COLORS[part]
        visual = ElementTree.SubElement(link, 'visual', name=part)
        ElementTree.SubElement(visual, 'origin', xyz='0.0 0.0 0.0', rpy='0.0 0.0 0.0')
        _geometry(visual, uri)
        material = ElementTree.SubElement(visual, 'material', name=f'{robot_name}_{part}')
        ElementTree.SubElement(material, 'color',
                               rgba=_triple(palette.rgb(colour) + (alpha,)))
        collision = ElementTree.SubElement(link, 'collision', name=part)
        ElementTree.SubElement(collision, 'origin', xyz='0.0 0.0 0.0', rpy='0.0 0.0 0.0')
        _geometry(collision, uri)
    for frame in disk_frames(body, body_frame):
        ElementTree.SubElement(robot, 'link', name=frame.child_frame_id)
        joint = ElementTree.SubElement(robot, 'joint', name=f'{frame.child_frame_id}_joint',
                                       type='fixed')
        ElementTree.SubElement(joint, 'parent', link=body_frame)
        ElementTree.SubElement(joint, 'child', link=frame.child_frame_id)
        ElementTree.SubElement(joint, 'origin', xyz=_triple(frame.translation),
                               rpy=_triple(rpy(frame.axes)))
    ElementTree.indent(robot)
    return '<?xml version="1.0"?>\n' + ElementTree.tostring(robot, encoding='unicode') + '\n'


def body_description(body, mass, body_frame='twodisk_body', *, resolution=DEFAULT_RESOLUTION,
                     thickness=None, directory=None, robot_name='twodisk', uri=mesh_uri):
    """The URDF with meshes: :func:`~twodisk_ros.model.mesh.mesh_parts` for ``mass.model``
    written to the mesh cache (:func:`~twodisk_ros.model.stl.cached_stl`, ``directory``
    overrides it) and referred to by ``uri(path)``, by default the ``file://`` URI (a server
    that hands the files out itself, e.g. to a browser, passes its own). Raises
    :class:`~twodisk_ros.outputs.OutputError` (one line) if the cache cannot be written.
    """
    check_frame_id(body_frame)
    parts = mesh_parts(body, mass, resolution, thickness)
    uris = {part: uri(cached_stl(mesh, directory)) for part, mesh in parts.items()}
    return robot_description(body, mass, body_frame, uris, robot_name=robot_name)

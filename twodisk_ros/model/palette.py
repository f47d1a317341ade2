"""The colours of every picture of the package, defined once (plain hex strings, no imports).

Contact A and disk 1 are blue, contact B and disk 2 orange, the contact line AB green, the
centre of mass G near-black, in the PNG figures (:mod:`~twodisk_ros.plotting.figures`,
:mod:`~twodisk_ros.inspector.figure`), the animations
(:mod:`~twodisk_ros.plotting.animation`) and the RViz/Foxglove markers
(:mod:`twodisk_ros.node.messages`, which must not import matplotlib: hence no matplotlib
here, and :func:`rgb` to turn a colour into the 0..1 floats of ``std_msgs/ColorRGBA``).
Blue and orange stay distinguishable for the common colour-vision deficiencies.
"""

__all__ = ['A', 'B', 'AB', 'G', 'FORCE', 'FORCE_PULLING', 'HULL', 'MU', 'INVALID', 'SLIP',
           'rgb']

#: contact point A, its trace, disk 1 (the disk that touches the ground at A)
A = '#1f5fa8'
#: contact point B, its trace, disk 2
B = '#d9622b'
#: the contact line (segment) AB
AB = '#1b8a3a'
#: the centre of mass G and its path
G = '#262626'
#: ground forces on the body (arrows)
FORCE = '#7b2d8e'
#: a ground force that would have to pull the body down (N < 0: the contact lifts off)
FORCE_PULLING = '#d7191c'
#: the convex hull of the two disks (markers)
HULL = '#999a9e'
#: the friction needed, μ_required, and the friction available μ
MU = '#2a9d8f'
#: shading of the stretches where the rolling model does not hold: a contact lifts off
INVALID = '#f4a6a6'
#: ... the body slips (μ_required > μ) with both contacts on the ground
SLIP = '#f6d38b'


def rgb(colour):
    """(r, g, b) floats in [0, 1] of a ``'#rrggbb'`` colour."""
    text = colour.lstrip('#')
    if len(text) != 6:
        raise ValueError(f'expected a colour #rrggbb, got {colour!r}')
    return tuple(int(text[k:k + 2], 16) / 255.0 for k in (0, 2, 4))

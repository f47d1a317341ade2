"""Two congruent laminae of any shape as a :class:`~twodisk_ros.physics.rolling_body.RollingBody`.

Placeholder: the class, its constructor's signature and its attributes are fixed (the node,
mass models, drawing and sweeps are written against them); the implementation is issue 20's
next step.
"""

from .general_body import ARRANGEMENTS
from .rolling_body import RollingBody

__all__ = ['LaminaBody']


class LaminaBody(RollingBody):
    """Two congruent convex laminae in perpendicular planes, centres at ∓Δ along e2.

    Parameters
    ----------
    lamina : Lamina
        The shape of both disks (lamina.py).
    delta : float
        Half the distance between the centres (m) (limits as in
        :class:`~twodisk_ros.physics.general_body.GeneralTwoDiskBody`).
    arrangement : str
        'parallel' (default) or 'swapped' (general_body.py).
    """

    def __init__(self, lamina, delta, arrangement='parallel'):
        if arrangement not in ARRANGEMENTS:
            raise ValueError(f'arrangement must be one of {sorted(ARRANGEMENTS)}, '
                             f'got {arrangement!r}')
        raise NotImplementedError('LaminaBody is not implemented yet')

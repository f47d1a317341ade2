"""The lamina a run's settings name: ``shape``, ``exponent``, ``egg_asymmetry``, ``shape_file``.

ROS-free and lazy-free: :mod:`twodisk_ros.run.parameters` checks settings with it, the run
description (:mod:`~twodisk_ros.run.description`) builds the body on it. Settings are read by
attribute (any object with the parameter names: ``RollerSettings`` in practice).

- ``ellipse``: :class:`~twodisk_ros.physics.laminae.shapes.Ellipse` (a, b); the body is
  :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody` (closed forms);
- ``superellipse``: :class:`~twodisk_ros.physics.laminae.shapes.Superellipse` (a, b, ``exponent``);
- ``egg``: :class:`~twodisk_ros.physics.laminae.support.Egg` (a, b, ε) with
  ε = ``egg_asymmetry`` × ε_max(a, b) (m): ``egg_asymmetry`` is dimensionless, |·| ≤
  :data:`EGG_ASYMMETRY`, so that the radius of curvature stays ≥ (1 − |egg_asymmetry|) times
  the ellipse's at every normal angle (the egg's radius is ρ_E − 8ε cos 3φ and ε_max is the
  least ρ_E / (8 cos 3φ)); > 0 makes the lamina's −y end (disk 1's outer end) the sharper;
- ``points``: an :class:`~twodisk_ros.physics.laminae.fit.Outline` fitted to the points of
  ``shape_file`` (CSV or YAML, :func:`~twodisk_ros.physics.laminae.fit.read_outline`), in metres;
  a and b are then the outline's own half length along the common axis and half width
  (:func:`axes_of`), and the parameters ``a`` and ``b`` are not used. A recording keeps the
  fitted outline's coefficients (:func:`outline_metadata`), so the recording is checked
  without the file.

Every refusal is a one-line ValueError naming the parameter or the file.
"""

from functools import lru_cache
import json
import math
import os
import stat

from ..physics.bodies.ellipse import EllipseBody
from ..physics.bodies.contact_solver import ContactSolver
from ..physics.laminae.shapes import Ellipse, Superellipse
from ..physics.laminae.support import Egg
from ..physics.laminae.fit import Outline, read_outline

__all__ = ['ARRANGEMENT_NAMES', 'EGG_ASYMMETRY', 'MAX_SHAPE_FILE_BYTES', 'OUTLINE_KEYS',
           'SHAPES', 'axes_of', 'clear_caches', 'describe_shape', 'lamina_of',
           'outline_from_metadata', 'outline_metadata', 'read_shape_file', 'shape_key',
           'theta_max_of']

SHAPES = ('ellipse', 'superellipse', 'egg', 'points')
ARRANGEMENT_NAMES = ('parallel', 'swapped')
#: Largest |egg_asymmetry|: the egg's radius of curvature stays ≥ 5 % of the ellipse's.
EGG_ASYMMETRY = 0.95
#: Largest shape file read (bytes): laminae.fit accepts at most 20 000 points (~ 1 MB of text).
MAX_SHAPE_FILE_BYTES = 4 << 20
#: Most coefficients accepted from a recording (the fit uses at most 129).
MAX_COEFFICIENTS = 1024
#: Keys of the recording's metadata that hold a ``points`` run's fitted outline.
OUTLINE_KEYS = ('outline', 'outline_fit_error', 'outline_points', 'outline_axis_offset')


def shape_key(settings, outline=None):
    """A hashable key of the lamina the settings name (equal keys, equal laminae).

    A ``points`` lamina is keyed by the file's identity (path, device, inode, size, mtime),
    so an edited file is read again; or by ``outline``'s coefficients when one is given.
    """
    s = settings
    if s.shape == 'ellipse':
        return ('ellipse', s.a, s.b)
    if s.shape == 'superellipse':
        return ('superellipse', s.a, s.b, s.exponent)
    if s.shape == 'egg':
        return ('egg', s.a, s.b, s.egg_asymmetry)
    if s.shape != 'points':
        raise ValueError(f'shape must be one of {", ".join(SHAPES)}, got {s.shape!r}')
    if outline is not None:
        return ('outline', tuple(float(c) for c in outline.coefficients))
    return ('points',) + _file_identity(s.shape_file)


def lamina_of(settings, outline=None):
    """The :class:`~twodisk_ros.physics.laminae.shapes.Lamina` of the settings (cached by its key).

    ``outline``: for ``points``, an :class:`Outline` to use instead of reading
    ``shape_file`` (a recording's). Raises ValueError (one line).
    """
    key = shape_key(settings, outline)
    if key[0] == 'outline':
        return outline
    return _lamina(key, settings.shape_file if key[0] == 'points' else '')


@lru_cache(maxsize=16)
def _lamina(key, path):
    kind = key[0]
    if kind == 'ellipse':
        return Ellipse(key[1], key[2])
    if kind == 'superellipse':
        return Superellipse(key[1], key[2], key[3])
    if kind == 'egg':
        a, b, asymmetry = key[1:]
        if not (math.isfinite(asymmetry) and abs(asymmetry) <= EGG_ASYMMETRY):
            raise ValueError(f'egg_asymmetry must satisfy -{EGG_ASYMMETRY:g} <= egg_asymmetry '
                             f'<= {EGG_ASYMMETRY:g}, got {asymmetry!r}')
        return Egg(a, b, asymmetry * Egg.epsilon_max(a, b))
    return _fit_file(path)


def _file_identity(path):
    """(path, device, inode, size, mtime_ns) of a regular shape file, or ValueError."""
    if not isinstance(path, str) or not path:
        raise ValueError("shape_file must name a CSV or YAML outline file when shape is "
                         "points (x, y in metres per point, in order around the outline), "
                         f"got {path!r}")
    shown = _shown(path)
    try:
        info = os.stat(path)
    except (OSError, ValueError) as error:
        reason = error.strerror if isinstance(error, OSError) and error.strerror else 'invalid'
        raise ValueError(f'shape_file {shown}: cannot be read ({reason})') from None
    if stat.S_ISDIR(info.st_mode):
        raise ValueError(f'shape_file {shown}: is a directory, not a CSV or YAML outline file')
    if not stat.S_ISREG(info.st_mode):
        raise ValueError(f'shape_file {shown}: not a regular file (a pipe or a device is not '
                         'read)')
    if info.st_size > MAX_SHAPE_FILE_BYTES:
        raise ValueError(f'shape_file {shown}: {info.st_size} bytes, more than the '
                         f'{MAX_SHAPE_FILE_BYTES} bytes an outline file may have')
    return (path, info.st_dev, info.st_ino, info.st_size, info.st_mtime_ns)


def _shown(path, limit=160):
    text = repr(str(path))[1:-1]
    return text if len(text) <= limit else text[:limit - 3] + '...'


def read_shape_file(path):
    """The :class:`Outline` fitted to the points of ``path`` (checked, not cached).

    Raises ValueError with one line naming the file and the problem.
    """
    _file_identity(path)
    return _fit_file(path)


def _fit_file(path):
    shown = _shown(path)
    try:
        points = read_outline(path)
    except ValueError as error:
        text = ' '.join(str(error).split())
        prefix = f'outline file {path}: '
        text = text[len(prefix):] if text.startswith(prefix) else text
        raise ValueError(f'shape_file {shown}: {text}') from None
    try:
        return Outline.from_points(points)
    except ValueError as error:
        raise ValueError(f'shape_file {shown}: {" ".join(str(error).split())}') from None


def axes_of(lamina):
    """(a, b) (m) of a lamina: half its length along the common axis, its half width.

    The ellipse's, superellipse's and egg's own a and b (the egg's ends are at −(a + ε) and
    a − ε); for an outline, what its points give.
    """
    x_max, y_min, y_max = lamina.extents
    return 0.5 * (y_max - y_min), x_max


@lru_cache(maxsize=32)
def _general(lamina, delta, arrangement):
    return ContactSolver(lamina, delta, arrangement)


def clear_caches():
    """Forget the cached laminae (files are read again) and general bodies."""
    _lamina.cache_clear()
    _general.cache_clear()


def theta_max_of(settings, lamina):
    """θ_max (rad) of the body the settings describe, made of ``lamina`` (their lamina,
    :func:`lamina_of`): ValueError if the laminae at Δ in the arrangement have no cycle.

    Only the contact geometry is built (not a rolling body's tables): for ``shape`` ellipse
    the closed form of :class:`~twodisk_ros.physics.bodies.ellipse.EllipseBody` (both
    arrangements are the same body), for the others the
    :class:`~twodisk_ros.physics.bodies.contact_solver.ContactSolver` of the lamina.
    """
    s = settings
    if s.shape == 'ellipse':
        return EllipseBody(s.a, s.b, s.delta).theta_max
    return _general(lamina, s.delta, s.arrangement).theta_max


def describe_shape(settings, lamina):
    """One line on the lamina, for logs and reports: ``superellipse a = 0.1 m, ...``."""
    s = settings
    if s.shape == 'ellipse':
        text = f'ellipse a = {s.a:g} m, b = {s.b:g} m'
    elif s.shape == 'superellipse':
        text = f'superellipse a = {s.a:g} m, b = {s.b:g} m, exponent {s.exponent:g}'
    elif s.shape == 'egg':
        text = (f'egg a = {s.a:g} m, b = {s.b:g} m, epsilon = {lamina.epsilon:.6g} m '
                f'(egg_asymmetry {s.egg_asymmetry:g})')
    else:
        a, b = axes_of(lamina)
        fit = (f', fit error {lamina.fit_error:.3g} m' if lamina.fit_error is not None
               else '')
        text = (f'outline of {lamina.coefficients.size - 1} harmonics, a = {a:.6g} m, '
                f'b = {b:.6g} m{fit}')
    arrangement = '' if s.shape == 'ellipse' else f', {s.arrangement}'
    return f'{text}, delta = {s.delta:g} m{arrangement}'


# -- the fitted outline in a recording's metadata (text, exact round trip) ------------------
def outline_metadata(lamina):
    """{key: text} of a fitted outline for the recording's metadata (:data:`OUTLINE_KEYS`).

    The coefficients (m) are written with 17 significant digits, so they read back exactly.
    """
    values = {'outline': json.dumps([float(c) for c in lamina.coefficients])}
    if lamina.fit_error is not None:
        values['outline_fit_error'] = repr(float(lamina.fit_error))
    values['outline_points'] = str(int(lamina.point_count))
    values['outline_axis_offset'] = repr(float(lamina.axis_offset))
    return values


def outline_from_metadata(strings):
    """The :class:`Outline` a recording's metadata holds, or ValueError (one line)."""
    text = strings.get('outline')
    if text is None:
        raise ValueError('parameter outline is missing: a run with shape points records its '
                         'fitted outline (the coefficients c_0 ... c_M in metres)')
    try:
        values = json.loads(text) if len(text) <= 64 * MAX_COEFFICIENTS else None
    except ValueError:
        values = None
    if not (isinstance(values, list) and 1 <= len(values) <= MAX_COEFFICIENTS and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)):
        raise ValueError(f'outline must be a list of 1 to {MAX_COEFFICIENTS} numbers (the '
                         f'coefficients in metres), got {_shown(text, 80)!r}')
    outline = Outline(values)          # ValueError (one line) unless finite and convex
    try:
        if 'outline_fit_error' in strings:
            outline.fit_error = float(strings['outline_fit_error'])
        outline.point_count = int(strings.get('outline_points', '0'))
        outline.axis_offset = float(strings.get('outline_axis_offset', '0'))
    except ValueError:
        raise ValueError('outline_fit_error, outline_points and outline_axis_offset must be '
                         'numbers') from None
    return outline

"""Animations of a rolling run: GIF (Pillow) or MP4 (ffmpeg), in 3D or seen from above.

Each frame shows the body as its two filled laminae (disk 1 blue, disk 2 orange; the real
outline of ``run.body.lamina``, :mod:`~twodisk_ros.physics.bodies.outline`), the
contact segment AB (green), the traces of A and B so far on the ground, the path of G and,
optionally, the ground forces on the body at A and B as arrows (length L for M g, L the
body size). A run on a slope (``run.slope`` β ≠ 0) draws its ground: in 3D the plane
through the origin with normal (sin β, 0, cos β), going down along +X, as a gridded quad
under the view (:attr:`_Scene.ground_quad`); seen from above, a note on the slope. :func:`animate` renders a :class:`~twodisk_ros.runs.Run` (or the
node's settings, simulated on the fly); the command line is
:mod:`twodisk_ros.plotting.animate_cli` (``twodisk-animate``,
``python -m twodisk_ros.plotting.animation``).
"""

import math
import os
import shutil
import textwrap

import numpy as np

from ..model import palette
from .frames import gif_frame as _gif_frame, one_palette as _one_palette, render as _render
from ..runs import Run, RunError, library_run

__all__ = ['VIEWS', 'CAMERAS', 'animate', 'drawn', 'frame_times', 'still']

VIEWS = ('3d', 'top')
CAMERAS = ('auto', 'follow', 'fit')
COLOR_1, COLOR_2 = palette.A, palette.B        # disk 1 / trace of A, disk 2 / trace of B
COLOR_AB, COLOR_G, COLOR_FORCE = palette.AB, palette.G, palette.FORCE
COLOR_GROUND = (0.93, 0.93, 0.90, 1.0)          # the ground pane (flat) or quad (slope)
DPI = 100


def frame_times(start, stop, fps):
    """Times of the frames (s): start, start + 1/fps, ... up to stop (at least one frame)."""
    count = int(math.floor((stop - start) * fps + 1e-9)) + 1
    return start + np.arange(count) / fps


def _check_span(run, start, stop, fps):
    for name, value in (('start', start), ('stop', stop), ('fps', fps)):
        if not isinstance(value, (int, float)) or not math.isfinite(value):
            raise RunError(f'{name} must be a finite number, got {value!r}')
    if fps <= 0 or fps > 120:
        raise RunError(f'fps must be in (0, 120], got {fps!r}')
    if start < 0 or stop <= start:
        raise RunError(f'the span must satisfy 0 <= start < stop, got start = {start!r} s, '
                       f'stop = {stop!r} s')
    if stop > run.t[-1] + 1e-6:
        raise RunError(f'the span ends at {stop:g} s but the run ends at {run.t[-1]:.6g} s')


def _output_kind(path):
    """'gif' or 'mp4' from the suffix; RunError (one line) if it cannot be written."""
    path = os.fspath(path)
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in ('.gif', '.mp4'):
        raise RunError(f'cannot write {path}: the file name must end in .gif or .mp4')
    if suffix == '.mp4' and shutil.which('ffmpeg') is None:
        raise RunError(f'cannot write {path}: MP4 needs ffmpeg, which is not installed '
                       '(write a .gif instead)')
    parent = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise RunError(f'cannot write {path}: it is a directory')
    if not os.path.isdir(parent):
        raise RunError(f'cannot write {path}: directory {parent} does not exist')
    if not os.access(parent, os.W_OK) or (os.path.exists(path) and not os.access(path, os.W_OK)):
        raise RunError(f'cannot write {path}: permission denied')
    return suffix[1:]


def _halves(disk1, disk2, centre1, centre2):
    """Four half-disk polygons cut along the common axis (depth sorting copes with them)."""
    halves = []
    for outline, centre, colour in ((disk1, centre1, COLOR_1), (disk2, centre2, COLOR_2)):
        n = len(outline) - 1
        half = n // 2
        for part in (outline[:half + 1], outline[half:]):
            # close each half along the axis, through the disk centre
            halves.append((np.vstack([part, centre]), colour))
    return halves


class _Scene:
    """Artists of one animation, updated frame by frame."""

    def __init__(self, run, figure, view, camera, forces, frames):
        self.run, self.figure, self.view, self.forces = run, figure, view, forces
        self.frames = frames                       # sample index of each frame
        size = run.body.size
        self.size = size
        self.arrow_scale = size / run.weight if run.weight > 0 else 0.0
        xy = np.concatenate([run.contact_a[:, :2], run.contact_b[:, :2],
                             run.position_g[:, :2]])
        extent = np.ptp(xy, axis=0).max()
        if camera == 'auto':
            camera = 'fit' if extent <= 6.0 * size else 'follow'
        self.camera = camera
        self.low = xy.min(axis=0) - 0.9 * size
        self.high = xy.max(axis=0) + 0.9 * size
        self.half = 1.9 * size                      # half width of a following window
        self.slope = float(run.slope)
        # the body's highest point above the ground, along Z (m)
        self.rise = float(np.max(run.position_g @ run.ground_normal)) / math.cos(
            self.slope) + size
        self.ground_quad = None                    # (4, 3) corners of the drawn ground (m)
        fontsize = max(6.0, min(11.0, figure.get_figheight() * 2.3))
        self.fontsize = fontsize
        # the legend is read at the size of the picture: at least 8 px (6 pt at 100 dpi) high
        self.legend_fontsize = max(0.85 * fontsize, 8.0 * 72.0 / figure.dpi)
        if view == '3d':
            self._setup_3d()
        else:
            self._setup_top()
        # the title, wrapped to the figure's width (a character ≈ 0.55 em wide)
        chars = int(figure.get_figwidth() * 72.0 / (0.55 * 0.75 * fontsize))
        figure.text(0.5, 0.985, textwrap.fill(run.label, max(20, chars)), ha='center',
                    va='top', fontsize=fontsize * 0.75, color='0.3')
        self.clock = figure.text(0.03, 0.93, '', ha='left', va='top', fontsize=fontsize,
                                 family='monospace')
        self._legend()
        self.background = None                     # the still parts, once drawn (blitting)
        self.overlays = []                         # still artists drawn over moving ones

    # -- set-up -------------------------------------------------------------------------------
    def _setup_3d(self):
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection
        import matplotlib
        with matplotlib.rc_context({'grid.color': '0.86', 'grid.linewidth': 0.5}):
            ax = self.ax = self.figure.add_axes((-0.04, 0.13, 1.08, 0.82), projection='3d')
        ax.view_init(elev=24, azim=-58)
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.pane.set_facecolor((0.95, 0.95, 0.93, 1.0))
            axis.pane.set_edgecolor('0.8')
        ax.xaxis.pane.set_facecolor((1, 1, 1, 0))
        ax.yaxis.pane.set_facecolor((1, 1, 1, 0))
        ax.zaxis.pane.set_facecolor(COLOR_GROUND if not self.slope else (1, 1, 1, 0))
        ax.tick_params(labelsize=self.fontsize * 0.7, pad=0)
        ax.set_xlabel('X (m)', fontsize=self.fontsize * 0.8, labelpad=-4)
        ax.set_ylabel('Y (m)', fontsize=self.fontsize * 0.8, labelpad=-4)
        ax.set_zticks([])
        self.polys = Poly3DCollection([], linewidths=0.8, alpha=None)
        if self.slope:
            # the sloped ground: a quad under everything (drawn in this order: the ground is
            # below the body seen from any of these elevations)
            from mpl_toolkits.mplot3d.art3d import Line3DCollection
            ax.computed_zorder = False
            self.ground = Poly3DCollection([], facecolor=COLOR_GROUND, edgecolor='0.7',
                                           linewidths=0.6, zorder=0)
            self.ground_grid = Line3DCollection([], colors='0.8', linewidths=0.5, zorder=0.5)
            ax.add_collection3d(self.ground, autolim=False)
            ax.add_collection3d(self.ground_grid, autolim=False)
            self.polys.set_zorder(2)
        ax.add_collection3d(self.polys)
        self.trace_a, = ax.plot([], [], [], color=COLOR_1, lw=1.1)
        self.trace_b, = ax.plot([], [], [], color=COLOR_2, lw=1.1)
        self.path_g, = ax.plot([], [], [], color=COLOR_G, lw=0.8, ls='--')
        self.segment, = ax.plot([], [], [], color=COLOR_AB, lw=2.2, marker='o', ms=2.5)
        self.centre, = ax.plot([], [], [], 'o', color=COLOR_G, ms=3)
        self.arrows = []
        if self.slope:
            for k, line in enumerate((self.trace_a, self.trace_b, self.path_g, self.segment,
                                      self.centre)):
                line.set_zorder(1 if k < 2 else 3)
        if self.camera == 'fit':
            self._limits_3d(self.low, self.high)

    def _limits_3d(self, low, high):
        """Limits around [low, high] (X, Y) and from the ground's lowest point there to the
        body's highest above it; on a slope the ground quad is moved to this window."""
        ax = self.ax
        ground = self.run.ground_height([low[0], high[0]])
        bottom, top = float(ground.min()), float(ground.max()) + self.rise
        ax.set_xlim(low[0], high[0])
        ax.set_ylim(low[1], high[1])
        ax.set_zlim(bottom, top)
        ax.set_box_aspect((high[0] - low[0], high[1] - low[1], top - bottom), zoom=1.3)
        if self.slope:
            x = np.array([low[0], high[0], high[0], low[0]])
            y = np.array([low[1], low[1], high[1], high[1]])
            self.ground_quad = np.stack([x, y, self.run.ground_height(x)], axis=-1)
            self.ground.set_verts([self.ground_quad])
            lines = []
            for f in np.linspace(0.0, 1.0, 7)[1:-1]:
                xf = low[0] + f * (high[0] - low[0])     # level lines (across the slope)
                yf = low[1] + f * (high[1] - low[1])     # fall lines (downhill)
                lines.append([(xf, low[1], self.run.ground_height(xf)),
                              (xf, high[1], self.run.ground_height(xf))])
                lines.append([(low[0], yf, self.run.ground_height(low[0])),
                              (high[0], yf, self.run.ground_height(high[0]))])
            self.ground_grid.set_segments(lines)

    def _setup_top(self):
        ax = self.ax = self.figure.add_axes((0.1, 0.2, 0.86, 0.7))
        ax.set_aspect('equal', adjustable='box')
        ax.set_facecolor((0.96, 0.96, 0.94))
        ax.grid(True, color='white', lw=0.8)
        ax.tick_params(labelsize=self.fontsize * 0.75, direction='in')
        ax.set_xlabel('X (m)', fontsize=self.fontsize * 0.85)
        ax.set_ylabel('Y (m)', fontsize=self.fontsize * 0.85)
        self.patches = []
        self.trace_a, = ax.plot([], [], color=COLOR_1, lw=1.2, zorder=2)
        self.trace_b, = ax.plot([], [], color=COLOR_2, lw=1.2, zorder=2)
        self.path_g, = ax.plot([], [], color=COLOR_G, lw=0.8, ls='--', zorder=2)
        self.segment, = ax.plot([], [], color=COLOR_AB, lw=2.0, marker='o', ms=3, zorder=6)
        self.centre, = ax.plot([], [], 'o', color=COLOR_G, ms=3, zorder=7)
        self.arrows = []
        if self.slope:
            ax.text(0.98, 0.97, f'ground down along +X at {math.degrees(self.slope):.3g}° '
                    f'(Z = −X tan β)', transform=ax.transAxes, ha='right', va='top',
                    fontsize=self.fontsize * 0.7, color='0.35', zorder=9)
        if self.camera == 'fit':
            self._limits_top(self.low, self.high)

    def _limits_top(self, low, high):
        """Limits around [low, high] with the shape of the axes (equal scales, no warning)."""
        box = self.ax.get_position(original=True)
        shape = (box.height * self.figure.get_figheight()) / (
            box.width * self.figure.get_figwidth())
        centre, span = 0.5 * (low + high), high - low
        width = max(span[0], span[1] / shape)
        self.ax.set_xlim(centre[0] - 0.5 * width, centre[0] + 0.5 * width)
        self.ax.set_ylim(centre[1] - 0.5 * width * shape, centre[1] + 0.5 * width * shape)

    def _legend(self):
        """One short legend below the view; its font grows with the figure (≥ 8 px high)."""
        from matplotlib.legend_handler import HandlerTuple
        from matplotlib.lines import Line2D
        from matplotlib.patches import Patch
        handles = [(Patch(fc=COLOR_1, alpha=0.6), Line2D([], [], color=COLOR_1)),
                   (Patch(fc=COLOR_2, alpha=0.6), Line2D([], [], color=COLOR_2)),
                   Line2D([], [], color=COLOR_AB, lw=2),
                   Line2D([], [], color=COLOR_G, ls='--', lw=0.8)]
        labels = ['disk 1, trace of A', 'disk 2, trace of B', 'contact line AB', 'path of G']
        if self.slope:
            handles.append(Patch(fc=COLOR_GROUND, ec='0.6'))
            labels.append(f'ground, slope {math.degrees(self.slope):.3g}°')
        if self.forces:
            handles.append(Line2D([], [], color=COLOR_FORCE, lw=1.5))
            labels.append('ground force (L ≙ Mg)' if self.view == '3d'
                          else 'ground force, horizontal')
        self.figure.legend(handles, labels, loc='lower center', ncol=3,
                           fontsize=self.legend_fontsize, frameon=False,
                           bbox_to_anchor=(0.5, 0.0), handlelength=2.2, columnspacing=1.2,
                           handletextpad=0.5, borderaxespad=0.2,
                           handler_map={tuple: HandlerTuple(ndivide=None, pad=0.2)})

    # -- one frame ---------------------------------------------------------------------------
    def draw(self, frame):
        run = self.run
        i = self.frames[frame]
        disk1, disk2 = run.outlines(i)
        centre1, centre2 = disk1[:-1].mean(axis=0), disk2[:-1].mean(axis=0)
        self.halves = halves = _halves(disk1, disk2, centre1, centre2)  # as drawn (m)
        a, b, g = run.contact_a[: i + 1], run.contact_b[: i + 1], run.position_g[: i + 1]
        if self.camera == 'follow':
            self.window = (g[-1, :2] - self.half, g[-1, :2] + self.half)
        for line, data in ((self.trace_a, a), (self.trace_b, b)):
            data = self._clipped(data)
            self._set_line(line, data[:, 0], data[:, 1], data[:, 2])
        clipped = self._clipped(g)
        self._set_line(self.path_g, clipped[:, 0], clipped[:, 1], clipped[:, 2])
        self._set_line(self.segment, [a[-1, 0], b[-1, 0]], [a[-1, 1], b[-1, 1]],
                       [a[-1, 2], b[-1, 2]])
        self._set_line(self.centre, g[-1:, 0], g[-1:, 1], g[-1:, 2])
        for arrow in self.arrows:
            arrow.remove()
        self.arrows = []
        if self.view == '3d':
            self._draw_3d(halves, i)
        else:
            self._draw_top(halves, i)
        self.clock.set_text(f't = {run.t[i]:5.2f} s')

    def _clipped(self, points):
        """Points outside a following 3D window become NaN (mplot3d does not clip lines)."""
        if self.view != '3d' or self.camera != 'follow':
            return points
        low, high = self.window
        inside = np.all((points[:, :2] >= low) & (points[:, :2] <= high), axis=1)
        return np.where(inside[:, None], points, np.nan)

    def _set_line(self, line, x, y, z):
        if self.view == '3d':
            line.set_data_3d(np.asarray(x), np.asarray(y), np.asarray(z))
        else:
            line.set_data(np.asarray(x), np.asarray(y))

    def _draw_3d(self, halves, i):
        from matplotlib.colors import to_rgba
        self.polys.set_verts([poly for poly, _ in halves])
        self.polys.set_facecolor([to_rgba(colour, 0.55) for _, colour in halves])
        self.polys.set_edgecolor([to_rgba(colour, 0.95) for _, colour in halves])
        if self.camera == 'follow':
            self._limits_3d(*self.window)
        if self.forces and self.run.force_a is not None:
            for point, force in ((self.run.contact_a[i], self.run.force_a[i]),
                                 (self.run.contact_b[i], self.run.force_b[i])):
                v = force * self.arrow_scale
                self.arrows.append(self.ax.quiver(*point, *v, color=COLOR_FORCE, lw=1.6,
                                                  arrow_length_ratio=0.18))

    def _draw_top(self, halves, i):
        from matplotlib.patches import Polygon
        for patch in self.patches:
            patch.remove()
        self.patches = []
        # seen from above: the higher half-disks are drawn last
        for k, (poly, colour) in enumerate(sorted(halves, key=lambda h: h[0][:, 2].mean())):
            self.patches.append(self.ax.add_patch(Polygon(
                poly[:, :2], closed=True, fc=colour, ec=colour, alpha=0.5, lw=0.8,
                zorder=3 + 0.1 * k)))
        if self.camera == 'follow':
            g = self.run.position_g[i]
            self._limits_top(g[:2] - self.half, g[:2] + self.half)
        if self.forces and self.run.force_a is not None:
            for point, force in ((self.run.contact_a[i], self.run.force_a[i]),
                                 (self.run.contact_b[i], self.run.force_b[i])):
                v = force[:2] * self.arrow_scale
                self.arrows.append(self.ax.annotate(
                    '', xy=tuple(point[:2] + v), xytext=tuple(point[:2]), zorder=8,
                    arrowprops=dict(arrowstyle='-|>', color=COLOR_FORCE, lw=1.5)))


def _check_view(view, camera):
    if view not in VIEWS:
        raise RunError(f'view must be one of {", ".join(VIEWS)}, got {view!r}')
    if camera not in CAMERAS:
        raise RunError(f'camera must be one of {", ".join(CAMERAS)}, got {camera!r}')


def _figure(size):
    """A white Agg figure of ``size`` (w, h) pixels, rounded up to even numbers."""
    width, height = (int(x) for x in size)
    if not (64 <= width <= 4096 and 64 <= height <= 4096):
        raise RunError(f'size must be between 64x64 and 4096x4096 pixels, got {width}x{height}')
    width, height = width + width % 2, height + height % 2
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    figure = Figure(figsize=(width / DPI, height / DPI), dpi=DPI, facecolor='white')
    FigureCanvasAgg(figure)
    return figure


def animate(run, path, *, start=0.0, stop=None, fps=15.0, view='3d', size=(640, 480),
            forces=False, camera='auto'):
    """Render a run as an animated GIF or MP4 (chosen by the suffix of ``path``).

    Parameters
    ----------
    run : Run or RollerSettings
        A sampled run (:func:`~twodisk_ros.runs.library_run`,
        :func:`~twodisk_ros.runs.recorded_run`), or the node's settings, then
        simulated over [0, stop].
    path : str or os.PathLike
        ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).
    start, stop : float
        The span shown (s); ``stop`` defaults to the end of the run (6 s for settings).
    fps : float
        Frames per second of simulated time (the animation plays in real time).
    view : {'3d', 'top'}
        A 3D view, or the ground seen from above.
    size : (int, int)
        Width and height in pixels (rounded to even numbers).
    forces : bool
        Draw the ground forces at A and B (a run without forces draws none).
    camera : {'auto', 'follow', 'fit'}
        Follow G, or fit the whole span; 'auto' fits spans shorter than ~6 body sizes.

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    RunError
        One line, for a bad span, view, size or an unwritable output.
    """
    _check_view(view, camera)
    kind = _output_kind(path)
    if not isinstance(run, Run):
        run = library_run(run, stop=6.0 if stop is None else stop, forces=forces)
    stop = float(run.t[-1]) if stop is None else stop
    _check_span(run, start, stop, fps)
    times = frame_times(start, stop, fps)
    shown = run.span(start, stop)
    frames = np.clip(np.searchsorted(shown.t, times - 1e-9), 0, len(shown) - 1)
    figure = _figure(size)
    scene = _Scene(shown, figure, view, camera, forces and shown.force_a is not None, frames)
    try:
        if kind == 'gif':
            # as matplotlib's PillowWriter, with each frame drawn by _render, in one palette
            pixels = tuple(int(x) for x in figure.canvas.get_width_height())
            images = []
            for frame in range(len(frames)):
                scene.draw(frame)
                images.append(_gif_frame(_render(scene), pixels))
            images = _one_palette(images)
            images[0].save(os.fspath(path), format='GIF', save_all=True,
                           append_images=images[1:], duration=int(1000 / fps), loop=0)
            return len(frames)
        from matplotlib.animation import FFMpegWriter
        writer = FFMpegWriter(fps=fps, codec='libx264', extra_args=['-pix_fmt', 'yuv420p'])
        with writer.saving(figure, os.fspath(path), dpi=DPI):
            for frame in range(len(frames)):
                scene.draw(frame)
                writer.grab_frame(facecolor='white')
    except OSError as error:
        raise RunError(f'cannot write {path}: {error.strerror or error}') from None
    return len(frames)


def drawn(run, *, at=None, start=0.0, view='3d', size=(640, 480), forces=False,
          camera='fit'):
    """The frame of a run at time ``at`` (s, default its end), drawn on an Agg figure (not
    written): the scene's ``figure``, ``ax``, the drawn ``halves`` [(polygon (m), colour)],
    the line artists (``segment`` AB, ``trace_a``, ...) and, on a slope in 3D, the
    ``ground_quad`` (4, 3) (m). Other arguments as :func:`animate`."""
    _check_view(view, camera)
    at = float(run.t[-1]) if at is None else at
    _check_span(run, start, at, 1.0)
    shown = run.span(start, at)
    figure = _figure(size)
    scene = _Scene(shown, figure, view, camera, forces and shown.force_a is not None,
                   [len(shown) - 1])
    scene.draw(0)
    return scene


def still(run, path, *, at=None, start=0.0, view='3d', size=(640, 480), forces=False,
          camera='fit'):
    """Write one frame of a run as a PNG: the body at time ``at`` (s, default the run's end),
    the traces from ``start`` to ``at``; other arguments as :func:`animate`. ``path`` is
    written as it is (a command line refuses existing files first, outputs.py).
    """
    _check_view(view, camera)
    if os.path.splitext(os.fspath(path))[1].lower() != '.png':
        raise RunError(f'cannot write {path}: the file name must end in .png')
    scene = drawn(run, at=at, start=start, view=view, size=size, forces=forces, camera=camera)
    try:
        scene.figure.savefig(os.fspath(path), dpi=DPI, facecolor='white')
    except OSError as error:
        raise RunError(f'cannot write {path}: {error.strerror or error}') from None

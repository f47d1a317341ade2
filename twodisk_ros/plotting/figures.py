"""Figures of the paper and of the notes, as PNG files (matplotlib, Agg).

Run ``python -m twodisk_ros.plotting.figures --out DIR [--overwrite]`` (``make figures`` writes
``docs/figures``; existing PNGs are replaced only with ``--overwrite``):

* ``figure3.png``, ``figure4.png``, ``oloid_traces.png``: traces of the contact points A and B
  on the ground over three whole cycles (world frame, m), as in the paper's Figures 3 and 4;
* ``height.png``: the height of G over one cycle for the oloid, the Figure 3 body and the
  Two-Circle-Roller, with the eight equilibria per cycle;
* ``stability_map.png``: which family of equilibria is stable, over b/a and Δ/a;
* ``laminae_traces.png``: the two bodies of other laminae shipped in ``config/`` (a rounded
  square, superellipse n = 4, and an egg): each lamina's outline beside the ellipse of the
  same extents, and the traces of A and B over whole cycles.

Plotting lives only here; the physics core never imports matplotlib.
"""

import argparse
import math
import sys
from pathlib import Path

import numpy as np  # noqa: E402

from ..physics.bodies.ellipse import EllipseBody  # noqa: E402
from ..physics.laminae.shapes import Superellipse  # noqa: E402
from ..physics.laminae.support import Egg  # noqa: E402
from ..physics.bodies.lamina_body import LaminaBody  # noqa: E402
from ..outputs import OutputError, check_output_dir, replacing  # noqa: E402
from ..model import palette  # noqa: E402
from ..physics.bodies.cycle import RollingCycle  # noqa: E402
from ..physics.stability.equilibria import NEUTRAL, STABLE, equilibria, stability_map  # noqa: E402

__all__ = ['FIGURE3', 'FIGURE4', 'lamina_bodies', 'NAMES', 'plot_traces', 'plot_height',
           'plot_outline', 'plot_stability_map',
           'write_figures', 'main', 'save_figure']

#: The paper's bodies (a, b, Δ) in m.
FIGURE3 = (2.0, 1.0, 1.0)
FIGURE4 = (math.sqrt(1.5), 1.0, 1.0)


def lamina_bodies():
    """The bodies of other laminae in config/ (rounded_square.yaml, egg.yaml): (title, lamina,
    Δ (m), arrangement, cycles drawn). The egg's ε is half its largest convex value
    (egg_asymmetry 0.5): a minimisation, so built when drawn, not when imported (--help)."""
    return (
        ('Rounded square (superellipse n = 4)', Superellipse(0.1, 0.1, 4.0), 0.05, 'parallel', 3),
        ('Egg (parallel)', Egg(0.1, 0.08, 0.5 * Egg.epsilon_max(0.1, 0.08)), 0.04, 'parallel',
         8),
    )


COLOR_A, COLOR_B, COLOR_RULING = palette.A, palette.B, '0.72'
DPI = 150
TWO_PI = 2.0 * math.pi

#: The figures' matplotlib style, set when matplotlib is first needed (:func:`_pyplot`).
STYLE = {
    'font.size': 9, 'axes.titlesize': 10, 'axes.labelsize': 9, 'legend.fontsize': 8,
    'xtick.direction': 'in', 'ytick.direction': 'in', 'axes.grid': True,
    'grid.color': '0.9', 'grid.linewidth': 0.6, 'savefig.dpi': DPI,
}
_styled = []


def _pyplot():
    """matplotlib.pyplot on the Agg backend with :data:`STYLE` (set once). matplotlib is
    imported here, on first use, not with this module: ``--help`` answers without it."""
    import matplotlib
    if not _styled:
        matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    if not _styled:
        plt.rcParams.update(STYLE)
        _styled.append(True)
    return plt


def plot_outline(lamina, ax, samples=721):
    """One lamina's outline in its own plane (m), beside the ellipse of the same extents.

    x across (e1), y along the common axis (e2), origin at the disk centre; the ellipse has
    semi-axes b = the largest x and a = the lamina's half length along y (dashed).
    """
    _pyplot()                                   # the figures' style (STYLE)
    s = np.linspace(-math.pi, math.pi, samples)
    rim = lamina.point(s)
    x_max, y_min, y_max = lamina.extents
    half, mid = 0.5 * (y_max - y_min), 0.5 * (y_max + y_min)
    ax.plot(x_max * np.sin(s), mid - half * np.cos(s), '--', color='0.6', lw=0.9,
            label='ellipse of the same extents')
    ax.plot(rim[:, 0], rim[:, 1], color=COLOR_A, lw=1.6, gid='outline', label='lamina')
    ax.plot([0.0], [0.0], '+', color='0.3', ms=6, label='disk centre')
    ax.set_aspect('equal', adjustable='datalim')
    ax.set_xlabel('x (m), across')
    ax.set_ylabel('y (m), common axis')
    ax.legend(loc='upper center', bbox_to_anchor=(0.5, -0.22), frameon=False, ncol=1)
    return ax


def _cycles(count):
    return '1 cycle' if count == 1 else f'{count} cycles'


def _advance(displacement):
    """The cycle's displacement in words: along X, or a step and a turn of the heading."""
    turn = math.remainder(displacement.turn, TWO_PI)
    if abs(turn) < 1e-9:
        return f'{displacement.shift.real:.5g} m along X per cycle'
    return (f'\n{abs(displacement.shift):.5g} m and a turn of {math.degrees(turn):.3g}° per '
            'cycle: the body walks a circle')


def plot_traces(body, cycles, ax, samples_per_cycle=2000, rulings_per_cycle=12, name=None):
    """Traces of A and B on the ground over whole cycles (world frame, m).

    Parameters
    ----------
    body : EllipseBody
    cycles : int
        Number of whole cycles, from phase u = 0 (A at the origin, θ = 0).
    ax : matplotlib.axes.Axes
    samples_per_cycle : int
        Points per cycle along each trace.
    rulings_per_cycle : int
        Contact lines AB drawn per cycle (thin grey), the rulings of the body's hull.
    name : str, optional
        Prefix of the title.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``; the traces are the lines with gid ``'trace A'`` and ``'trace B'``.
    """
    _pyplot()                                   # the figures' style (STYLE)
    cycle = RollingCycle(body)
    u = np.linspace(0.0, TWO_PI * cycles, samples_per_cycle * cycles + 1)
    _, a_world, b_world = cycle.positions(u)
    u_rule = np.arange(rulings_per_cycle * cycles + 1) * TWO_PI / rulings_per_cycle
    _, a_rule, b_rule = cycle.positions(u_rule)
    for k, (pa, pb) in enumerate(zip(a_rule, b_rule)):
        ax.plot([pa[0], pb[0]], [pa[1], pb[1]], color=COLOR_RULING, lw=0.6, zorder=1,
                label='contact line AB' if k == 0 else None)
    ax.plot(a_world[:, 0], a_world[:, 1], color=COLOR_A, lw=1.4, zorder=3, gid='trace A',
            label='trace of A (disk 1)')
    ax.plot(b_world[:, 0], b_world[:, 1], color=COLOR_B, lw=1.4, zorder=3, gid='trace B',
            label='trace of B (disk 2)')
    # cusps: A turns back at the turning points (u = π/2 + kπ), B where θ = 0 (u = kπ)
    cusp_u = np.arange(2 * cycles + 1) * math.pi
    _, _, b_cusp = cycle.positions(cusp_u)
    _, a_cusp, _ = cycle.positions(cusp_u[:-1] + math.pi / 2)
    ax.plot(a_cusp[:, 0], a_cusp[:, 1], 'v', color=COLOR_A, ms=4, zorder=4,
            label='cusps of A (turning points)')
    ax.plot(b_cusp[:, 0], b_cusp[:, 1], '^', color=COLOR_B, ms=4, zorder=4,
            label='cusps of B (θ = 0)')
    ax.set_aspect('equal', adjustable='box')
    ax.set_xlabel('X (m)')
    ax.set_ylabel('Y (m)')
    prefix = f'{name}: ' if name else ''
    ax.set_title(f'{prefix}{body.describe()}\n{_cycles(cycles)} of the phase u (0 to '
                 f'{2 * cycles}π), one lobe of each trace per half-cycle; '
                 f'{_advance(cycle.displacement)}')
    ax.legend(loc='upper center', bbox_to_anchor=(0.5, 0.0), borderaxespad=3.6, ncol=3,
              frameon=False)
    return ax


_FAMILY_MARKERS = {'theta=0': 'o', 'theta=+pi/2': 's', 'theta=-pi/2': 's', 'turning': '^'}
_FAMILY_LABELS = {'o': 'θ = 0', 's': 'θ = ±π/2', '^': 'turning point θ = ±θ_max'}


def _marker(name):
    for key, marker in _FAMILY_MARKERS.items():
        if name.startswith(key):
            return marker
    return 'o'


_EQ_THETA = ['0', 'π/2', 'θ_max', 'π/2', '0', '−π/2', '−θ_max', '−π/2']


def plot_height(bodies, ax, samples=1441, annotate=0):
    """Height of G (m) over one cycle, x = phase u (rad), with the equilibria marked.

    Stable equilibria are filled, unstable ones open, neutral ones crossed; the marker shape
    gives the family (θ = 0, θ = ±π/2, turning point).

    Parameters
    ----------
    bodies : sequence of (label, EllipseBody)
    ax : matplotlib.axes.Axes
    samples : int
        Phases over [0, 2π].
    annotate : int or None
        Index of the body whose equilibria are labelled with their θ on the top axis.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``; each curve has gid ``'height <label>'``.
    """
    _pyplot()                                   # the figures' style (STYLE)
    u = np.linspace(0.0, TWO_PI, samples)
    colors = _pyplot().rcParams['axes.prop_cycle'].by_key()['color']
    for k, (label, body) in enumerate(bodies):
        color = colors[k % len(colors)]
        ax.plot(u, body.phase_height(u), color=color, lw=1.4, gid=f'height {label}',
                label=label)
        for eq in equilibria(body):
            marker = _marker(eq.name)
            if eq.stability == NEUTRAL:
                ax.plot(eq.phase, eq.height, marker='x', color=color, ms=5, mew=1.0,
                        zorder=3)
                continue
            face = color if eq.stability == STABLE else 'white'
            ax.plot(eq.phase, eq.height, marker=marker, mfc=face, mec=color, ms=6, mew=1.2,
                    ls='none', zorder=4)
    ax.set_xlim(0.0, TWO_PI)
    ax.margins(y=0.1)
    ax.set_xticks(np.arange(5) * math.pi / 2)
    ax.set_xticklabels(['0', 'π/2', 'π', '3π/2', '2π'])
    ax.set_xlabel('cycle phase u (rad)')
    ax.set_ylabel('height of G, z_G (m)')
    if annotate is not None:
        label, body = bodies[annotate]
        top = ax.secondary_xaxis('top')
        top.set_xticks([eq.phase for eq in equilibria(body)])
        top.set_xticklabels(_EQ_THETA, fontsize=7)
        top.set_xlabel(f'θ at the equilibria ({label})', fontsize=8)
        top.tick_params(direction='in')
    ax.set_title('Height of the centre of mass over one cycle', pad=8)
    curves = ax.legend(loc='upper left', bbox_to_anchor=(1.01, 1.0), frameon=False,
                       title='body')
    ax.add_artist(curves)
    # two keys: the shape gives the kind of equilibrium, the fill its stability
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    shapes = [Line2D([], [], marker=m, color='0.35', ls='none', mfc='0.8', mec='0.35',
                     label=text) for m, text in _FAMILY_LABELS.items()]
    kinds = ax.legend(handles=shapes, loc='center left', bbox_to_anchor=(1.01, 0.5),
                      frameon=False, title='shape: kind of equilibrium')
    ax.add_artist(kinds)
    fills = [Patch(fc='0.3', ec='0.3', label='filled: stable'),
             Patch(fc='white', ec='0.3', label='hollow: unstable'),
             Line2D([], [], marker='x', color='0.3', ls='none',
                    label='×: neutral (z_G constant)')]
    ax.legend(handles=fills, loc='lower left', bbox_to_anchor=(1.01, -0.02), frameon=False,
              title='fill: stability', handlelength=1.2)
    return ax


_NAMED_BODIES = [('Oloid', (1.0, 1.0, 0.5)), ('TCR', (1.0, 1.0, 1.0 / math.sqrt(2.0))),
                 ('Fig. 3', FIGURE3), ('Fig. 4', FIGURE4)]


def plot_stability_map(ax, b_range=(0.05, 3.0), resolution=400):
    """Which equilibria are stable over b/a and Δ/a (from :func:`stability_map`).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    b_range : (float, float)
        Range of b/a.
    resolution : int
        Grid points per axis.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``; the neutral curve has gid ``'neutral curve'``.
    """
    _pyplot()                                   # the figures' style (STYLE)
    b = np.linspace(b_range[0], b_range[1], resolution)
    d = np.linspace(0.0, 1.0, resolution + 1)[1:-1]
    grid = stability_map(b[None, :], d[:, None])
    from matplotlib.colors import ListedColormap
    cmap = ListedColormap(['#f3d9c4', '#ffffff', '#cfe0f1'])
    ax.pcolormesh(b, d, grid, cmap=cmap, vmin=-1.5, vmax=1.5, shading='auto',
                  rasterized=True)
    b_line = np.linspace(b_range[0], math.sqrt(2.0), 400)
    ax.plot(b_line, np.sqrt(np.clip(1.0 - b_line**2 / 2, 0.0, None)), color='k', lw=1.4,
            gid='neutral curve', label='neutral: Δ = √(a² − b²/2), z_G constant')
    offsets = {'TCR': (7, 3), 'Fig. 4': (7, 3), 'Oloid': (7, -11), 'Fig. 3': (-8, -13)}
    for label, (a_, b_, d_) in _NAMED_BODIES:
        x, y = b_ / a_, d_ / a_
        ax.plot(x, y, 'o', mfc='k', mec='white', ms=6, zorder=4)
        dx, dy = offsets[label]
        ax.annotate(f'{label} ({x:.3g}, {y:.3g})', (x, y), xytext=(dx, dy),
                    textcoords='offset points', fontsize=8, ha='left' if dx > 0 else 'center')
    ax.text(0.62, 0.2, 'b² − 2a² + 2Δ² < 0\nθ = ±π/2 stable\nθ = 0, turning points unstable',
            ha='center', va='center', fontsize=8)
    ax.text(2.25, 0.6, 'b² − 2a² + 2Δ² > 0\nθ = 0, turning points stable\nθ = ±π/2 unstable',
            ha='center', va='center', fontsize=8)
    ax.set_xlim(*b_range)
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel('b / a')
    ax.set_ylabel('Δ / a')
    ax.set_title('Stable family of equilibria')
    ax.legend(loc='lower right', frameon=True, framealpha=0.9)
    ax.grid(False)
    return ax


#: the files :func:`write_figures` writes, in order
NAMES = ('figure3.png', 'figure4.png', 'oloid_traces.png', 'height.png', 'stability_map.png',
         'laminae_traces.png')


def save_figure(fig, path, dpi=DPI):
    """Save ``fig`` (a pyplot figure) through a temporary file renamed over ``path`` when
    complete, at ``dpi``, cropped to its content; close it; return ``path``."""
    import matplotlib.pyplot as plt
    try:
        with replacing(path) as temporary:
            fig.savefig(temporary, dpi=dpi, bbox_inches='tight')
    finally:
        plt.close(fig)
    return path


def write_figures(out_dir):
    """Write all figures as PNG into ``out_dir`` (created if missing).

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    plt = _pyplot()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for filename, title, shape in [('figure3.png', 'Paper, Figure 3', FIGURE3),
                                   ('figure4.png', 'Paper, Figure 4', FIGURE4),
                                   ('oloid_traces.png', 'Oloid', (1.0, 1.0, 0.5))]:
        fig, ax = plt.subplots(figsize=(8.0, 3.6))
        plot_traces(EllipseBody(*shape), 3, ax, name=title)
        written.append(save_figure(fig, out / filename))
    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    plot_height([('Oloid', EllipseBody.oloid()), ('Fig. 3 body', EllipseBody(*FIGURE3)),
                 ('Two-Circle-Roller', EllipseBody.two_circle_roller())], ax, annotate=1)
    written.append(save_figure(fig, out / 'height.png'))
    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    plot_stability_map(ax)
    written.append(save_figure(fig, out / 'stability_map.png'))
    bodies = lamina_bodies()
    fig, axes = plt.subplots(len(bodies), 2, figsize=(10.0, 4.3 * len(bodies)),
                             gridspec_kw={'width_ratios': (1, 3.2)})
    for (title, lamina, delta, arrangement, cycles), (left, right) in zip(bodies, axes):
        plot_outline(lamina, left)
        left.set_title(title.split(' (')[0], fontsize=9)
        plot_traces(LaminaBody(lamina, delta, arrangement), cycles, right, name=title)
    fig.tight_layout()
    written.append(save_figure(fig, out / 'laminae_traces.png'))
    return written


def main(argv=None):
    """Command line: ``python -m twodisk_ros.plotting.figures [--out DIR] [--overwrite]``.

    Returns the exit status: 0 written, 2 an output refused (one line on stderr, nothing
    written).
    """
    parser = argparse.ArgumentParser(
        prog='python -m twodisk_ros.plotting.figures',
        description='Write the figures (PNG) of twodisk_ros: the paper\'s Figures 3 and 4 and '
                    'the oloid\'s traces over whole cycles, the height of G with the '
                    'equilibria, the stability map, and the traces of two bodies of other '
                    'laminae (a rounded square and an egg).',
        epilog=f'Writes {", ".join(NAMES)} into DIR. Exit status: 0 written, 2 bad '
               'arguments or an output refused (one line, nothing written).')
    parser.add_argument('--out', metavar='DIR', default='docs/figures',
                        help='output directory, created if missing (default docs/figures)')
    parser.add_argument('--overwrite', action='store_true',
                        help='replace existing figures (without it they are refused)')
    args = parser.parse_args(argv)
    try:
        check_output_dir(args.out, overwrite=args.overwrite, names=NAMES)
    except OutputError as error:
        print(f'figures: {error}', file=sys.stderr)
        return 2
    for path in write_figures(args.out):
        print(path)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

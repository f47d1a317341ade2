"""Figures and tables of ``contact_model:=hybrid`` beside the engine alone (issue 31; PNG,
matplotlib Agg).

``python -m twodisk_ros.plotting.hybrid_figures [--out DIR] [--overwrite] [--span S]``
(``make figures``) runs :mod:`~twodisk_ros.plotting.hybrid_results` and writes

* ``hybrid_rounded_square.png``: config/rounded_square.yaml over ``--span`` s (default 20):
  the energy against time, hybrid and engine alone, the hybrid's engine stretches shaded;
  the energy lost at each stretch of either; z_G and the contact points' slip speeds at the
  first vertex;
* ``hybrid_oloid_hops.png``: the oloid spun up (ω0 from the lift-off threshold to 20 rad/s):
  z_G against time, the highest hop's rise against the ballistic closed form, and that hop
  beside its parabola;

and prints the Markdown tables docs/physics.md quotes (the vertices, the engine alone's
rolling error, the lift-off speed and the hops). Existing PNGs are replaced only with
``--overwrite``. Takes about a minute and a half of CPU.
"""

import argparse
import math
import os
import sys

import numpy as np

from ..outputs import OutputError, check_output_dir
from .figures import save_figure

__all__ = ['NAMES', 'OMEGAS', 'main', 'plot_oloid', 'plot_square', 'tables']

NAMES = ('hybrid_rounded_square.png', 'hybrid_oloid_hops.png')
#: rad/s: the oloid's start speeds
OMEGAS = (8.5, 9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0, 17.0, 18.0, 19.0, 20.0)
DPI = 150
SHADE = dict(color='tab:orange', alpha=0.25, lw=0)


def _pyplot():
    import matplotlib
    if 'matplotlib.pyplot' not in sys.modules:
        matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    return plt


def _shade(ax, stretches, label=None):
    for k, (t0, t1) in enumerate(stretches):
        ax.axvspan(t0, t1, label=label if k == 0 else None, **SHADE)


def plot_square(r, path):
    """The rounded square's figure (module docstring) from :func:`square_runs`' dict."""
    plt = _pyplot()
    s, alone, vertices = r['samples'], r['alone'], r['vertices']
    engine = [(v.t0, v.t1) for v in vertices]
    fig, axes = plt.subplots(2, 2, figsize=(11.0, 7.0))
    ax = axes[0, 0]
    _shade(ax, engine, 'hybrid: engine stretch (a vertex)')
    ax.plot(s.t, s.energy, color='tab:blue', lw=1.0, label='hybrid')
    ax.plot(alone.t, alone.energy, color='tab:red', lw=1.0, ls='--', label='MuJoCo alone')
    ax.set_xlabel('t (s)')
    ax.set_ylabel('E (J)')
    ax.set_title('(a) energy; exact rolling conserves it between the vertices')
    ax.legend(loc='center right')
    ax = axes[0, 1]
    ax.plot([v.t0 for v in vertices], [1e3 * v.energy_lost for v in vertices], 'o',
            color='tab:blue', ms=4, label='hybrid, per engine stretch (slip vertex)')
    lost = [(a, 1e3 * (alone.energy[np.searchsorted(alone.t, a)]
                       - alone.energy[min(np.searchsorted(alone.t, b), len(alone.t) - 1)]))
            for a, b in alone.stretches]
    ax.plot(*zip(*lost), 'x', color='tab:red', ms=5,
            label='MuJoCo alone, per stretch its return rule fails')
    errors = r['rolling_errors']
    ax.plot([e[0] for e in errors], [1e3 * e[3] for e in errors], '^', mfc='none',
            color='tab:green', ms=5, label='MuJoCo from each rolling stretch\'s start, '
            'over that stretch')
    ax.set_xlabel('t at the stretch\'s start (s)')
    ax.set_ylabel('energy lost (mJ)')
    ax.set_title('(b) energy lost per stretch')
    ax.set_ylim(bottom=0)
    ax.legend(loc='center right', fontsize=7)
    v = vertices[0]
    lo, hi = v.t0 - 0.03, v.t1 + 0.03
    window = (s.t >= lo) & (s.t <= hi)
    ax = axes[1, 0]
    _shade(ax, [(v.t0, v.t1)], 'engine stretch')
    rolling_z = r['dynamics'].body.phase_height(s.phase[window])
    ax.plot(s.t[window], 1e3 * s.position_g[window, 2], color='tab:blue', label='hybrid z_G')
    ax.plot(s.t[window], 1e3 * rolling_z, color='0.4', ls=':', lw=1.2,
            label='rolling pose at the published phase')
    ax.set_xlabel('t (s)')
    ax.set_ylabel('z_G (mm)')
    ax.set_title(f'(c) z_G at the first vertex ({v.reason}, {v.kind}, '
                 f'{1e3 * (v.t1 - v.t0):.1f} ms)')
    ax.legend(loc='lower left', fontsize=7)
    ax = axes[1, 1]
    _shade(ax, [(v.t0, v.t1)])
    from .hybrid_results import slip_speeds
    speeds = slip_speeds(s)
    for j, (name, color) in enumerate((('A', 'tab:purple'), ('B', 'tab:green'))):
        touching = s.touching[window, j] | ~s.engine[window]
        shown = np.where(touching, 1e3 * speeds[window, j], np.nan)
        ax.plot(s.t[window], shown, color=color, label=f'slip speed of {name}')
        air = s.t[window][~touching]
        if air.size:
            ax.plot(air, np.full(air.size, -2.0 - 2 * j), '|', color=color, ms=6,
                    label=f'{name} in the air')
    ax.axhline(1e3 * r['rule'].slip_speed, color='0.4', ls=':', lw=1,
               label='return rule\'s slip speed')
    ax.set_xlabel('t (s)')
    ax.set_ylabel('contact point speed along the ground (mm/s)')
    ax.set_title('(d) slip at the first vertex (0 while rolling)')
    ax.legend(loc='upper right', fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, DPI)


def _highest(flights):
    return max(flights, key=lambda f: f[2]) if flights else None


def plot_oloid(o, path):
    """The oloid's figure (module docstring) from :func:`oloid_hops`' dict."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(15.0, 4.4))
    ax = axes[0]
    colors = dict(zip((9.0, 15.0, 20.0), ('tab:blue', 'tab:green', 'tab:red')))
    for run in o['runs']:
        if run['omega0'] not in colors:
            continue
        c, h, a = colors[run['omega0']], run['hybrid'], run['alone']
        ax.plot(h['t'], 1e3 * h['z'], color=c, lw=1, label=f'ω0 = {run["omega0"]:g} rad/s')
        ax.plot(a['t'], 1e3 * a['z'], color=c, lw=0.8, ls='--')
        ax.axvline(h['switch'], color=c, lw=0.6, ls=':')
    ax.plot([], [], color='0.3', ls='--', lw=0.8, label='MuJoCo alone (dashed)')
    ax.set_xlabel('t (s)')
    ax.set_ylabel('z_G (mm)')
    ax.set_xlim(0, 0.6)
    ax.set_title('(a) z_G (dotted: the hybrid\'s switch)')
    ax.legend(loc='upper right', fontsize=7)
    ax = axes[1]
    for key, marker, color, label in (('hybrid', 'o', 'tab:blue', 'hybrid (engine)'),
                                      ('alone', 'x', 'tab:red', 'MuJoCo alone')):
        rows = [(run['omega0'], _highest(run[key]['flights'])) for run in o['runs']]
        rows = [(w, f) for w, f in rows if f is not None]
        if rows:
            ax.plot([w for w, _ in rows], [1e3 * f[2] for _, f in rows], marker, color=color,
                    label=f'{label}: rise of the highest flight')
            ax.plot([w for w, _ in rows], [1e3 * f[3] for _, f in rows], '_', color=color,
                    ms=12, label=f'{label}: v_z0² / (2 g) at its take-off')
    ax.axvline(o['threshold'][0], color='0.3', ls=':', lw=1,
               label=f'lift-off threshold ω0 = {o["threshold"][0]:.4f} rad/s')
    ax.set_xlabel('ω0 at phase π/4 (rad/s)')
    ax.set_ylabel('hop height above take-off (mm)')
    ax.set_yscale('log')
    ax.set_title('(b) highest hop against the ballistic closed form')
    ax.legend(loc='upper left', fontsize=7)
    ax = axes[2]
    run = o['runs'][-1]
    h = run['hybrid']
    t0, t1, rise, ballistic = _highest(h['flights'])
    g, step = o['dynamics'].gravity, o['timestep']
    k = np.flatnonzero((h['t'] >= t0) & (h['t'] <= t1))
    tau = h['t'][k] - t0
    v0 = math.sqrt(2 * g * ballistic)
    ax.plot(1e3 * tau, 1e3 * (h['z'][k] - h['z'][k[0]]), color='tab:blue', lw=2,
            label=f'engine, ω0 = {run["omega0"]:g} rad/s')
    ax.plot(1e3 * tau, 1e3 * (v0 * tau - 0.5 * g * tau ** 2), color='k', ls='--', lw=1,
            label='ballistic v_z0 τ − ½ g τ²')
    ax.plot(1e3 * tau, 1e3 * (v0 * tau - 0.5 * g * tau ** 2 - 0.5 * g * step * tau),
            color='0.5', ls=':', lw=1, label='minus ½ g h τ (semi-implicit Euler, h = step)')
    ax.set_xlabel('τ = t − take-off (ms)')
    ax.set_ylabel('z_G − z_G(take-off) (mm)')
    ax.set_title(f'(c) the highest hop: {1e3 * rise:.3f} mm, ballistic {1e3 * ballistic:.3f} mm')
    ax.legend(loc='lower center', fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, DPI)


def tables(r, o):
    """The Markdown tables (str) of both runs, as docs/physics.md quotes them."""
    lines = ['| vertex | t (s) | reason | what it does | duration (ms) | energy lost (mJ) '
             '| largest slip (mm/s) | slid (mm) | largest rise of G (µm) |', '|' + '---|' * 9]
    for k, v in enumerate(r['vertices'], 1):
        lines.append(f'| {k} | {v.t0:.4f} | {v.reason} | {v.kind} | {1e3 * (v.t1 - v.t0):.1f} '
                     f'| {1e3 * v.energy_lost:.2f} | {1e3 * v.max_slip:.0f} '
                     f'| {1e3 * v.slide:.2f} | {1e6 * v.max_rise:.1f} |')
    alone, s = r['alone'], r['samples']
    lost = [alone.energy[np.searchsorted(alone.t, a)] - alone.energy[min(
        np.searchsorted(alone.t, b), len(alone.t) - 1)] for a, b in alone.stretches]
    errors = r['rolling_errors']
    kinds = {k: sum(v.kind == k for v in r['vertices']) for k in ('slide', 'rock', 'rattle',
                                                                  'hop')}
    lines += ['', f'hybrid: {len(r["vertices"])} engine stretches ({kinds}); '
              f'E {s.energy[0]:.5f} -> {s.energy[-1]:.5f} J; cpu {r["cpu_hybrid"]:.2f} s',
              f'MuJoCo alone: {len(alone.stretches)} stretches where the return rule fails, '
              f'losing {1e3 * np.sum(lost):.1f} mJ; E {alone.energy[0]:.5f} -> '
              f'{alone.energy[-1]:.5f} J; cpu {alone.cpu:.2f} s; G at the end '
              f'{1e3 * np.linalg.norm(alone.qpos[-1, :3] - s.position_g[-1]):.1f} mm from '
              "the hybrid's",
              f'MuJoCo from each rolling stretch\'s start ({len(errors)} stretches): G off the '
              f'exact rolling motion by {1e3 * np.mean([e[2] for e in errors]):.2f} mm at '
              f'the stretch\'s end on average (max {1e3 * max(e[2] for e in errors):.2f}), '
              f'energy lost {1e3 * np.mean([e[3] for e in errors]):.2f} mJ per stretch '
              f'(total {1e3 * np.sum([e[3] for e in errors]):.1f} mJ)', '']
    w, t, u, speed = o['threshold']
    crit = o['critical']
    lines += [f'oloid: Omega_c = {crit[0]:.10g} rad/s at u = {crit[1]:.6g} ({crit[2]}); '
              f'threshold omega0 = {w:.10g} rad/s from u0 = {o["u0"]:.6g}: lift-off at '
              f't = {t:.6f} s, u = {u:.9g}, |w| = {speed:.10g} rad/s '
              f'(relative to Omega_c {speed / crit[0] - 1:.2e})', '',
              '| ω0 (rad/s) | hybrid: switch (s) | MuJoCo alone: first separation ≥ 5 ms (s) '
              '| flights (hybrid / alone) | highest rise, hybrid (mm) '
              '| v_z0²/2g (− h v_z0/2) (mm) '
              '| highest rise, alone (mm) | v_z0²/2g (− h v_z0/2) (mm) '
              '| cpu hybrid / alone (s) |',
              '|' + '---|' * 9]
    for run in o['runs']:
        h, a = run['hybrid'], run['alone']
        fh, fa = _highest(h['flights']), _highest(a['flights'])

        def mm(f):
            return f'{1e3 * f[2]:.3f}' if f is not None else '–'

        def ballistic(f):
            if f is None:
                return '–'
            v0 = math.sqrt(2 * o['dynamics'].gravity * f[3])
            return f'{1e3 * f[3]:.3f} ({1e3 * (f[3] - 0.5 * o["timestep"] * v0):.3f})'
        lines.append(f'| {run["omega0"]:g} | {h["switch"]:.4f} | {a["separation"]:.4f} '
                     f'| {len(h["flights"])} / {len(a["flights"])} | {mm(fh)} '
                     f'| {ballistic(fh)} | {mm(fa)} | {ballistic(fa)} '
                     f'| {h["cpu"]:.2f} / {a["cpu"]:.2f} |')
    return '\n'.join(lines)


def _parser():
    parser = argparse.ArgumentParser(
        prog='python -m twodisk_ros.plotting.hybrid_figures',
        description='Write the figures of contact_model hybrid beside MuJoCo alone (PNG): the '
                    'rounded square of config/rounded_square.yaml at its flat vertices, and '
                    'the oloid spun up until it hops; print their tables (Markdown).',
        epilog=f'Writes {NAMES[0]} and {NAMES[1]} into DIR. Exit status: 0 written, 2 bad '
               'arguments or an output refused (one line, nothing written).')
    parser.add_argument('--out', metavar='DIR', default=os.path.join('docs', 'figures'),
                        help='output directory, created if missing (default docs/figures)')
    parser.add_argument('--overwrite', action='store_true',
                        help='replace existing figures (without it they are refused)')
    parser.add_argument('--span', type=float, default=20.0, metavar='S',
                        help='seconds of the rounded square (0.6 to 600, default 20)')
    return parser


def main(argv=None):
    """Write both figures into ``--out`` and print the tables; return 0, or 2 refused."""
    parser = _parser()
    args = parser.parse_args(argv)
    if not (math.isfinite(args.span) and 0.6 <= args.span <= 600):
        print(f'hybrid_figures: --span must be 0.6 to 600 s, got {args.span:g}',
              file=sys.stderr)
        return 2
    try:
        check_output_dir(args.out, overwrite=args.overwrite, names=NAMES)
    except OutputError as error:
        print(f'hybrid_figures: {error}', file=sys.stderr)
        return 2
    from .hybrid_results import oloid_hops, square_runs
    os.makedirs(args.out, exist_ok=True)
    square = square_runs(args.span)
    plot_square(square, os.path.join(args.out, NAMES[0]))
    oloid = oloid_hops(OMEGAS)
    plot_oloid(oloid, os.path.join(args.out, NAMES[1]))
    print(tables(square, oloid))
    for name in NAMES:
        print(os.path.join(args.out, name))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

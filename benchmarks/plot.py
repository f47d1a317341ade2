"""The work-precision figure: one log-log panel per body."""

import math

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402

from scenarios import BODIES  # noqa: E402

from twodisk_ros.physics.motion.simulate import CLOSED_FORM_SOLVERS  # noqa: E402

KIND_COLORS = {'rolling': '#1f77b4', 'oscillating': '#d62728', 'kinematic': '#2ca02c'}
KIND_LABELS = {'rolling': 'dynamic, rolling over', 'oscillating': 'dynamic, oscillating',
               'kinematic': 'kinematic (|ω| const.)'}
METHOD_STYLE = {'direct': dict(marker='o', linestyle='-', markerfacecolor='white'),
                'table': dict(marker='s', linestyle='--')}
CEILING = 1.0     # errors above this (≥ the body size) are drawn at the top edge


def _tol_label(tol):
    return f'{int(round(math.log10(tol)))}'


def work_precision_figure(results, reference_errors, path):
    """results: list of work_precision.Result; reference_errors: {(body, kind): est. error}."""
    fig, axes = plt.subplots(2, 2, figsize=(13, 11), layout='constrained', sharex=True,
                             sharey=True)
    legend = {}
    global_lo = 1e-13
    for ax, body in zip(axes.flat, BODIES):
        diverged = 0
        rows = [r for r in results if r.body == body]
        finite = [r.error for r in rows if math.isfinite(r.error) and 0 < r.error < CEILING]
        lo = min(finite + [1e-13]) / 3
        top = CEILING * 3
        global_lo = min(global_lo, lo)
        for kind in KIND_COLORS:
            for method in ('direct', 'table'):
                pts = sorted((r for r in rows if r.kind == kind and r.method == method),
                             key=lambda r: r.tolerance)
                if not pts:
                    continue
                color = KIND_COLORS[kind]
                quad = pts[0].solver in CLOSED_FORM_SOLVERS
                if quad:       # tolerance-independent: one point
                    pts = [min(pts, key=lambda r: r.wall_per_second)]
                xs = [r.wall_per_second for r in pts]
                ys = [r.error if (math.isfinite(r.error) and r.error < CEILING) else top
                      for r in pts]
                style = dict(METHOD_STYLE[method])
                label = f'{method}, {KIND_LABELS[kind]}'
                if quad:
                    label += f' [{pts[0].solver}: any tolerance]'
                (line,) = ax.plot(xs, ys, color=color, markersize=7, label=label, **style)
                legend.setdefault(label, line)
                for j, (r, x, y) in enumerate(zip(pts, xs, ys)):
                    if y >= top:
                        what = (f'error {r.error:.0e} × size' if math.isfinite(r.error)
                                else 'NaN samples')
                        ax.annotate(f'{method}, {KIND_LABELS[kind]}: diverged ({what})', (x, y),
                                    textcoords='offset points', xytext=(8, -14 - 12 * diverged),
                                    fontsize=7, color=color,
                                    arrowprops=dict(arrowstyle='-', color=color, lw=0.5))
                        (tri,) = ax.plot([x], [y], marker='^', color='black', markersize=9,
                                         linestyle='none')
                        legend.setdefault('error > body size (drawn at the top edge)', tri)
                        diverged += 1
                        continue
                    # the loosest and the tightest tolerance only (the others lie between,
                    # in order): labels of neighbouring points would overlap; the
                    # tolerance-independent points are named in the legend
                    if quad or 0 < j < len(pts) - 1:
                        continue
                    tightest = j == 0      # pts are sorted by tolerance, tightest first
                    ax.annotate(_tol_label(r.tolerance), (x, y), textcoords='offset points',
                                xytext=(7, -3) if tightest else (7, 3), ha='left',
                                va='top' if tightest else 'bottom', fontsize=7, color=color)
        refs = [v for (b, _), v in reference_errors.items() if b == body]
        if refs:
            (ref_line,) = ax.axhline(max(refs), color='grey', linestyle=':', linewidth=1),
            legend.setdefault('reference: estimated error (max over the states)', ref_line)
        ax.set_xscale('log')
        ax.set_yscale('log')
        ax.set_ylim(global_lo / 1.5, top * 3)
        ax.axhline(CEILING, color='black', linewidth=0.5)
        ax.set_title(BODIES[body][3])
        ax.set_xlabel('wall time per simulated second (s/s), simulate + positions')
        ax.set_ylabel('max position error of G, A, B / body size')
        ax.tick_params(labelbottom=True, labelleft=True)
        ax.grid(True, which='major', alpha=0.3)
    fig.legend(list(legend.values()), list(legend.keys()), loc='outside lower center', ncol=3,
               fontsize=8)
    fig.suptitle('Work-precision: direct (DOP853 on closed forms) vs table; laminae, '
                 'g = 9.81 m/s², 1 kHz output\nnumbers: log10 of the tolerance at the ends of '
                 'each line (1e-6, 1e-8, 1e-10, 1e-12 in order along it)')
    fig.savefig(path, dpi=110)
    plt.close(fig)

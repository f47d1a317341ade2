"""Figures of the contact forces (matplotlib, Agg): over one cycle, and against speed.

``python -m twodisk_ros.plotting.contact_forces [--out DIR] [--overwrite]`` writes
DIR/contact_forces_cycle.png and DIR/contact_forces_speed.png (DIR default docs/figures,
created if missing; existing files are replaced only with ``--overwrite``).
The bodies are those of config/*.yaml (mass 1 kg, laminae, g = 9.81 m/s²).
"""

import argparse
import math
import os
import sys

import numpy as np  # noqa: E402

from twodisk_ros.physics.bodies.ellipse import EllipseBody  # noqa: E402
from twodisk_ros.physics.motion.dynamics import RollingDynamics  # noqa: E402
from twodisk_ros.physics.mass.models import mass_properties  # noqa: E402
from twodisk_ros.physics.forces.contact import ContactForceModel  # noqa: E402
from twodisk_ros.physics.forces.validity import (  # noqa: E402
    liftoff_speed, mu_required_kinematic)
from twodisk_ros.outputs import OutputError, check_output_dir, replacing  # noqa: E402

__all__ = ['BODIES', 'NAMES', 'coinciding_speeds', 'force_model', 'plot_cycle', 'plot_speed',
           'main']

#: (label, (a, b, Δ) in m) as in config/oloid.yaml, two_circle_roller.yaml, figure3/4.yaml
BODIES = (
    ('Oloid (a = b = 0.1 m, Δ = 0.05 m)', (0.1, 0.1, 0.05)),
    ('Two-Circle-Roller (a = b = 0.1 m, Δ = 0.0707 m)', (0.1, 0.1, 0.1 / math.sqrt(2))),
    ('paper Fig. 3 (a = 0.2 m, b = Δ = 0.1 m)', (0.2, 0.1, 0.1)),
    ('paper Fig. 4 (a = 0.1225 m, b = Δ = 0.1 m)', (math.sqrt(1.5) * 0.1, 0.1, 0.1)),
)
FIGURES = os.path.join('docs', 'figures')
NAMES = ('contact_forces_cycle.png', 'contact_forces_speed.png')
#: lift-off speeds closer than this fraction draw their dotted lines on top of each other
SAME_LINE = 0.005


def _pyplot():
    """matplotlib.pyplot on Agg, imported on first use (``--help`` answers without it)."""
    import matplotlib
    if 'matplotlib.pyplot' not in sys.modules:
        matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    return plt


def force_model(shape, mass=1.0, model='laminae', gravity=9.81):
    """A :class:`ContactForceModel` for (a, b, Δ) in m."""
    body = EllipseBody(*shape)
    return ContactForceModel(RollingDynamics(body, mass_properties(model, *shape, mass),
                                             gravity=gravity))


def plot_cycle(path, shape=BODIES[0][1], fractions=(0.0, 0.5, 0.8, 0.95), samples=1001):
    """N_A/Mg, N_B/Mg and μ_required over one cycle (kinematic) at fractions of Ω_c."""
    model = force_model(shape)
    critical = liftoff_speed(model)[0]
    u = np.linspace(0.0, 2 * math.pi, samples)
    plt = _pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(fractions)))
    for fraction, colour in zip(fractions, colours):
        omega = fraction * critical
        forces = model.kinematic(u, omega)
        label = f'Ω = {omega:.2f} rad/s ({fraction:.0%} of Ω_c)'
        top.plot(u, forces.normal_a_per_weight, color=colour, lw=1.8)
        top.plot(u, forces.normal_b_per_weight, color=colour, lw=1.8, ls='--')
        bottom.plot(u, forces.mu_required, color=colour, lw=1.8, label=label)
    top.plot([], [], color='0.3', lw=1.8, label='N_A (contact A, disk 1)')
    top.plot([], [], color='0.3', lw=1.8, ls='--', label='N_B (contact B, disk 2)')
    top.axhline(0.0, color='k', lw=0.8)
    top.set_ylabel('normal force / weight  N / (M g)  (–)')
    top.set_title(f'Oloid (a = b = 0.1 m, Δ = 0.05 m, 1 kg) driven at constant |ω| = Ω: '
                  f'lift-off at Ω_c = {critical:.2f} rad/s', fontsize=10)
    top.legend(fontsize=8.5, loc='upper left', bbox_to_anchor=(1.01, 1.0))
    bottom.set_ylabel('μ_required  (–)')
    bottom.set_xlabel('cycle phase u (rad)')
    bottom.set_xticks(np.linspace(0, 2 * math.pi, 5), ['0', 'π/2', 'π', '3π/2', '2π'])
    bottom.legend(fontsize=8.5, loc='upper left', bbox_to_anchor=(1.01, 1.0),
                  title='speed (colour, both panels)', title_fontsize=8.5)
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
    fig.tight_layout()
    _save(fig, path)


def _save(fig, path):
    """Save through a temporary file renamed over ``path`` when complete; close ``fig``."""
    try:
        with replacing(path) as temporary:
            fig.savefig(temporary, dpi=120)
    finally:
        _pyplot().close(fig)


def coinciding_speeds(criticals):
    """Groups (indices) of lift-off speeds within :data:`SAME_LINE` of each other."""
    order = sorted(range(len(criticals)), key=lambda k: criticals[k])
    groups, current = [], [order[0]]
    for k in order[1:]:
        if criticals[k] - criticals[current[-1]] <= SAME_LINE * criticals[k]:
            current.append(k)
        else:
            groups.append(current)
            current = [k]
    groups.append(current)
    return [group for group in groups if len(group) > 1]


def plot_speed(path, bodies=BODIES, samples=160):
    """max over a cycle of μ_required against Ω (kinematic), lift-off speeds marked.

    Lift-off speeds that coincide at the scale of the figure (within :data:`SAME_LINE`, as the
    oloid's 8.2810 and the Fig. 3 body's 8.2796 rad/s) are named together beside their
    shared dotted line.
    """
    plt = _pyplot()
    fig, axis = plt.subplots(figsize=(8, 5.5))
    colours = plt.cm.tab10(np.arange(len(bodies)))
    criticals, names = [], []
    for (label, shape), colour in zip(bodies, colours):
        model = force_model(shape)
        critical = liftoff_speed(model)[0]
        criticals.append(critical)
        names.append(label.split(' (')[0])
        omega = critical * np.linspace(0.02, 0.998, samples)
        mu = mu_required_kinematic(model, omega)
        axis.semilogy(omega, mu, color=colour, lw=1.8,
                      label=f'{label}: Ω_c = {critical:.4f} rad/s')
        axis.axvline(critical, color=colour, ls=':', lw=1.2)
        axis.plot(critical, mu[-1], marker='x', ms=9, mew=2, color=colour)
    for group in coinciding_speeds(criticals):
        text = ', '.join(f'{names[k]} {criticals[k]:.4f}' for k in sorted(group))
        axis.annotate(f'Ω_c = {text} rad/s:\nindistinguishable here (one dotted line)',
                      (criticals[group[0]], 0.02), xycoords=('data', 'axes fraction'),
                      xytext=(-6, 0), textcoords='offset points', ha='right', va='bottom',
                      fontsize=8, bbox=dict(boxstyle='round,pad=0.25', fc='white', ec='0.7'))
    axis.plot([], [], color='0.3', ls=':', marker='x', ms=9, mew=2,
              label='lift-off speed Ω_c (a contact leaves the ground)')
    axis.set_xlabel('angular speed held by the drive  Ω = |ω|  (rad/s)')
    axis.set_ylabel('max over a cycle of μ_required  (–)')
    axis.set_title('Friction needed for rolling without slip, 1 kg laminae, g = 9.81 m/s²',
                   fontsize=10)
    axis.grid(alpha=0.3, which='both')
    axis.legend(fontsize=8, loc='upper left')
    fig.tight_layout()
    _save(fig, path)


def _parser():
    parser = argparse.ArgumentParser(
        prog='python -m twodisk_ros.plotting.contact_forces',
        description='Write the contact-force figures (PNG): N_A, N_B and mu_required over one '
                    'cycle of the oloid at fractions of its lift-off speed, and the friction '
                    'needed against the driven speed for the bodies of config/*.yaml.',
        epilog=f'Writes {NAMES[0]} and {NAMES[1]} into DIR. Exit status: 0 written, 2 bad '
               'arguments or an output refused (one line, nothing written).')
    parser.add_argument('--out', metavar='DIR', default=FIGURES,
                        help=f'output directory, created if missing (default {FIGURES})')
    parser.add_argument('--overwrite', action='store_true',
                        help='replace existing figures (without it they are refused)')
    return parser


def main(argv=None):
    """Write both figures into ``--out``; return the exit status (0, or 2 refused)."""
    args = _parser().parse_args(argv)
    try:
        check_output_dir(args.out, overwrite=args.overwrite, names=NAMES)
    except OutputError as error:
        print(f'contact_forces: {error}', file=sys.stderr)
        return 2
    os.makedirs(args.out, exist_ok=True)
    plot_cycle(os.path.join(args.out, NAMES[0]))
    plot_speed(os.path.join(args.out, NAMES[1]))
    for name in NAMES:
        print(os.path.join(args.out, name))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

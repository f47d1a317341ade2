"""Figures of the contact forces (matplotlib, Agg): over one cycle, and against speed.

Run ``python -m twodisk_ros.plotting.contact_forces`` (from the repository root) to write
docs/figures/contact_forces_cycle.png and docs/figures/contact_forces_speed.png.
The bodies are those of config/*.yaml (mass 1 kg, laminae, g = 9.81 m/s²).
"""

import math
import os
import sys

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from twodisk_ros.physics.body import TwoDiskBody  # noqa: E402
from twodisk_ros.physics.dynamics import RollingDynamics  # noqa: E402
from twodisk_ros.physics.mass_models import mass_properties  # noqa: E402
from twodisk_ros.physics.contact_forces import ContactForceModel  # noqa: E402
from twodisk_ros.physics.contact_validity import (  # noqa: E402
    liftoff_speed, mu_required_kinematic)

__all__ = ['BODIES', 'force_model', 'plot_cycle', 'plot_speed', 'main']

#: (label, (a, b, Δ) in m) as in config/oloid.yaml, two_circle_roller.yaml, figure3/4.yaml
BODIES = (
    ('Oloid (a = b = 0.1 m, Δ = 0.05 m)', (0.1, 0.1, 0.05)),
    ('Two-Circle-Roller (a = b = 0.1 m, Δ = 0.0707 m)', (0.1, 0.1, 0.1 / math.sqrt(2))),
    ('paper Fig. 3 (a = 0.2 m, b = Δ = 0.1 m)', (0.2, 0.1, 0.1)),
    ('paper Fig. 4 (a = 0.1225 m, b = Δ = 0.1 m)', (math.sqrt(1.5) * 0.1, 0.1, 0.1)),
)
FIGURES = os.path.join('docs', 'figures')


def force_model(shape, mass=1.0, model='laminae', gravity=9.81):
    """A :class:`ContactForceModel` for (a, b, Δ) in m."""
    body = TwoDiskBody(*shape)
    return ContactForceModel(RollingDynamics(body, mass_properties(model, *shape, mass),
                                             gravity=gravity))


def plot_cycle(path, shape=BODIES[0][1], fractions=(0.0, 0.5, 0.8, 0.95), samples=1001):
    """N_A/Mg, N_B/Mg and μ_required over one cycle (kinematic) at fractions of Ω_c."""
    model = force_model(shape)
    critical = liftoff_speed(model)[0]
    u = np.linspace(0.0, 2 * math.pi, samples)
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
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_speed(path, bodies=BODIES, samples=160):
    """max over a cycle of μ_required against Ω (kinematic), lift-off speeds marked."""
    fig, axis = plt.subplots(figsize=(8, 5.5))
    colours = plt.cm.tab10(np.arange(len(bodies)))
    for (label, shape), colour in zip(bodies, colours):
        model = force_model(shape)
        critical = liftoff_speed(model)[0]
        omega = critical * np.linspace(0.02, 0.998, samples)
        mu = mu_required_kinematic(model, omega)
        axis.semilogy(omega, mu, color=colour, lw=1.8,
                      label=f'{label}: Ω_c = {critical:.2f} rad/s')
        axis.axvline(critical, color=colour, ls=':', lw=1.2)
        axis.plot(critical, mu[-1], marker='x', ms=9, mew=2, color=colour)
    axis.plot([], [], color='0.3', ls=':', marker='x', ms=9, mew=2,
              label='lift-off speed Ω_c (a contact leaves the ground)')
    axis.set_xlabel('angular speed held by the drive  Ω = |ω|  (rad/s)')
    axis.set_ylabel('max over a cycle of μ_required  (–)')
    axis.set_title('Friction needed for rolling without slip, 1 kg laminae, g = 9.81 m/s²',
                   fontsize=10)
    axis.grid(alpha=0.3, which='both')
    axis.legend(fontsize=8, loc='upper left')
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(directory=FIGURES):
    """Write both figures into ``directory``."""
    os.makedirs(directory, exist_ok=True)
    plot_cycle(os.path.join(directory, 'contact_forces_cycle.png'))
    plot_speed(os.path.join(directory, 'contact_forces_speed.png'))


if __name__ == '__main__':
    main(*sys.argv[1:2])

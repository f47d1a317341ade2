"""The engine's rolling error and its convergence in the contact parameters (issue 31).

The oloid of config/oloid.yaml (a = b = 0.1 m, Δ = 0.05 m, 1 kg, laminae, θ0 = 0.3 rad,
ω0 = 3 rad/s, μ = 0.5) is handed to MuJoCo in its exact rolling state at t = 0
(twodisk_ros.engine.state.engine_state) and run for ``--span`` s; G is compared with the
package's exact motion (simulate, method='table', accurate to ~1e-10 m) every 10 ms. Each row
changes one parameter from the defaults (twodisk_ros.engine.model.ContactParameters), so the
table shows which parameter limits the error: the time step, the contact time constant
(softness: penetration), the mesh resolution n and the plates' thickness. Also the largest
slip speed after the first 0.1 s (the engine's contacts creep where the exact body rolls),
and the wall time of the engine alone.

``python benchmarks/engine_convergence.py [--span 1.0]`` prints a Markdown table.
"""

import argparse
import dataclasses
import time

import numpy as np

from twodisk_ros import EllipseBody, RollingDynamics, simulate
from twodisk_ros.engine.model import ContactParameters
from twodisk_ros.engine.run import Engine
from twodisk_ros.engine.state import engine_state
from twodisk_ros.physics.mass.models import centred_on_mass

VARIANTS = [
    {},
    {'timestep': 1e-3, 'time_constant': 5e-3},
    {'timestep': 2.5e-4},
    {'timestep': 1e-4, 'time_constant': 2e-3},
    {'timestep': 2.5e-4, 'time_constant': 1e-3},
    {'time_constant': 2e-2},
    {'time_constant': 1e-2},
    {'resolution': 64},
    {'resolution': 128},
    {'resolution': 512},
    {'resolution': 1024},
    {'thickness': 1e-2},
    {'thickness': 3e-3},
    {'thickness': 1e-4},
    {'integrator': 'Euler'},
    {'integrator': 'RK4'},
    {'cone': 'pyramidal'},
]


def oloid_run(span):
    """(dynamics, sample times, exact G) of the oloid of config/oloid.yaml."""
    body, props = centred_on_mass('laminae', EllipseBody(0.1, 0.1, 0.05), 1.0)
    dyn = RollingDynamics(body, props, 9.81)
    t = np.linspace(0.0, span, int(round(span / 0.01)) + 1)
    exact = simulate(dyn, t, theta0=0.3, omega0=3.0, method='table')
    return dyn, t, exact


def measure(dyn, t, exact, **changes):
    """G's largest deviation (m), slip after 0.1 s (m/s), wall time (s) of one variant."""
    params = dataclasses.replace(ContactParameters(), **changes)
    engine = Engine(dyn.body, dyn.mass, dyn.gravity, params)
    start = engine_state(dyn, exact.phase[0], 3.0)
    engine.set_state(start.qpos, start.qvel)
    t0 = time.perf_counter()
    samples = engine.sample(t)
    wall = time.perf_counter() - t0
    dev = np.linalg.norm(samples.qpos[:, :3] - exact.states().position_g, axis=1)
    return dev.max(), float(np.nanmax(samples.slip_speed[t > 0.1])), wall


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--span', type=float, default=1.0, help='simulated time (s)')
    args = parser.parse_args()
    dyn, t, exact = oloid_run(args.span)
    print(f'| change from the defaults ({ContactParameters()}) | max |G - G_exact| over '
          f'{args.span:g} s (mm) | max slip after 0.1 s (mm/s) | engine wall (s) |')
    print('|---|---|---|---|')
    for changes in VARIANTS:
        dev, slip, wall = measure(dyn, t, exact, **changes)
        label = ', '.join(f'{k}={v}' for k, v in changes.items()) or 'defaults'
        print(f'| {label} | {dev * 1e3:.3f} | {slip * 1e3:.3f} | {wall:.3f} |', flush=True)


if __name__ == '__main__':
    main()

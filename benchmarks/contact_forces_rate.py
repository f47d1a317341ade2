"""States per second of the contact-force evaluation (not a unit test).

One million states of a simulated oloid motion (phases over many cycles, as a recording
would ask) and one million random phases (no locality), dynamic and kinematic; best of
``REPEAT`` wall-clock runs each, table build excluded (reported separately).

Run: ``python benchmarks/contact_forces_rate.py``.
"""

import time

import numpy as np

from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics import RollingDynamics, simulate
from twodisk_ros.physics.mass.models import mass_properties
from twodisk_ros.physics.forces.contact import ContactForceModel

STATES = 10**6
REPEAT = 5


def best_of(function):
    times = []
    for _ in range(REPEAT):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main():
    body = EllipseBody.oloid(0.1)
    dynamics = RollingDynamics(body, mass_properties('laminae', 0.1, 0.1, 0.05, 1.0))
    start = time.perf_counter()
    model = ContactForceModel(dynamics)
    model.dynamic(0.0, 1.0)
    model.kinematic(0.0, 1.0)
    build = time.perf_counter() - start
    motion = simulate(dynamics, np.linspace(0.0, 1000.0, STATES), omega0=6.0)
    rng = np.random.default_rng(1)
    random_u = rng.uniform(-100.0, 100.0, STATES)
    cases = {
        'dynamic, along a motion': lambda: model.dynamic(motion.phase, motion.phase_rate),
        'dynamic, random phases': lambda: model.dynamic(random_u, motion.phase_rate),
        'kinematic, random phases': lambda: model.kinematic(random_u, 5.0),
        'general (u, u_dot, u_ddot)': lambda: model.forces(random_u, 3.0, 1.0),
    }
    print(f'table build ({model.nodes} nodes): {build * 1e3:.1f} ms')
    for name, case in cases.items():
        wall = best_of(case)
        print(f'{name:28s} {STATES} states in {wall:.3f} s: {STATES / wall / 1e6:.2f} M states/s')


if __name__ == '__main__':
    import argparse
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    main()

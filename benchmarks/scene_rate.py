"""Samples per second of a scene's motion against today's flat free table method (not a test).

The oloid (a = b = 0.1 m, Δ = 0.05 m, 1 kg laminae) from θ0 = 0.3 rad at 3 rad/s, sampled at
1 kHz for 10 s of simulated time, in one run: the flat free scene (MotionStream, the table
method's quadrature), the general integrator on flat ground, on a slope across the fall line
(it rocks), with damping, and driven by a torque. Wall clock of a fresh stream each (tables
built beforehand and reported separately), best of ``REPEAT``.

Run: ``python benchmarks/scene_rate.py``.
"""

import argparse
import math
import time

import numpy as np

from twodisk_ros.physics import MotionStream, RollingDynamics, TwoDiskBody
from twodisk_ros.physics.mass_models import mass_properties
from twodisk_ros.physics.scene import Scene
from twodisk_ros.physics.scene_motion import SceneStream
from twodisk_ros.physics.scene_terms import SceneTerms

REPEAT = 3
DURATION, RATE = 10.0, 1000.0


def best_of(function):
    times = []
    for _ in range(REPEAT):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main():
    shape = (0.1, 0.1, 0.05)
    dynamics = RollingDynamics(TwoDiskBody(*shape), mass_properties('laminae', *shape, 1.0))
    u0 = float(dynamics.body.phase_from_theta(0.3, 1))
    u_dot0 = dynamics.initial_phase_rate(u0, 3.0)
    t = np.arange(0.0, DURATION, 1.0 / RATE)
    rows = [('flat free, MotionStream (table)',
             lambda: MotionStream(dynamics, u0, u_dot0).sample(t))]
    start = time.perf_counter()
    flat_terms = SceneTerms(dynamics, Scene())
    print(f'SceneTerms build: {time.perf_counter() - start:.3f} s')
    scenes = [('flat free, general integrator', Scene()),
              ('slope 0.2 rad across (rocks)', Scene(slope=0.2, heading0=math.pi / 2)),
              ('slope 0.05 rad downhill', Scene(slope=0.05)),
              ('damping 0.01 N m s', Scene(damping=0.01)),
              ('rolling resistance 0.01', Scene(rolling_resistance=0.01)),
              ('torque 0.01 N m', Scene(drive='torque', command=0.01))]
    for name, scene in scenes:
        terms = SceneTerms(dynamics, scene, model=flat_terms.model)
        rows.append((name, lambda terms=terms: SceneStream(terms, u0, u_dot0).samples(t)))
    for name, run in rows:
        seconds = best_of(run)
        print(f'{name:38s} {t.size / seconds:12.0f} samples/s  ({seconds:.3f} s for '
              f'{DURATION:g} s at {RATE:g} Hz)')


if __name__ == '__main__':
    argparse.ArgumentParser(description=__doc__.split('\n')[0]).parse_args()
    main()

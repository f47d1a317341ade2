#!/usr/bin/env python3
"""Samples per second of a scene's motion beside the flat free table method (not a test).

Part of ``make bench`` (docs/benchmarks.md, section "Scenes"). The oloid (a = b = 0.1 m,
Δ = 0.05 m, 1 kg laminae, config/oloid.yaml) from θ0 = 0.3 rad at 3 rad/s, sampled at 1 kHz
for 10 s of simulated time, in one run, each a fresh stream (its construction included; the
scene's tables are built beforehand and their cost reported on its own), best of ``REPEATS``
(the flat case's best over runs beside every scene):

* the flat free scene: the level ground's ``MotionStream`` (the table method's quadrature);
* conservative scenes on a slope through ``scene_stream`` (the closed forms of
  physics/scenes/closed.py): rolling on down a 0.05 rad slope (quadrature with the drift
  composed) and swinging across a 0.2 rad slope (oscillation between turning points);
  target: within 2× of the flat case (``TARGET_RATIO``);
* the general integrator (DOP853, ``SceneStream``) where the scene needs it: on flat ground
  (for comparison), damping, rolling resistance, a torque and a speed drive.

``sample`` gives (u, u̇) as ``MotionStream.sample`` does; the ``samples`` column adds ü,
energies, the drive's torque and power (``SceneSamples``).

Run: ``python benchmarks/scene_rate.py [--quick]``.
"""

import argparse
import math
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

import numpy as np  # noqa: E402

from twodisk_ros.physics import MotionStream, RollingDynamics, EllipseBody  # noqa: E402
from twodisk_ros.physics.mass.models import mass_properties  # noqa: E402
from twodisk_ros.physics.scenes.scene import Scene  # noqa: E402
from twodisk_ros.physics.scenes.motion import SceneStream, scene_stream  # noqa: E402
from twodisk_ros.physics.scenes.terms import SceneTerms  # noqa: E402

REPEATS = 3
DURATION, RATE = 10.0, 1000.0
TARGET_RATIO = 2.0
SHAPE = (0.1, 0.1, 0.05)
#: (key, description, scene, path): 'closed' through scene_stream, 'ode' a SceneStream
SCENES = [
    ('slope_down', 'slope 0.05 rad downhill (rolls on, accelerating)',
     Scene(slope=0.05), 'closed'),
    ('slope_across', 'slope 0.2 rad across (swings over two wells)',
     Scene(slope=0.2, heading0=0.5 * math.pi), 'closed'),
    ('flat_ode', 'flat, general integrator (DOP853)', Scene(), 'ode'),
    ('slope_down_ode', 'slope 0.05 rad downhill, DOP853', Scene(slope=0.05), 'ode'),
    ('damping', 'damping 0.01 N m s', Scene(damping=0.01), 'ode'),
    ('rolling', 'rolling resistance 0.01', Scene(rolling_resistance=0.01), 'ode'),
    ('torque', 'torque 0.01 N m', Scene(drive='torque', command=0.01), 'ode'),
    ('speed', 'speed drive 4 rad/s (lag 0.1 s)', Scene(drive='speed', command=4.0), 'ode'),
]


def _best(function, repeats):
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        walls.append(time.perf_counter() - start)
    return min(walls)


def measure(quick=False, log=print):
    """The measurements (a dict): samples/s of every scene of :data:`SCENES` and the flat case."""
    repeats = 1 if quick else REPEATS
    duration = DURATION / 10 if quick else DURATION
    dynamics = RollingDynamics(EllipseBody(*SHAPE), mass_properties('laminae', *SHAPE, 1.0))
    u0 = float(dynamics.body.phase_from_theta(0.3, 1))
    u_dot0 = dynamics.initial_phase_rate(u0, 3.0)
    t = np.arange(0.0, duration, 1.0 / RATE)
    def flat_run():
        return MotionStream(dynamics, u0, u_dot0).sample(t)
    # the flat case is timed again beside every scene (best of all): on a shared machine one
    # early best-of-3 can catch a busy moment and flatter every ratio (or spoil it)
    flat_wall = _best(flat_run, repeats)
    start = time.perf_counter()
    model = SceneTerms(dynamics, Scene(slope=0.05)).model
    build = time.perf_counter() - start
    rows = []
    for key, text, scene, path in SCENES:
        terms = SceneTerms(dynamics, scene, model=model)

        def stream():
            if path == 'closed':
                return scene_stream(dynamics, scene, u0, u_dot0, terms=terms)
            return SceneStream(terms, u0, u_dot0)
        solver = stream().solver
        flat_wall = min(flat_wall, _best(flat_run, repeats))
        rate = t.size / _best(lambda: stream().sample(t), repeats)
        full = t.size / _best(lambda: stream().samples(t), repeats)
        flat_wall = min(flat_wall, _best(flat_run, repeats))
        rows.append(dict(key=key, text=text, path=path, solver=solver, rate=rate, full=full))
        log(f'   {text}: {solver}, {rate:.3g} samples/s (samples: {full:.3g}/s)')
    flat = t.size / flat_wall
    log(f'   flat free MotionStream: {flat:.3g} samples/s')
    for row in rows:
        row['ratio'] = flat / row['rate']
    return dict(flat=flat, rows=rows, build=build, duration=duration, rate=RATE,
                repeats=repeats)


def report_lines(m):
    """The report's section (Markdown lines)."""
    lines = []
    w = lines.append
    w('## Scenes\n')
    w(f'`benchmarks/scene_rate.py`: the oloid (config/oloid.yaml) from θ0 = 0.3 rad at 3 rad/s, '
      f'{m["duration"]:g} s at {m["rate"]:g} Hz, a fresh stream each (construction included), '
      f'best of {m["repeats"]}. The scene tables (`SceneTerms`, with the contact-force model) '
      f'took {m["build"]:.3f} s. Flat free `MotionStream`: {m["flat"]:.3g} samples/s. '
      f'Target: the conservative scenes on a slope (closed forms) within {TARGET_RATIO:g}× '
      f'of the flat case.\n')
    w('| scene | path | solver | sample: samples/s | × flat time | samples (with ü, E, '
      'torque): samples/s |')
    w('|---|---|---|---|---|---|')
    for r in m['rows']:
        mark = ' ✓' if r['path'] == 'closed' and r['ratio'] <= TARGET_RATIO else (
            ' ✗' if r['path'] == 'closed' else '')
        w(f'| {r["text"]} | {"closed form" if r["path"] == "closed" else "DOP853"} | '
          f'{r["solver"]} | {r["rate"]:.3g} | {r["ratio"]:.2f}{mark} | {r["full"]:.3g} |')
    w('')
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--quick', action='store_true', help='1 s of motion, one repeat')
    args = parser.parse_args()
    print('\n'.join(report_lines(measure(quick=args.quick))))


if __name__ == '__main__':
    main()

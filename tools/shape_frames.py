"""PNG frames of bodies of non-elliptic laminae, drawn by the package's animation code.

Until LaminaBody (issue 20) drives the cycle and the dynamics, the run is made here from
GeneralTwoDiskBody's exact resting poses, rolled without slipping by a discrete rule: between
consecutive poses the body turns by the smallest rotation taking the new ground normal to the
old one (the rolling axis AB lies in the ground, so there is no spin about the normal) about
the body point midway between the two A's, which stays put on the ground. This is a drawing
aid (second order in the step), not the package's kinematics (physics/cycle.py).

    PYTHONPATH=$PWD python tools/shape_frames.py OUTDIR [--overwrite]
"""

import argparse
import math
import os
import sys

import numpy as np

from twodisk_ros.physics.general_body import GeneralTwoDiskBody
from twodisk_ros.physics.lamina import Egg, Superellipse
from twodisk_ros.plotting.animation import still
from twodisk_ros.runs import Run


def _align(n_from, n_to):
    """The smallest rotation matrix taking unit vector ``n_from`` to ``n_to``."""
    axis = np.cross(n_from, n_to)
    sine, cosine = np.linalg.norm(axis), float(np.dot(n_from, n_to))
    if sine < 1e-15:
        return np.eye(3)
    k = axis / sine
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + sine * cross + (1 - cosine) * cross @ cross


def rolled_run(body, cycles=1.5, steps=720, duration=6.0, label=''):
    """A Run of ``body`` (GeneralTwoDiskBody) rolled over ``cycles`` cycles in ``steps``
    steps per cycle, timed uniformly over ``duration`` s."""
    v = np.linspace(0.0, 2 * math.pi * cycles, int(steps * cycles) + 1)
    theta = np.clip(body.theta_max * np.sin(v), -body.theta_max, body.theta_max)
    branch = np.where(np.cos(v) >= 0, 1, -1)
    poses = [body.geometry(theta[branch == s], s) for s in (1, -1)]
    a, b, n, height = (np.empty((len(v), 3)), np.empty((len(v), 3)), np.empty((len(v), 3)),
                       np.empty(len(v)))
    for s, pose in zip((1, -1), poses):
        a[branch == s], b[branch == s] = pose.contact_a, pose.contact_b
        n[branch == s], height[branch == s] = pose.ground_normal, pose.height
    rotation = np.empty((len(v), 3, 3))
    position = np.empty((len(v), 3))
    rotation[0] = _align(n[0], np.array([0.0, 0.0, 1.0]))
    # start with A at the origin and disk 1's tangent along +X
    position[0] = -rotation[0] @ a[0]
    for k in range(len(v) - 1):
        rotation[k + 1] = rotation[k] @ _align(n[k + 1], n[k])
        middle = 0.5 * (a[k] + a[k + 1])
        position[k + 1] = position[k] + (rotation[k] - rotation[k + 1]) @ middle
        position[k + 1, 2] = height[k + 1]
    world_a = position + np.einsum('kij,kj->ki', rotation, a)
    world_b = position + np.einsum('kij,kj->ki', rotation, b)
    t = np.linspace(0.0, duration, len(v))
    return Run(body, t, position, world_a, world_b, rotation, label=label)


BODIES = {
    'superellipse6': (GeneralTwoDiskBody(Superellipse(0.2, 0.2, 6), 0.1),
                      'Superellipse(a = b = 0.2 m, n = 6), Δ = 0.1 m'),
    'egg': (GeneralTwoDiskBody(Egg(0.2, 0.16, 0.012), 0.08),
            'Egg(a = 0.2 m, b = 0.16 m, ε = 0.012 m), Δ = 0.08 m, parallel'),
}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('outdir')
    parser.add_argument('--overwrite', action='store_true')
    args = parser.parse_args(argv)
    written = []
    for name, (body, label) in BODIES.items():
        run = rolled_run(body, label=label)
        for view, at in (('3d', 2.5), ('top', 5.0)):
            path = os.path.join(args.outdir, f'{name}_{view}.png')
            if os.path.exists(path) and not args.overwrite:
                print(f'{path} exists (use --overwrite)', file=sys.stderr)
                return 2
            still(run, path, at=at, view=view, size=(640, 480))
            written.append(path)
    print('\n'.join(written))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

#!/usr/bin/env python3
"""MuJoCo or Drake as the free-body engine of ``contact_model:=hybrid`` (issue 31), measured.

The same body in both engines: the two plates of :func:`~twodisk_ros.model.mesh.mesh_parts`
(the vertices twodisk_ros/engine/model.py gives MuJoCo, n = 512, 1e-3 of the size thick) as
convex hulls, the mass model's mass and inertia about G, Coulomb μ, the ground the plane
z = 0 of the (slope) frame, gravity tilted in it, time step 0.5 ms (MuJoCo's default setting,
:class:`~twodisk_ros.engine.model.ContactParameters`). MuJoCo runs through
:class:`~twodisk_ros.engine.run.Engine` (its soft contact, τ = 5 ms, implicitfast, elliptic
cone), and at benchmarks/hybrid_cost.py's finer settings (n = 2048, τ = 1 ms, h = 0.1 ms:
"MuJoCo fine"). Drake (pydrake, MultibodyPlant, discrete) uses **point contact** (one contact
per plate and ground, compliant: stiffness 1e6 N/m per geometry, 5e5 N/m per contact, so G
sinks M g / 1e6 N/m ≈ 1e-5 m at rest, MuJoCo's 1.4e-5 m; Hunt–Crossley dissipation 50 s/m), solved by
**TAMSI** and by **SAP** (its *lagged* approximation, Drake's default: the same contact model
as TAMSI). Hydroelastic contact is not tried: the plates are 0.1 mm thick prisms, and
hydroelastic contact needs compliant volumes.

Runs, each engine from the same state, G sampled every 10 ms:

(a) slide: the oloid (config/oloid.yaml's body) at rest in its rolling rest pose, contact
    line along the fall line of a 0.3 rad slope, μ = 0.1, 0.5 s: G's acceleration along the
    fall line (a fit of x = x0 + v0 t + a t²/2 over 0.05 … 0.5 s) against g (sin β − μ cos β);
(b) flight: the oloid thrown up with spin, 0.4 s clear of the ground: G against the parabola,
    the angular momentum about G (world) against its start value;
(c) rolling: the oloid from config/oloid.yaml's start (θ0 = 0.3 rad, ω0 = 3 rad/s, μ = 0.5)
    on level ground: G against the package's exact rolling motion
    (:class:`~twodisk_ros.run.simulation.Simulation`, contact_model rolling);
(d) rounded square (config/rounded_square.yaml, μ = 0.5) from its start: the energy
    E = ½ M v² + ½ ωᵀ I ω + M g z over the run (the body slips at its vertices, where
    friction takes energy: no exact reference), and the cost;
(e) (c) over 1 s stepped one step at a time from Python, the state read after each step (as
    the hybrid steps its engine stretches): the cost per simulated second.

For each: CPU seconds (process time of the stepping) per simulated second, the errors and the
penetration (the deepest mesh vertex below the ground over the run). Engines alternate run by
run (``--repeats``, order swapped each time), the least CPU is kept; the load average is
recorded with each case. Writes the section between ``<!-- engine-choice:begin -->`` and
``<!-- engine-choice:end -->`` of docs/benchmarks.md and prints JSON.

Needs pydrake, which is not a dependency of the package: run it with a scratch venv, e.g.
``python -m venv /tmp/drakevenv && python -m pip --python /tmp/drakevenv/bin/python install
drake==1.51.1`` plus the package's pins (requirements.txt) of numpy, scipy, PyYAML, mujoco and
mujoco-core, then
``PYTHONPATH=$PWD /tmp/drakevenv/bin/python benchmarks/engine_choice.py [--quick]``.
"""

import argparse
import json
import math
import os
import sys
import time

from sections import provenance, replace_section

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BEGIN, END = '<!-- engine-choice:begin -->', '<!-- engine-choice:end -->'
DT = 0.01                    #: s between samples
STIFFNESS = 1e6              #: N/m, Drake point contact, per geometry
DISSIPATION = 50.0           #: s/m, Drake Hunt–Crossley dissipation
HOW = ('engine_choice.py needs pydrake (Drake), not a dependency: python -m venv /tmp/drakevenv '
       '&& python -m pip --python /tmp/drakevenv/bin/python install drake==1.51.1 and the pins of '
       'numpy, scipy, PyYAML, mujoco, mujoco-core; run it with /tmp/drakevenv/bin/python')


def _parser():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--quick', action='store_true', help='shorter runs, one repeat (smoke)')
    parser.add_argument('--repeats', type=int, default=3,
                        help='runs per engine and case, alternated (default 3)')
    parser.add_argument('--out', default=os.path.join(ROOT, 'docs', 'benchmarks.md'),
                        help='the report whose section is written (default docs/benchmarks.md)')
    parser.add_argument('--no-write', action='store_true', help='print the JSON only')
    return parser


def _matrix(q):
    from twodisk_ros.engine.state import quaternion_matrix
    return quaternion_matrix(q / math.sqrt(sum(x * x for x in q)))


class MujocoBody:
    """MuJoCo through :class:`~twodisk_ros.engine.run.Engine` (the package's engine)."""

    name = 'MuJoCo'

    changes = {}

    def __init__(self, dyn, mu, slope):
        from twodisk_ros.engine.model import ContactParameters
        from twodisk_ros.engine.run import Engine
        self.engine = Engine(dyn.body, dyn.mass, dyn.gravity,
                             ContactParameters(mu=mu, **self.changes), slope=slope)

    def start(self, qpos, qvel):
        """From MuJoCo's free-joint state (G, quaternion w x y z; v_G world, ω body)."""
        self.engine.set_state(qpos, qvel, 0.0)

    def advance(self, t):
        self.engine.step_to(t)

    def state(self):
        """(G (3,) m, R body → world, v_G (3,) m/s world, ω (3,) rad/s world)."""
        d = self.engine.data
        rotation = _matrix(d.qpos[3:7])
        return d.qpos[:3].copy(), rotation, d.qvel[:3].copy(), rotation @ d.qvel[3:6]


class MujocoFine(MujocoBody):
    """MuJoCo at benchmarks/hybrid_cost.py's finer settings (its cost of more accuracy)."""

    name = 'MuJoCo fine'
    changes = dict(resolution=2048, time_constant=1e-3, timestep=1e-4)


class DrakeBody:
    """The same body in Drake's MultibodyPlant (module docstring), SAP solver."""

    name = 'Drake SAP'
    approximation = 'lagged'    #: Drake's default: the TAMSI model solved by SAP

    def __init__(self, dyn, mu, slope):
        import numpy as np
        import logging
        from pydrake.geometry import AddContactMaterial, Convex, HalfSpace, ProximityProperties
        from pydrake.math import RigidTransform
        from pydrake.multibody.plant import (AddMultibodyPlant, CoulombFriction,
                                             MultibodyPlantConfig)
        from pydrake.multibody.tree import RotationalInertia, SpatialInertia
        from pydrake.systems.analysis import Simulator
        from pydrake.systems.framework import DiagramBuilder
        from twodisk_ros.engine.model import ContactParameters, gravity_vector
        from twodisk_ros.model.mesh import mesh_parts

        logging.getLogger('drake').setLevel(logging.ERROR)   # not the warning that half spaces are not deformable
        p = ContactParameters(mu=mu)
        builder = DiagramBuilder()
        plant, _ = AddMultibodyPlant(MultibodyPlantConfig(
            time_step=p.timestep, contact_model='point',
            discrete_contact_approximation=self.approximation),
            builder)
        i = dyn.mass.inertia
        inertia = RotationalInertia(i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2])
        self.body = plant.AddRigidBody('body', SpatialInertia.MakeFromCentralInertia(
            dyn.mass.mass, np.zeros(3), inertia))

        def props():
            out = ProximityProperties()
            AddContactMaterial(DISSIPATION, STIFFNESS, CoulombFriction(mu, mu), out)
            return out
        parts = mesh_parts(dyn.body, dyn.mass, p.resolution, p.thickness * dyn.body.size)
        for name, mesh in parts.items():
            plant.RegisterCollisionGeometry(self.body, RigidTransform(),
                                            Convex(np.asarray(mesh.vertices).T.copy(), name),
                                            name, props())
        plant.RegisterCollisionGeometry(plant.world_body(), RigidTransform(), HalfSpace(),
                                        'ground', props())
        plant.mutable_gravity_field().set_gravity_vector(gravity_vector(dyn.gravity, slope))
        plant.Finalize()
        self.plant = plant
        self.simulator = Simulator(builder.Build())
        self.context = plant.GetMyMutableContextFromRoot(self.simulator.get_mutable_context())

    def start(self, qpos, qvel):
        import numpy as np
        from pydrake.common.eigen_geometry import Quaternion
        from pydrake.math import RigidTransform
        from pydrake.multibody.math import SpatialVelocity
        root = self.simulator.get_mutable_context()
        root.SetTime(0.0)
        q = np.asarray(qpos[3:7], dtype=float)
        self.plant.SetFreeBodyPose(self.context, self.body, RigidTransform(
            Quaternion(q / np.linalg.norm(q)), np.asarray(qpos[:3], dtype=float)))
        omega = _matrix(qpos[3:7]) @ np.asarray(qvel[3:6], dtype=float)
        self.plant.SetFreeBodySpatialVelocity(self.context, self.body, SpatialVelocity(
            omega, np.asarray(qvel[:3], dtype=float)))
        self.simulator.Initialize()

    def advance(self, t):
        self.simulator.AdvanceTo(t)

    def state(self):
        pose = self.plant.EvalBodyPoseInWorld(self.context, self.body)
        velocity = self.plant.EvalBodySpatialVelocityInWorld(self.context, self.body)
        return (pose.translation().copy(), pose.rotation().matrix().copy(),
                velocity.translational().copy(), velocity.rotational().copy())


class DrakeTamsi(DrakeBody):
    """The same, TAMSI solver (same contact model as SAP's lagged approximation)."""

    name = 'Drake TAMSI'
    approximation = 'tamsi'


def _vertices(dyn):
    import numpy as np
    from twodisk_ros.engine.model import ContactParameters
    from twodisk_ros.model.mesh import mesh_parts
    p = ContactParameters()
    parts = mesh_parts(dyn.body, dyn.mass, p.resolution, p.thickness * dyn.body.size)
    return np.concatenate([np.asarray(m.vertices) for m in parts.values()])


def _trace(engine_class, dyn, mu, slope, qpos, qvel, times):
    """Build, start, step through ``times``: dict of arrays (G, R, v, ω world; penetration m)
    and the CPU seconds of the build and of the stepping."""
    import numpy as np
    vertices = _vertices(dyn)
    clock = time.process_time()
    engine = engine_class(dyn, mu, slope)
    engine.start(qpos, qvel)
    build = time.process_time() - clock
    rows, cpu = [], 0.0
    for t in times:
        clock = time.process_time()
        engine.advance(t)
        cpu += time.process_time() - clock
        g, rotation, v, omega = engine.state()
        depth = -float(np.min((vertices @ rotation.T)[:, 2] + g[2]))
        rows.append((g, rotation, v, omega, max(depth, 0.0)))
    g, rotation, v, omega, depth = (np.array(x) for x in zip(*rows))
    return dict(g=g, rotation=rotation, v=v, omega=omega, depth=depth, cpu=cpu, build=build)


def _energy(dyn, tr, slope=0.0):
    import numpy as np
    from twodisk_ros.engine.model import gravity_vector
    m, inertia = dyn.mass.mass, dyn.mass.inertia
    omega_body = np.einsum('nji,nj->ni', tr['rotation'], tr['omega'])
    return (0.5 * m * np.einsum('ij,ij->i', tr['v'], tr['v'])
            + 0.5 * np.einsum('ij,jk,ik->i', omega_body, inertia, omega_body)
            - m * tr['g'] @ gravity_vector(dyn.gravity, slope))


def _oloid(values=None):
    from twodisk_ros.run.description import RunDescription
    from twodisk_ros.run.parameters import DEFAULTS
    from twodisk_ros.plotting.hybrid_results import OLOID
    values = dict(OLOID, friction=0.5) if values is None else values
    settings = DEFAULTS.with_values(**values, contact_model='rolling').checked()
    return settings, RunDescription(settings)


def _rest_state(dyn):
    """(qpos, qvel) of the oloid at rest in its lowest rolling pose, contact line AB along x."""
    import numpy as np
    from scipy.optimize import minimize_scalar
    from twodisk_ros.engine.state import engine_state
    grid = np.linspace(0.0, 2 * math.pi, 257)
    heights = [engine_state(dyn, u, 0.0).qpos[2] for u in grid]
    k = int(np.argmin(heights))
    u = minimize_scalar(lambda x: engine_state(dyn, x, 0.0).qpos[2],
                        bracket=(grid[k - 1], grid[k], grid[k + 1]), tol=1e-12).x
    state = engine_state(dyn, u, 0.0)
    from twodisk_ros.model.mesh import mesh_parts
    low = []
    for mesh in mesh_parts(dyn.body, dyn.mass, 512).values():
        world = np.asarray(mesh.vertices) @ _matrix(state.qpos[3:7]).T + state.qpos[:3]
        low.append(world[np.argmin(world[:, 2])])
    ab = low[1] - low[0]
    return engine_state(dyn, u, 0.0, yaw=-math.atan2(ab[1], ab[0]))


def case_slide(engine_class, quick):
    import numpy as np
    slope, mu, span = 0.3, 0.1, 0.5
    _, run = _oloid()
    dyn = run.dynamics
    state = _rest_state(dyn)
    times = np.arange(1, int(round(span / DT)) + 1) * DT
    tr = _trace(engine_class, dyn, mu, slope, state.qpos, state.qvel, times)
    fit = times >= 0.05
    x = tr['g'][fit, 0]
    basis = np.stack([np.ones(fit.sum()), times[fit], 0.5 * times[fit] ** 2], axis=1)
    accel = float(np.linalg.lstsq(basis, x, rcond=None)[0][2])
    exact = dyn.gravity * (math.sin(slope) - mu * math.cos(slope))
    turn = max(float(np.arccos(np.clip((np.trace(r @ _matrix(state.qpos[3:7]).T) - 1) / 2,
                                       -1, 1))) for r in tr['rotation'])
    return dict(span=span, cpu=tr['cpu'], build=tr['build'], accel=accel, exact=exact,
                rel_error=abs(accel / exact - 1), turn=turn,
                lateral=float(np.max(np.abs(tr['g'][:, 1] - state.qpos[1]))),
                depth=float(tr['depth'].max()))


def case_flight(engine_class, quick):
    import numpy as np
    span = 0.4
    _, run = _oloid()
    dyn = run.dynamics
    qpos = np.array([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    qvel = np.array([0.5, 0.2, 2.0, 3.0, -2.0, 8.0])
    times = np.arange(1, int(round(span / DT)) + 1) * DT
    tr = _trace(engine_class, dyn, 0.5, 0.0, qpos, qvel, times)
    parabola = qpos[:3] + np.outer(times, qvel[:3]) \
        + np.outer(0.5 * times ** 2, [0.0, 0.0, -dyn.gravity])
    momentum0 = dyn.mass.inertia @ qvel[3:]
    omega_body = np.einsum('nji,nj->ni', tr['rotation'], tr['omega'])
    momentum = np.einsum('nij,jk,nk->ni', tr['rotation'], dyn.mass.inertia, omega_body)
    energy = 0.5 * np.einsum('ij,jk,ik->i', omega_body, dyn.mass.inertia, omega_body)
    energy0 = 0.5 * qvel[3:] @ dyn.mass.inertia @ qvel[3:]
    return dict(span=span, cpu=tr['cpu'], build=tr['build'],
                g_error=float(np.max(np.linalg.norm(tr['g'] - parabola, axis=1))),
                momentum_rel=float(np.max(np.linalg.norm(momentum - momentum0, axis=1))
                                   / np.linalg.norm(momentum0)),
                spin_energy_rel=float(np.max(np.abs(energy / energy0 - 1))),
                depth=float(tr['depth'].max()))


def _rolling_case(engine_class, settings, run, span):
    import numpy as np
    from twodisk_ros.engine.state import engine_state
    from twodisk_ros.run.simulation import Simulation
    dyn = run.dynamics
    times = np.arange(1, int(round(span / DT)) + 1) * DT
    start = run.start()
    state = engine_state(dyn, start.phase, settings.omega0)
    exact = Simulation(settings, run).sample(np.concatenate([[0.0], times])).position_g
    if np.linalg.norm(exact[0] - state.qpos[:3]) > 1e-9:
        raise RuntimeError('the rolling start and the engine start differ')
    tr = _trace(engine_class, dyn, settings.friction, 0.0, state.qpos, state.qvel, times)
    energy = _energy(dyn, tr)
    v0 = state.qvel[:3]
    w0 = _matrix(state.qpos[3:7]) @ state.qvel[3:]
    first = dict(g=state.qpos[None, :3], rotation=_matrix(state.qpos[3:7])[None],
                 v=v0[None], omega=w0[None])
    energy0 = float(_energy(dyn, first)[0])
    error = np.linalg.norm(tr['g'] - exact[1:], axis=1)
    return dict(span=span, cpu=tr['cpu'], build=tr['build'], energy0=energy0,
                energy_end=float(energy[-1]), energy_dev=float(np.max(np.abs(energy - energy0))),
                g_error_max=float(error.max()), g_error_end=float(error[-1]),
                g_error_1s=float(error[min(len(error), int(round(1.0 / DT))) - 1]),
                travel=float(np.linalg.norm(tr['g'][-1, :2] - state.qpos[:2])),
                depth=float(tr['depth'].max()))


def case_rolling(engine_class, quick):
    settings, run = _oloid()
    return _rolling_case(engine_class, settings, run, 1.0 if quick else 3.0)


def case_square(engine_class, quick):
    from twodisk_ros.plotting.hybrid_results import ROUNDED_SQUARE
    settings, run = _oloid(dict(ROUNDED_SQUARE, friction=0.5))
    return _rolling_case(engine_class, settings, run, 1.0 if quick else 3.0)


def case_steps(engine_class, quick):
    """The oloid rolling for 1 s, stepped one step at a time from Python with the state read
    after each step (as the hybrid steps its engine stretches, checking its return rule)."""
    from twodisk_ros.engine.model import ContactParameters
    from twodisk_ros.engine.state import engine_state
    settings, run = _oloid()
    state = engine_state(run.dynamics, run.start().phase, settings.omega0)
    engine = engine_class(run.dynamics, settings.friction, 0.0)
    engine.start(state.qpos, state.qvel)
    step = ContactParameters(**getattr(engine_class, 'changes', {})).timestep
    count = int(round(1.0 / step))
    clock = time.process_time()
    for k in range(1, count + 1):
        engine.advance(k * step)
        engine.state()
    return dict(span=1.0, cpu=time.process_time() - clock, build=0.0)


CASES = (('slide', case_slide), ('flight', case_flight), ('rolling', case_rolling),
         ('square', case_square), ('steps', case_steps))


def measure(quick=False, repeats=3):
    """{case: {'load': [...], engine: result (least CPU of the repeats, 'cpus': all)}}."""
    sys.path.insert(0, ROOT)
    engines = (MujocoBody, DrakeTamsi, DrakeBody, MujocoFine)
    out = {}
    for name, case in CASES:
        results = {e.name: [] for e in engines}
        load = [os.getloadavg()[0]]
        for k in range(repeats):
            for engine in (engines if k % 2 == 0 else engines[::-1]):
                results[engine.name].append(case(engine, quick))
        load.append(os.getloadavg()[0])
        out[name] = dict(load=load)
        for engine, runs in results.items():
            best = dict(runs[0])
            best['cpus'] = [r['cpu'] for r in runs]
            best['cpu'] = min(best['cpus'])
            best['builds'] = [r['build'] for r in runs]
            out[name][engine] = best
        print(name, json.dumps(out[name]), file=sys.stderr, flush=True)
    return out


def _per_second(r):
    return r['cpu'] / r['span']


def section(out, machine, date, commit):
    names = ('MuJoCo', 'Drake TAMSI', 'Drake SAP', 'MuJoCo fine')
    m = names[0]
    s, f, r, q = (out[k] for k in ('slide', 'flight', 'rolling', 'square'))
    loads = ', '.join(f'{k} {c["load"][0]:.1f}–{c["load"][1]:.1f}' for k, c in out.items())
    lines = [BEGIN, '## Beyond rolling: which free-body engine (MuJoCo or Drake)', '',
             f'`benchmarks/engine_choice.py` (run with pydrake in a scratch venv, drake 1.51.1; '
             f'not a dependency), {date}, commit {commit[:10]}, {machine}; load average during '
             f'each case: {loads} (the machine is shared: the CPU ratios are those of runs '
             'alternated in one process, the least of the repeats). The same body in each '
             '(the plates of twodisk_ros/engine/model.py, n = 512, as convex hulls; the mass '
             'model\'s mass and inertia; Coulomb μ; step 0.5 ms). **MuJoCo**: the package\'s '
             'engine (twodisk_ros/engine: soft contact τ = 5 ms, implicitfast, elliptic cone). '
             '**Drake**: MultibodyPlant, point contact (compliant, 1e6 N/m per geometry, '
             'Hunt–Crossley dissipation 50 s/m), with the TAMSI solver or the SAP solver (its '
             '*lagged* approximation, Drake\'s default: the same contact model as TAMSI, so the '
             'same motion to the solvers\' tolerance). **MuJoCo fine**: n = 2048, τ = 1 ms, '
             'h = 0.1 ms (benchmarks/hybrid_cost.py\'s finer settings). Penetration: the deepest '
             'mesh vertex below the ground over the run. CPU: process time of the stepping per '
             'simulated second. (d) has no error column: with μ = 0.5 the rounded square slips '
             'at its vertices (README "Beyond rolling"), where friction takes energy, so its '
             'exact rolling motion is no reference there; E shows each engine\'s energy '
             'behaviour over the slips and landings.', '',
             '| run | quantity | ' + ' | '.join(names) + ' |',
             '| --- | --- | ' + ' | '.join('---' for _ in names) + ' |']

    def row(c, what, key, fmt, scale=1.0):
        lines.append(f'| {what[0]} | {what[1]} | '
                     + ' | '.join(fmt.format(scale * c[e][key]) for e in names) + ' |')
    lines.append(f'| (a) slide, β = 0.3 rad, μ = 0.1, {s[m]["span"]:g} s | exact g (sin β − '
                 f'μ cos β) = {s[m]["exact"]:.4f} m/s²: fitted (m/s²) | '
                 + ' | '.join(f'{s[e]["accel"]:.4f}' for e in names) + ' |')
    row(s, ('(a)', 'relative error of the acceleration'), 'rel_error', '{:.1e}')
    row(s, ('(a)', 'largest rotation of the body (mrad)'), 'turn', '{:.2f}', 1e3)
    row(s, ('(a)', 'penetration (mm)'), 'depth', '{:.4f}', 1e3)
    row(s, ('(a)', 'CPU per simulated s'), 'cpu', '{:.3f}', 1 / s[m]['span'])
    row(f, (f'(b) flight with spin, {f[m]["span"]:g} s', 'max \\|G − parabola\\| (mm)'),
        'g_error', '{:.3f}', 1e3)
    row(f, ('(b)', 'max \\|L − L0\\| / \\|L0\\| (about G)'), 'momentum_rel', '{:.1e}')
    row(f, ('(b)', 'max \\|ΔE_rot\\| / E_rot'), 'spin_energy_rel', '{:.1e}')
    row(f, ('(b)', 'CPU per simulated s'), 'cpu', '{:.3f}', 1 / f[m]['span'])
    label = f'(c) oloid rolling (config/oloid.yaml), {r[m]["span"]:g} s'
    row(r, (label, '\\|G − G_rolling\\| at 1 s (mm)'), 'g_error_1s', '{:.2f}', 1e3)
    row(r, ('(c)', f'max \\|G − G_rolling\\| over {r[m]["span"]:g} s (mm)'), 'g_error_max',
        '{:.2f}', 1e3)
    for c, tag in ((r, '(c)'), (q, f'(d) rounded square, {q[m]["span"]:g} s')):
        row(c, (tag, f'E(0) = {c[m]["energy0"]:.4f} J: max \\|E − E(0)\\| (mJ)'),
            'energy_dev', '{:.1f}', 1e3)
        row(c, (tag[:3], 'E at the end (J)'), 'energy_end', '{:.4f}')
        row(c, (tag[:3], 'penetration (mm)'), 'depth', '{:.4f}', 1e3)
        row(c, (tag[:3], 'CPU per simulated s'), 'cpu', '{:.3f}', 1 / c[m]['span'])
    row(out['steps'], ('(e) = (c) over 1 s, stepped one step at a time from Python, the state '
                       'read after each step (as the hybrid steps its engine)',
                       'CPU per simulated s'), 'cpu', '{:.3f}')
    total = {e: sum(_per_second(out[k][e]) for k in ('slide', 'flight', 'rolling', 'square'))
             for e in names}
    lines += ['', 'CPU over the runs (a) to (d) against MuJoCo\'s: '
              + ', '.join(f'{e} {total[e] / total[m]:.1f}×' for e in names[1:])
              + ' (the build apart: ' + ', '.join(f'{e} {r[e]["build"]:.2f} s' for e in names)
              + ' for the oloid). The choice and its reasons: README "Beyond rolling".', END]
    return '\n'.join(lines) + '\n'


def main():
    args = _parser().parse_args()
    try:
        import pydrake.multibody.plant  # noqa: F401
    except ImportError:
        print(HOW, file=sys.stderr)
        return 2
    if args.repeats < 1:
        print('engine_choice.py: --repeats must be an integer >= 1', file=sys.stderr)
        return 2
    machine, date, commit = provenance(ROOT)
    out = measure(args.quick, 1 if args.quick else args.repeats)
    print(json.dumps(dict(machine=machine, date=date, commit=commit, cases=out), indent=1))
    if not args.no_write:
        replace_section(args.out, section(out, machine, date, commit), BEGIN, END)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

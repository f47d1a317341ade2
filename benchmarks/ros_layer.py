"""Benchmarks of the node and of the capabilities built on the physics (part of ``make bench``).

- full poses and positions per second against the independent reference (``targets.py``);
- batch recording: the node's messages/s against the ``mcap`` writer's and rclpy's floors,
  measured side by side in one run (``node_rates.py``);
- real time at 100 Hz, 1 kHz and 10 kHz, every topic subscribed and recording on
  (``node_rates.py``);
- the cost of ``/tf``: the same runs without and with a ``/tf`` subscriber (``node_rates.py``);
- real time at 1 kHz by shape: the ellipse beside a superellipse n = 4 and an egg
  (``node_rates.py``, ``SHAPE_SCENARIOS``);
- real time at 1 kHz by scene: slope, dissipation and the two drives beside the flat free
  case (``node_rates.py``, ``SCENE_SCENARIOS``);
- contact forces per second, and the cost of the solid mass model;
- parameter sweeps on Dask (``sweep_rate.py``);
- the live view without ROS, ``twodisk-view``, at 100 Hz and 1 kHz (``view_rate.py``).
- the set-up's extra seconds for building tf2_msgs/TFMessage (``setup_cost.py``).
"""

import contextlib
from dataclasses import asdict
import io
import time

import numpy as np

from node_rates import batch_rate, batch_tf_cost, realtime_rate, scene_rates, shape_rates
import setup_cost
from targets import poses_throughput
import view_rate

from twodisk_ros.physics import RollingDynamics, EllipseBody, simulate
from twodisk_ros.physics.forces.contact import ContactForceModel
from twodisk_ros.physics.mass.models import clear_hull_cache, mass_properties, solid_hull

TARGET_POSES, TARGET_POSITIONS, TARGET_FLOOR_SHARE = 1.5e6, 3e6, 0.6


def _best(function, repeats=3):
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        walls.append(time.perf_counter() - start)
    return min(walls)


def contact_force_rate(states=10**6):
    """States per second of ContactForceModel.dynamic along a motion of the oloid (0.1 m)."""
    body = EllipseBody.oloid(0.1)
    dynamics = RollingDynamics(body, mass_properties('laminae', 0.1, 0.1, 0.05, 1.0))
    build = _best(lambda: ContactForceModel(dynamics), repeats=2)
    model = ContactForceModel(dynamics)
    motion = simulate(dynamics, np.linspace(0.0, 1000.0, states), omega0=6.0)
    wall = _best(lambda: model.dynamic(motion.phase, motion.phase_rate))
    return {'states': states, 'wall': wall, 'rate': states / wall, 'build': build}


def solid_hull_cost():
    """Seconds per first call of the solid mass model (the old unit test's wall-clock bound);
    its quadrature is remembered per Δ/a, so the cache is cleared before each timed call."""
    cases = {'oloid': (1.0, 1.0, 0.5), 'delta/a = 1e-3': (1.0, 1.0, 1e-3),
             'b/a = 0.01': (1.0, 0.01, 0.5)}

    def cold(args):
        clear_hull_cache()
        solid_hull(*args, 1.0, rtol=1e-9)
    return {name: _best(lambda args=args: cold(args)) for name, args in cases.items()}


def measure(builds, quick=False, log=print):
    """Every measurement of this module; ``builds`` are the benchmark bodies of run_all."""
    n = 10**5 if quick else 10**6
    out = {'poses': []}
    for built in builds:
        p = poses_throughput(built, n=n)
        out['poses'].append(p)
        log(f'   poses {built.name}: {p.rate_poses / 1e6:.2f} M/s, positions '
            f'{p.rate_positions / 1e6:.2f} M/s, error {p.position_error:.1e}')
    runs = [batch_rate(duration=20.0 if quick else 300.0) for _ in range(1 if quick else 2)]
    out['batch'] = max(runs, key=lambda r: r.per_second / r.floor_rate)
    log(f'   batch: {out["batch"].per_second:.0f} messages/s, floor '
        f'{out["batch"].floor_rate:.0f}')
    out['realtime'] = [realtime_rate(hz, seconds=3.0 if quick else 8.0)
                       for hz in (100.0, 1000.0, 10000.0)]
    for r in out['realtime']:
        log(f'   realtime {r.rate_hz:g} Hz: node {r.node_achieved_hz:.0f} Hz, lag '
            f'{r.node_lag_ms:.2f} ms, dropped {r.dropped}')
    out['tf_cost'] = {
        'batch': batch_tf_cost(duration=5.0 if quick else 20.0, repeats=2 if quick else 5),
        'realtime': [realtime_rate(1000.0, seconds=3.0 if quick else 8.0, tf=tf, record=False)
                     for tf in (False, True)]}
    t = out['tf_cost']
    log(f'   /tf cost: batch {t["batch"]["cpu_off"]:.1f} -> {t["batch"]["cpu_on"]:.1f} us CPU '
        f'per sample; 1 kHz real time node CPU {t["realtime"][0].node_cpu:.2f} -> '
        f'{t["realtime"][1].node_cpu:.2f}')
    out['shapes'] = shape_rates(1000.0, seconds=3.0 if quick else 8.0)
    for r in out['shapes']:
        log(f'   realtime 1 kHz {r.body}: node {r.node_achieved_hz:.0f} Hz, lag '
            f'{r.node_lag_ms:.2f} ms, dropped {r.dropped}, CPU {r.node_cpu:.2f}')
    out['scenes'] = scene_rates(1000.0, seconds=3.0 if quick else 8.0)
    for r in out['scenes']:
        log(f'   realtime 1 kHz {r.body}: node {r.node_achieved_hz:.0f} Hz, lag '
            f'{r.node_lag_ms:.2f} ms, dropped {r.dropped}, CPU {r.node_cpu:.2f}')
    out['forces'] = contact_force_rate(10**5 if quick else 10**6)
    out['solid'] = solid_hull_cost()
    log('   parameter sweeps on Dask (benchmarks/sweep_rate.py)')
    import sweep_rate
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        sweep_rate.main()
    out['sweep'] = text.getvalue()
    out['view'] = [view_rate.view_rate(hz, 3.0 if quick else 10.0) for hz in (100.0, 1000.0)]
    for r in out['view']:
        log(f'   twodisk-view {r.rate_hz:g} Hz: {r.per_second:.0f} transforms/s, lag p50 '
            f'{r.lag_p50_ms:.2f} ms, server CPU {r.server_cpu:.0%}, skipped {r.skipped}')
    log('   set-up: building tf2_msgs/TFMessage (benchmarks/setup_cost.py)')
    out['setup'] = setup_cost.build_cost(repeats=1 if quick else 2)
    log(f'   tf2_msgs build: {out["setup"]["wall"]:.1f} s')
    return out


def as_dict(out):
    return {'poses': [asdict(p) for p in out['poses']], 'batch': out['batch'].as_dict(),
            'realtime': [r.as_dict() for r in out['realtime']], 'forces': out['forces'],
            'shapes': [r.as_dict() for r in out.get('shapes', ())],
            'scenes': [r.as_dict() for r in out.get('scenes', ())],
            'tf_cost': {'batch': out['tf_cost']['batch'],
                        'realtime': [r.as_dict() for r in out['tf_cost']['realtime']]},
            'solid': out['solid'], 'sweep': out['sweep'], 'setup': out['setup'],
            'view': [r.as_dict() for r in out['view']]}


def _status(ok):
    return 'PASS' if ok else 'MISSED'


def report_lines(out):
    """The report's sections for these measurements (Markdown lines)."""
    lines = []
    w = lines.append
    w('## Full poses and positions (the node\'s source)\n')
    w('`RollingCycle.poses(u)` (G, A, B and the quaternion from the tables) and '
             '`positions(u)` on 10⁶ phases over three cycles, best of 5; errors against the '
             'independent reference (orientation as an angle). Targets: full poses '
             f'≥ {TARGET_POSES / 1e6:g} M/s, positions ≥ {TARGET_POSITIONS / 1e6:g} M/s, '
             '≤ 1e-10 of the size.\n')
    w('| body | full poses (M/s) | positions (M/s) | position error / size | '
             'orientation error (rad) | reference\'s own error | sign flips |')
    w('|---|---|---|---|---|---|---|')
    for p in out['poses']:
        w(f'| {p.body} | {p.rate_poses / 1e6:.2f} | {p.rate_positions / 1e6:.2f} | '
                 f'{p.position_error:.1e} | {p.orientation_error:.1e} | '
                 f'{p.reference_error:.1e} | {p.sign_flips} |')
    ok = all(p.rate_poses >= TARGET_POSES and p.rate_positions >= TARGET_POSITIONS
             and p.position_error <= 1e-10 for p in out['poses'])
    w(f'\n**{_status(ok)}** (the machine is shared: rates vary by up to 2× between '
             'runs).\n')
    b = out['batch']
    share = b.per_second / b.floor_rate
    w('## Batch recording against the file format\n')
    w(f'`roller` in process, `realtime:=false`, `rate:={b.rate_hz:g}`, '
             f'`duration:={b.duration:g}`, every topic recorded (pose, contacts, rolling_state, '
             'wrenches at the rate; paths at 2 Hz with up to 1000 poses; markers at 10 Hz; '
             'diagnostics at 1 Hz); `run_batch` is timed, start-up excluded. In the same run, '
             'on the same messages: `mcap.Writer.add_message` alone (zstd, 256 KiB chunks, '
             'as the node writes) and `rclpy.serialization.serialize_message` of pre-built '
             'PoseStamped (the per-message path the node used before).\n')
    w('| messages | node (messages/s) | add_message floor (messages/s) | node / floor | '
      'serialize_message (messages/s) | an hour at 1 kHz (extrapolated) |')
    w('|---|---|---|---|---|---|')
    w(f'| {b.messages} | {b.per_second:.0f} | {b.floor_rate:.0f} | {share:.2f} | '
      f'{b.serialize_rate:.0f} | {b.hour_estimate:.0f} s (linear from {b.duration:g} s) |')
    w(f'\n**{_status(share >= TARGET_FLOOR_SHARE)}** (target: node ≥ '
      f'{TARGET_FLOOR_SHARE:.0%} of the floor).\n')
    w('## Real time\n')
    w('`roller` as a process with `config/oloid.yaml`, recording on, every topic subscribed '
      'by a listener process (`/tf`, `/clock`, `/tf_static` and `robot_description` '
      'included; raw subscriptions, so that the listener\'s own decoding is not '
      'measured). Node: its achieved rate, its lag (wall clock minus the time of the last '
      'sample it published, mean) and the samples it dropped, from its `/diagnostics`; its '
      'CPU time per wall second (1 = one core, all its threads, from `/proc`). '
      'Listener: inter-arrival times of `/pose` (p50, p99) and the mean arrival time minus '
      'stamp; on this 2-core machine the Python listener shares the cores with the node, so '
      'its numbers include its own backlog.\n')
    w('| rate (Hz) | node achieved (Hz) | node lag (ms) | dropped | diagnostics | node CPU | '
      'listener p50 (ms) | listener p99 (ms) | listener lag (ms) |')
    w('|---|---|---|---|---|---|---|---|---|')
    levels = {0: 'OK', 1: 'WARN', 2: 'ERROR', -1: 'none'}
    for r in out['realtime']:
        w(f'| {r.rate_hz:g} | {r.node_achieved_hz:.0f} | {r.node_lag_ms:.2f} | {r.dropped} | '
          f'{levels.get(r.level, r.level)} | {r.node_cpu:.2f} | {r.p50_ms:.2f} | '
          f'{r.p99_ms:.2f} | {r.lag_ms:.1f} |')
    w('')
    if out.get('shapes'):
        w('## Real time by shape\n')
        w('The same real-time run at 1 kHz (recording on, every topic subscribed) for the '
          'ellipse (`config/oloid.yaml`, closed forms) and for non-elliptic bodies through '
          '`LaminaBody`\'s tables: `config/rounded_square.yaml` (superellipse n = 4) and '
          '`config/egg.yaml` (the parallel egg, table method). The rounded square\'s '
          'diagnostics say ERROR: its contact forces spike without bound where a contact '
          'crosses a flat vertex, so it leaves the rolling model (physics, not speed). '
          'Columns as in the real-time table.\n')
        w('| body | node achieved (Hz) | node lag (ms) | dropped | diagnostics | node CPU | '
          'listener p50 (ms) | listener p99 (ms) | listener lag (ms) |')
        w('|---|---|---|---|---|---|---|---|---|')
        for r in out['shapes']:
            w(f'| {r.body} | {r.node_achieved_hz:.0f} | {r.node_lag_ms:.2f} | {r.dropped} | '
              f'{levels.get(r.level, r.level)} | {r.node_cpu:.2f} | {r.p50_ms:.2f} | '
              f'{r.p99_ms:.2f} | {r.lag_ms:.1f} |')
        w('')
    if out.get('scenes'):
        w('## Real time by scene\n')
        w('The same real-time run at 1 kHz (recording on, every topic subscribed) in every '
          'scene, beside the flat free oloid (`config/oloid.yaml`, the level ground\'s closed forms): '
          '`config/slope.yaml` (downhill, damped: DOP853), the same slope across and without '
          'damping (the closed forms of a conservative slope), damping and rolling resistance '
          'on the flat (DOP853), and `config/driven.yaml` under the speed drive and the torque '
          'drive, each commanded at 10 Hz by the listener (`cmd_speed` 6 rad/s, `cmd_torque` '
          '0.01 N m; every command continues the motion in a new stretch). A body on a slope '
          'or driven may leave the rolling model (diagnostics ERROR) and is published on. '
          'Columns as in the real-time table.\n')
        w('| scene | node achieved (Hz) | node lag (ms) | dropped | diagnostics | node CPU | '
          'listener p50 (ms) | listener p99 (ms) | listener lag (ms) |')
        w('|---|---|---|---|---|---|---|---|---|')
        for r in out['scenes']:
            w(f'| {r.body} | {r.node_achieved_hz:.0f} | {r.node_lag_ms:.2f} | {r.dropped} | '
              f'{levels.get(r.level, r.level)} | {r.node_cpu:.2f} | {r.p50_ms:.2f} | '
              f'{r.p99_ms:.2f} | {r.lag_ms:.1f} |')
        w('')
    t = out['tf_cost']
    b = t['batch']
    w('## The cost of /tf\n')
    w('The node builds and publishes `/tf` only for a subscriber or a recording, so the same '
      'run without and with a `/tf` subscriber (recording off, every other topic subscribed) '
      'shows what it adds. Batch: `run_batch` in process at 1 kHz for '
      f'{b["samples"]} samples, best of alternated runs, per sample, as wall time and as the '
      'process\'s CPU time (less disturbed by the other processes of a shared machine). Real '
      'time: the node as a process at 1 kHz, its CPU time per wall second; this includes '
      'DDS\'s work for a listener that falls behind (reliable topics are resent), so on a '
      'loaded machine it varies by more than /tf adds, and the batch rows are the measure.\n')
    w('| | /tf off | /tf on | added |')
    w('|---|---|---|---|')
    w(f'| batch, wall per sample (µs) | {b["off"]:.1f} | {b["on"]:.1f} | '
      f'{b["on"] - b["off"]:+.1f} |')
    w(f'| batch, CPU per sample (µs) | {b["cpu_off"]:.1f} | {b["cpu_on"]:.1f} | '
      f'{b["cpu_on"] - b["cpu_off"]:+.1f} |')
    off, on = t['realtime']
    w(f'| real time 1 kHz, node CPU (cores) | {off.node_cpu:.3f} | {on.node_cpu:.3f} | '
      f'{on.node_cpu - off.node_cpu:+.3f} |')
    w(f'| real time 1 kHz, node achieved (Hz), dropped | {off.node_achieved_hz:.0f}, '
      f'{off.dropped} | {on.node_achieved_hz:.0f}, {on.dropped} | |')
    w('')
    f = out['forces']
    w('## Contact forces\n')
    w(f'`ContactForceModel.dynamic` along a motion of the oloid: {f["states"]} states in '
      f'{f["wall"]:.3f} s ({f["rate"] / 1e6:.2f} M states/s); table build '
      f'{f["build"] * 1e3:.0f} ms per body.\n')
    w('## Solid mass model\n')
    w('`solid_hull(..., rtol=1e-9)`, best of 3: ' + ', '.join(
        f'{name} {wall * 1e3:.1f} ms' for name, wall in out['solid'].items()) + '.\n')
    w('## Parameter sweeps on Dask\n')
    w('`benchmarks/sweep_rate.py`, as printed (a LocalCluster on 127.0.0.1; the cost per body '
      'split by quantity, bodies per second with 1 and 2 workers, the 100 × 100 map and the '
      'projection to 1000 × 1000 with the model it uses):\n')
    w('```\n' + out['sweep'].strip() + '\n```\n')
    lines.extend(view_rate.report_lines(out['view']))
    lines.extend(setup_cost.report_lines(out['setup']))
    return lines

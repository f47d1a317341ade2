#!/usr/bin/env python3
"""Entry point of ``make bench``: work-precision runs, the three targets, report and plot.

Writes docs/benchmarks.md, docs/figures/work_precision.png and benchmarks/results.json.
``--quick`` shortens every span (a smoke run; its numbers are not the reported ones).
"""

import argparse
from dataclasses import asdict
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
if ROOT not in sys.path:
    sys.path.insert(1, ROOT)


def _parser():
    """The command line (built before the heavy imports, so that ``--help`` answers at once)."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--quick', action='store_true', help='short spans, short hour runs')
    parser.add_argument('--out', default=os.path.join(ROOT, 'docs', 'benchmarks.md'))
    parser.add_argument('--figure',
                        default=os.path.join(ROOT, 'docs', 'figures', 'work_precision.png'))
    parser.add_argument('--json', default=os.path.join(HERE, 'results.json'))
    parser.add_argument('--overwrite', action='store_true',
                        help='replace the report, the figure and the JSON if they exist '
                        '(make bench passes it)')
    return parser


if __name__ == '__main__':
    _parser().parse_args()      # --help (or a wrong option) before the heavy imports

import numpy as np  # noqa: E402
import scipy  # noqa: E402
import matplotlib  # noqa: E402

from scenarios import BODIES, scenarios  # noqa: E402
from work_precision import (METHODS, REFERENCE_CHECK_RTOL, REFERENCE_RTOL,  # noqa: E402
                            TOLERANCES, build, reference_run, run_method)
from targets import hour_run, positions_throughput, speed_ratios  # noqa: E402
from plot import work_precision_figure  # noqa: E402
from report import write_report, TARGET_RATE, TARGET_POS_ERROR, TARGET_RATIO  # noqa: E402
from reference import ReferenceBody  # noqa: E402

from twodisk_ros import EllipseBody  # noqa: E402
from twodisk_ros.outputs import OutputError, check_output  # noqa: E402
from twodisk_ros.physics.motion.simulate import CLOSED_FORM_SOLVERS  # noqa: E402
import ros_layer  # noqa: E402
import sweep_exponent  # noqa: E402
import sweep_scaling  # noqa: E402
import general_shapes  # noqa: E402
import scene_rate  # noqa: E402
import suite_time  # noqa: E402


def _run(cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ''


def machine_info():
    lscpu = _run(['lscpu'])
    fields = {}
    for line in lscpu.splitlines():
        if ':' in line:
            k, v = line.split(':', 1)
            fields[k.strip()] = v.strip()
    try:
        cores = int(fields.get('Core(s) per socket', '0')) * int(fields.get('Socket(s)', '0'))
    except ValueError:
        cores = 0
    return {
        'cpu': fields.get('Model name', platform.processor() or 'unknown'),
        'cores': cores or os.cpu_count(),
        'nproc': _run(['nproc']) or str(os.cpu_count()),
        'python': platform.python_version(),
        'numpy': np.__version__,
        'scipy': scipy.__version__,
        'matplotlib': matplotlib.__version__,
        'load_start': ' '.join(f'{x:.2f}' for x in os.getloadavg()),
    }


def log(msg):
    print(f'[bench {time.strftime("%H:%M:%S")}] {msg}', flush=True)


def closed_form_checks(builds):
    """Reference vs package closed forms; the direct method's m' vs the exact one."""
    text, fd = [], {}
    for b in builds:
        rb, dyn = b.ref_body, b.dynamics
        u = np.linspace(-2 * math.pi, 2 * math.pi, 2001)
        m, v, om = rb.mechanics(u, 0)
        w = np.sqrt(sum(x.c[0] ** 2 for x in om))
        dm = max(float(np.max(np.abs(m.c[0] - dyn.effective_mass(u)))) / float(np.max(m.c[0])),
                 float(np.max(np.abs(v.c[0] - dyn.potential(u)))) / float(np.max(v.c[0])),
                 float(np.max(np.abs(w - dyn.angular_speed_per_phase(u)))) / float(np.max(w)))
        text.append(f'{b.name} {dm:.0e}')
        us = np.linspace(-math.pi, math.pi, 301)
        exact = np.array([rb.mechanics(x, 1)[0].c[1] for x in us])
        fd[b.name] = float(np.max(np.abs(dyn.effective_mass_slope(us) - exact))
                           / np.max(np.abs(exact)))
        b.speed_range = (float(w.min()), float(w.max()))
    return ('m(u), V(u) and |ω_u(u)| agree to ' + ', '.join(text)
            + ' (max relative difference over u ∈ [−2π, 2π]).'), fd


def findings(results, hours, builds, fd_errors, ratios, throughput):
    out = []
    # 1. the quadrature path
    failed = [r for r in results if r.method == 'table' and r.solver in CLOSED_FORM_SOLVERS
              and not (math.isfinite(r.error) and r.error < 1e-6)]
    failed_h = [h for h in hours if not (h.finite and h.position_error < 1e-6)]
    if failed or failed_h:
        seen, parts = set(), []
        for r in failed:
            if (r.body, r.kind) in seen:
                continue
            seen.add((r.body, r.kind))
            parts.append(f'{r.body} / {r.kind}: error {r.error:.1e} of the size, '
                         f'{r.bad_samples} of {r.samples} samples wrong'
                         + ('' if r.finite else ', some NaN'))
        for h in failed_h:
            parts.append(f'{h.body} / {h.kind}, 1 h: pose error {h.position_error:.1e}')
        speeds = {b.name: b.speed_range for b in builds}
        sr = '; '.join(f'{n} {lo:.3g}…{hi:.3g} (×{hi / lo:.3g})' for n, (lo, hi) in speeds.items())
        out.append(
            '**Bug in the table method\'s quadrature path** (`twodisk_ros/dynamics.py`, '
            '`_Quadrature.__call__`): t(u) is inverted by plain Newton from the linear guess '
            'u0 + s·t/mean, with no bracketing or damping, and after 50 iterations the result '
            'is returned without a convergence check. When 1/|u̇| varies strongly over a cycle '
            'the iteration overshoots into other cycles and diverges, silently (numpy overflow '
            'RuntimeWarnings only): ' + '; '.join(parts) + '. |ω_u| over a cycle: ' + sr + '. '
            'Because G(u) = ∫du/|u̇| is monotone, a safeguarded inversion fixes it: locate each '
            'sample\'s cycle k = floor(t / cycle_time) and its node interval by searchsorted on '
            'the tabulated G, Newton inside that bracket with bisection fallback, and raise if '
            'not converged. (Not fixed here: outside this benchmark\'s files.)')
    # 2. the direct method's finite-difference m'
    fd_txt = ', '.join(f'{n} {e:.1e}' for n, e in fd_errors.items())
    ext = [r for r in results if r.body == 'extreme' and r.method == 'direct'
           and r.kind != 'kinematic']
    tail = ''
    if ext:
        bests = []
        for kind in dict.fromkeys(r.kind for r in ext):
            best = min((r for r in ext if r.kind == kind), key=lambda r: r.error)
            bests.append(f'{best.error:.1e} of the size when {kind} (best of the tolerance '
                         f'sweep, at tol {best.tolerance:.0e})')
        tail = (' On the extreme body this floors the direct method: ' + '; '.join(bests)
                + '.')
    out.append('The direct method\'s dm/du is a 5-point difference with step 1e-3 rad times '
               'the body\'s feature width (`RollingDynamics.effective_mass_slope`, as '
               'documented); against the exact m\' '
               f'of the reference its max relative error is {fd_txt}.' + tail)
    # 3. the cost of one direct RHS call
    per_call = [r.wall_simulate / r.nfev for r in results
                if r.method == 'direct' and r.nfev > 0 and r.kind != 'kinematic']
    if per_call:
        out.append(f'One direct right-hand-side call (dynamic mode: m, dm/du by 4 more '
                   f'evaluations of m, dV/du) costs {1e3 * float(np.median(per_call)):.2f} ms '
                   f'(median; range {1e3 * min(per_call):.2f}–{1e3 * max(per_call):.2f} ms) on '
                   'this machine, more than the ~0.5 ms the issue assumed; spans are short '
                   'accordingly.')
    # 4. body.size for b > a
    tb = EllipseBody(1.0, 2.0, 0.5)
    true_size = ReferenceBody(1.0, 2.0, 0.5).size
    if abs(tb.size - true_size) > 1e-9 * true_size:
        out.append(f'Minor: `EllipseBody.size` is documented as "the largest distance of a '
                   f'disk point from G", but for b > a it returns hypot(b, Δ), which is smaller '
                   f'when aΔ < b² − a²: EllipseBody(1, 2, 0.5).size = {tb.size:.6f} m, the '
                   f'largest distance is {true_size:.6f} m (√(b² + Δ² + a²Δ²/(b² − a²))). '
                   'None of the benchmark bodies has b > a, so the numbers here are unaffected.')
    # 5. energy_drift in kinematic mode
    kin = [r.energy_drift_package for r in results if r.kind == 'kinematic'
           and math.isfinite(r.energy_drift_package)]
    if kin:
        out.append('Note: `RollingMotion.energy_drift` is max |E − E₀| even in kinematic mode, '
                   f'where E is not conserved (it reads {min(kin):.2f}–{max(kin):.2f} here); '
                   'this benchmark reports the |ω| drift for that mode instead.')
    return out


def main(argv=None):
    parser = _parser()
    args = parser.parse_args(argv)
    try:
        for path, suffixes in ((args.out, ('.md',)), (args.figure, ('.png',)),
                               (args.json, ('.json',))):
            check_output(path, overwrite=args.overwrite, suffixes=suffixes)
    except OutputError as error:
        parser.exit(2, f'{parser.prog}: {error}\n')
    start = time.perf_counter()
    machine = machine_info()
    date = _run(['date', '-u']) or datetime.datetime.now(datetime.timezone.utc).isoformat()
    log(f'{machine["cpu"]}, {machine["nproc"]} CPUs, load {machine["load_start"]}')

    builds = [build(name) for name in BODIES]
    by_name = {b.name: b for b in builds}
    check_text, fd_errors = closed_form_checks(builds)
    log('reference vs package closed forms: ' + check_text)

    scale = 0.25 if args.quick else 1.0
    scs = scenarios(scale)
    refs, results = [], []
    for sc in scs:
        built = by_name[sc.body]
        rr = reference_run(built, sc)
        refs.append(rr)
        log(f'{sc.key}: span {sc.span:g} s, reference {rr.wall:.1f} s, nfev {rr.nfev}, '
            f'est. error {rr.estimated_error:.1e}')
        for method in METHODS:
            for tol in TOLERANCES:
                r = run_method(built, rr, method, tol)
                results.append(r)
                log(f'   {method:6s} {tol:.0e}: nfev {r.nfev:6d}, wall/s '
                    f'{r.wall_per_second * 1e3:9.2f} ms, error {r.error:.2e}, drift '
                    f'{r.energy_drift:.1e}')

    log('target 1: positions throughput')
    n = 10**5 if args.quick else 10**6
    throughput = []
    for b in builds:
        tp = positions_throughput(b, n=n)
        throughput.append(tp)
        log(f'   {b.name}: {tp.rate / 1e6:.2f} M/s, error {tp.error:.1e}')

    log('target 2: one hour at 1 kHz, oloid')
    duration = 60.0 if args.quick else 3600.0
    hours = []
    for kind in ('rolling', 'kinematic'):
        sc = next(s for s in scs if s.body == 'oloid' and s.kind == kind)
        h = hour_run(by_name['oloid'], sc, duration=duration)
        hours.append(h)
        log(f'   {kind}: {h.wall:.2f} s (simulate {h.wall_simulate:.2f} + positions '
            f'{h.wall_positions:.2f}), drift {h.drift:.1e}, phase error {h.phase_error:.1e}, '
            f'pose error {h.position_error:.1e}')

    ratios = speed_ratios(results)

    log('the node and the capabilities on the physics: poses, recording, real time, forces')
    ros = ros_layer.measure(builds, quick=args.quick, log=log)
    log('the sweep on 1, 2, 4 workers and its extrapolation to a cluster')
    scaling = sweep_scaling.measure(quick=args.quick, log=log)
    log('bodies of other laminae: the general path beside the closed forms')
    shapes = general_shapes.measure(quick=args.quick, log=log)
    log('scenes: slopes, drives and losses beside the flat free motion')
    scenes = scene_rate.measure(quick=args.quick, log=log)
    log('the sweep along the exponent axis: n = 2 batched, n = 4 general, per body')
    exponent = sweep_exponent.measure(quick=args.quick, log=log)
    machine['load_end'] = ' '.join(f'{x:.2f}' for x in os.getloadavg())
    log('the test suite on a fresh clone, as CI runs it (after every other measurement)')
    suite = suite_time.measure(quick=args.quick, log=log)

    # why a target was missed
    t1_why = []
    for tp in throughput:
        if tp.rate < TARGET_RATE:
            t1_why.append(f'{tp.body} {1e6 / tp.rate:.2f} µs per sample')
        if tp.error > TARGET_POS_ERROR:
            t1_why.append(f'{tp.body} error {tp.error:.1e}')
    chunk_gain = ', '.join(f'{tp.body} {tp.rate_chunked / 1e6:.2f} M/s' for tp in throughput)
    target1_why = ('RollingCycle.positions costs ' + ', '.join(t1_why) + ': one quintic '
                   'Hermite evaluation of the 8-column table (≈ 50 numpy passes over N × 8 '
                   'doubles, ~64 MB per temporary at N = 1e6) plus the complex pose '
                   'arithmetic, single-threaded numpy. At 1e6 samples per call it is memory '
                   'bound: the same phases in calls of 1e5 samples run at ' + chunk_gain +
                   ', so evaluating in cache-sized blocks inside positions() would likely '
                   'meet the target. The machine is also shared (load average above).')
    h_parts = [f'{h.kind}: simulate {h.wall_simulate:.1f} s + positions {h.wall_positions:.1f} s'
               for h in hours]
    target2_why = ('; '.join(h_parts) + '. Simulate is the vectorised Newton inversion of '
                   't(u) (several passes over 3.6e6 samples, each evaluating the Hermite table '
                   'twice) plus the energy recomputation; positions is the cost of target 1 '
                   'times 3.6. Both are single-threaded numpy over arrays far larger than the '
                   'cache; the same hour in chunks of 1e5 samples takes '
                   + ', '.join(f'{h.wall_chunked:.1f} s ({h.kind})' for h in hours)
                   + '. The machine is shared (load average above).')
    miss3 = [r for r in ratios if not (r.relation in ('=', '>=') and r.ratio >= TARGET_RATIO)]
    groups = {}
    for r in miss3:
        groups.setdefault((r.body, r.kind, r.table_solver), []).append(r)
    parts = []
    for (body, kind, solver), rs in groups.items():
        if any(math.isnan(r.ratio) for r in rs):
            parts.append(f'{body} / {kind}: the table run failed (quadrature bug, Findings)')
        elif solver in CLOSED_FORM_SOLVERS:
            parts.append(f'{body} / {kind}: {rs[0].ratio:.0f}× is a lower bound (direct never '
                         'reaches the table\'s error); ' + rs[0].note.split('; ')[-1])
        else:
            lo, hi = min(r.ratio for r in rs), max(r.ratio for r in rs)
            parts.append(f'{body} / {kind}: {lo:.0f}–{hi:.0f}× ({len(rs)} tolerances)')
    ode = [r.ratio for r in ratios if r.table_solver not in CLOSED_FORM_SOLVERS
           and r.ratio == r.ratio]
    ode_range = f'{min(ode):.0f}–{max(ode):.0f}×' if ode else 'n/a'
    target3_why = '; '.join(parts) + '.'
    if any(solver == 'libration' for (_, _, solver) in groups):
        target3_why += (' When oscillating, the table method builds the tables of its well '
                        '(u(φ), t(φ): they depend on the energy) in every simulate call, and '
                        'that build dominates the short spans the slow direct method allows '
                        'here; over long runs it is amortised.')
    if ode:
        target3_why += (' Where the table method steps DOP853 on its tabulated right-hand side '
                        '(next to the separatrix) it has the same steps as direct, so the '
                        f'speed-up is the cost ratio of one RHS call ({ode_range} here).')
    target3_why += (' The kinematic direct RHS (|ω_u| only) is cheap, so there the margin is '
                    'thinner than in dynamic mode.')

    os.makedirs(os.path.dirname(args.figure), exist_ok=True)
    ref_errors = {(rr.scenario.body, rr.scenario.kind): rr.estimated_error for rr in refs}
    work_precision_figure(results, ref_errors, args.figure)
    elapsed = time.perf_counter() - start
    ctx = dict(machine=machine, date=date, quick=args.quick, scenarios=scs, builds=builds,
               references=refs, results=results, throughput=throughput, hours=hours,
               ratios=ratios, tolerances=TOLERANCES, reference_rtol=REFERENCE_RTOL,
               reference_check_rtol=REFERENCE_CHECK_RTOL, closed_form_check=check_text,
               findings=findings(results, hours, builds, fd_errors, ratios, throughput),
               target1_why=target1_why, target2_why=target2_why, target3_why=target3_why,
               ros_layer=ros, sweep_scaling=scaling, general_shapes=shapes, scene_rate=scenes,
               sweep_exponent=exponent, suite_time=suite,
               commit=_run(['git', '-C', ROOT, 'rev-parse', 'HEAD']) or 'unknown',
               elapsed=elapsed)
    write_report(args.out, ctx)
    data = dict(date=date, machine=machine, elapsed=elapsed, quick=args.quick,
                scenarios=[asdict(s) for s in scs],
                builds=[dict(body=b.name, resolution=b.resolution, cycle_build=b.cycle_build,
                             dynamics_build=b.dynamics_build) for b in builds],
                references=[dict(scenario=rr.scenario.key, nfev=rr.nfev, wall=rr.wall,
                                 estimated_error=rr.estimated_error,
                                 phase_difference=rr.phase_difference, cycles=rr.cycles)
                            for rr in refs],
                results=[r.as_dict() for r in results],
                throughput=[t.as_dict() for t in throughput],
                hours=[h.as_dict() for h in hours],
                ratios=[r.as_dict() for r in ratios],
                ros_layer=ros_layer.as_dict(ros),
                sweep_scaling=scaling,
                general_shapes=shapes,
                scene_rate=scenes,
                sweep_exponent=exponent,
                suite_time=suite,
                direct_fd_slope_error=fd_errors)
    with open(args.json, 'w') as fh:
        json.dump(data, fh, indent=1, default=lambda x: None if x != x else str(x))
    log(f'wrote {args.out}, {args.figure}, {args.json} in {elapsed:.0f} s')
    return 0


if __name__ == '__main__':
    with warnings.catch_warnings():
        sys.exit(main())

"""The redesign's guard rails, measured side by side: this checkout against an earlier commit.

Issue 29 (one pipeline) must not make anything a user sees slower. Both trees are measured in
one run, in alternation (old, new, old, new, ...), each measurement in a fresh process that
imports only that tree's package and its own benchmark modules (the same measuring functions
in both, by name): full poses per second (the oloid, ``targets.poses_throughput``, and the
same call in process CPU time), one hour
at 1 kHz (the oloid rolling over, ``targets.hour_run``), the 100 × 100 ellipse map end to end
(``twodisk-sweep`` on two local workers, ``sweep_rate.end_to_end``) and the node in real time
at 1 kHz with every topic subscribed and recording on (``node_rates.realtime_rate``). Each
number is the best of the rounds (the machine is shared); the ratio new/old is of those.

``python benchmarks/before_after.py --ref 5d7b327 [--rounds 2] [--out FILE --overwrite]``
prints the table (Markdown) and, with ``--out``, writes it to FILE.
"""

import argparse
import datetime
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

#: what each measurement runs inside a tree (cwd = the tree; prints one JSON line)
PROBES = {
    'poses': ('full poses, oloid (M/s)', 'higher', """
import targets, work_precision
r = targets.poses_throughput(work_precision.build('oloid'))
print(json.dumps(r.rate_poses / 1e6))"""),
    # the same call timed in process CPU time (best of 7): on a shared machine the wall
    # time mostly measures the other jobs' share of the cores
    'poses_cpu': ('full poses, oloid, process CPU time (M/s)', 'higher', """
import time, numpy as np, work_precision
cycle = work_precision.build('oloid').dynamics.cycle
u = np.linspace(-2 * np.pi, 4 * np.pi, 10**6)
cycle.poses(u[:1000])
best = float('inf')
for _ in range(7):
    start = time.process_time()
    cycle.poses(u)
    best = min(best, time.process_time() - start)
print(json.dumps(u.size / best / 1e6))"""),
    'hour': ('one hour at 1 kHz, oloid rolling over (s)', 'lower', """
import targets, work_precision, scenarios
sc = next(s for s in scenarios.scenarios() if s.body == 'oloid' and s.kind == 'rolling')
h = targets.hour_run(work_precision.build('oloid'), sc)
print(json.dumps(h.wall_simulate + h.wall_positions))"""),
    'sweep': ('100 × 100 ellipse map, twodisk-sweep on 2 workers (s)', 'lower', """
import sweep_rate
print(json.dumps(sweep_rate.end_to_end()[0]))"""),
    'realtime': ('node at 1 kHz, every topic subscribed, recording: achieved Hz, dropped, '
                 'node CPU (cores)', 'higher', """
import node_rates
r = node_rates.realtime_rate(1000.0)
print(json.dumps([r.node_achieved_hz, r.dropped, getattr(r, 'node_cpu', float('nan'))]))"""),
}


def _parser():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--ref', required=True, help='the earlier commit (a git revision)')
    parser.add_argument('--rounds', type=int, default=2, help='alternations (default 2)')
    parser.add_argument('--only', nargs='*', choices=sorted(PROBES), help='a subset')
    parser.add_argument('--out', help='also write the Markdown table to this file')
    parser.add_argument('--overwrite', action='store_true', help='replace --out if it exists')
    return parser


def _export(ref, folder):
    """``git archive`` of ``ref`` unpacked into ``folder``; returns its full hash."""
    full = subprocess.run(['git', '-C', ROOT, 'rev-parse', ref], check=True,
                          capture_output=True, text=True).stdout.strip()
    archive = subprocess.run(['git', '-C', ROOT, 'archive', full], check=True,
                             capture_output=True).stdout
    subprocess.run(['tar', '-x', '-C', folder], input=archive, check=True)
    return full


def _measure(tree, code):
    env = dict(os.environ, PYTHONPATH=tree, MPLBACKEND='Agg',
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    env.setdefault('ROS_DOMAIN_ID', '71')
    script = 'import json, sys\nsys.path[:0] = ["benchmarks", "."]\n' + code
    done = subprocess.run([sys.executable, '-c', script], cwd=tree, env=env,
                          capture_output=True, text=True, timeout=3600)
    if done.returncode != 0:
        return None, done.stderr.strip().splitlines()[-1:] or ['failed']
    return json.loads(done.stdout.strip().splitlines()[-1]), None


def main(argv=None):
    args = _parser().parse_args(argv)
    if args.out and os.path.exists(args.out) and not args.overwrite:
        sys.exit(f'before_after: {args.out} exists; pass --overwrite to replace it')
    new_hash = subprocess.run(['git', '-C', ROOT, 'rev-parse', 'HEAD'], check=True,
                              capture_output=True, text=True).stdout.strip()
    names = args.only or list(PROBES)
    results = {name: {'old': [], 'new': []} for name in names}
    with tempfile.TemporaryDirectory() as folder:
        old_hash = _export(args.ref, folder)
        for round_ in range(args.rounds):
            for name in names:
                for side, tree in (('old', folder), ('new', ROOT)):
                    value, error = _measure(tree, PROBES[name][2])
                    print(f'round {round_ + 1} {name} {side}: {value if error is None else error}',
                          file=sys.stderr, flush=True)
                    if error is None:
                        results[name][side].append(value)
    lines = [f'Measured {datetime.date.today().isoformat()}, old {old_hash[:7]}, new '
             f'{new_hash[:7]}, {args.rounds} alternated rounds, best of them '
             '(`benchmarks/before_after.py`).', '',
             '| measure | old | new | new / old |', '|---|---|---|---|']
    for name in names:
        title, better, _ = PROBES[name]
        old, new = results[name]['old'], results[name]['new']
        if not old or not new:
            lines.append(f'| {title} | {old or "failed"} | {new or "failed"} | |')
            continue
        if name == 'realtime':
            best_old = min(old, key=lambda r: (r[1], r[2]))      # fewest drops, least CPU
            best_new = min(new, key=lambda r: (r[1], r[2]))
            lines.append(f'| {title} | {best_old[0]:.0f} Hz, {best_old[1]}, {best_old[2]:.2f} | '
                         f'{best_new[0]:.0f} Hz, {best_new[1]}, {best_new[2]:.2f} | CPU '
                         f'{best_new[2] / best_old[2]:.2f} |')
            continue
        pick = max if better == 'higher' else min
        b_old, b_new = pick(old), pick(new)
        lines.append(f'| {title} | {b_old:.3g} | {b_new:.3g} | {b_new / b_old:.2f} |')
    table = '\n'.join(lines) + '\n'
    print(table)
    if args.out:
        with open(args.out, 'w', encoding='utf-8') as handle:
            handle.write(table)


if __name__ == '__main__':
    main()

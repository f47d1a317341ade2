"""The sweep's cost per body along the exponent axis: n = 2 (batched) beside n = 4 (general).

``twodisk-sweep --exponent`` computes n = 2 (the ellipse) with the batched closed forms
(:mod:`twodisk_ros.sweep.batch`) and any other exponent body by body through the RollingBody
protocol (:mod:`twodisk_ros.sweep.general`: LaminaBody, its cycle, dynamics, equilibria and
contact-force tables). Both are timed here in this process (one core, no Dask: a task's own
work; the Dask overheads are sweep_rate.py's and sweep_scaling.py's), on the same bodies of
the representative map (b/a in [0.2, 3], Δ/a in [0.05, 0.95]), in tasks of the default chunk
sizes (:data:`~twodisk_ros.sweep.request.DEFAULT_CHUNK_SIZE` bodies for n = 2,
:data:`~twodisk_ros.sweep.request.GENERAL_CHUNK_SIZE` for n ≠ 2), with the general path's cost
split by stage; beside them the per-body path on the ellipse's closed forms (EllipseBody, the
same stages as the general path without the lamina's contact solve). A body that fails is
reported with its one line (e.g. while LaminaBody is not implemented); the rate counts only
the bodies computed.

Run: ``python benchmarks/sweep_exponent.py [--quick]`` (PYTHONPATH = the repository);
``make bench`` runs it (run_all.py) and writes its table into docs/benchmarks.md.
"""

import time


def _arguments():
    """The command line's options (``--help`` answers here, before the heavy imports)."""
    import argparse
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--quick', action='store_true', help='fewer bodies (a smoke run)')
    return parser.parse_args()


if __name__ == '__main__':
    _arguments()

import numpy as np  # noqa: E402

from twodisk_ros.physics.bodies.ellipse import EllipseBody  # noqa: E402
from twodisk_ros.physics.mass.models import mass_properties  # noqa: E402
from twodisk_ros.sweep.chunks import chunk_bodies, quantities  # noqa: E402
from twodisk_ros.sweep.general import Laminae  # noqa: E402
from twodisk_ros.sweep.quantities import STAGES  # noqa: E402
from twodisk_ros.sweep.request import (CORE_SECONDS_PER_BODY, DEFAULT_CHUNK_SIZE,  # noqa: E402
                                       GENERAL_CHUNK_SIZE, GENERAL_CORE_SECONDS_PER_BODY)

B_RANGE, D_RANGE = (0.2, 3.0), (0.05, 0.95)
ELLIPSE_GRID = (16, 8)      # 128 bodies: one default task of the batched path
GENERAL_GRID = (4, 2)       # 8 bodies: one default task of the general path
GENERAL_EXPONENT = 4.0


def _grid(shape):
    b, d = np.meshgrid(np.linspace(*B_RANGE, shape[0]), np.linspace(*D_RANGE, shape[1]),
                       indexing='ij')
    return b.ravel(), d.ravel()


def _ellipse_body(b, d, n):
    """The general path's body factory on the ellipse's closed forms (whatever n)."""
    return EllipseBody(1.0, b, d)


def _ellipse_mass(model, body):
    return mass_properties(model, 1.0, body.b, body.delta, 1.0)


def _timed(b, d, exponent, chunk, factories=None):
    """(wall s, CPU s, bodies computed, {stage: wall s}, first failure or '')."""
    timings = {}
    wall, cpu = time.perf_counter(), time.process_time()
    failures = []
    for start in range(0, b.size, chunk):
        part = slice(start, start + chunk)
        bodies = (Laminae(b[part], d[part], exponent, *factories) if factories
                  else chunk_bodies(b[part], d[part], exponent))
        result = quantities(bodies, timings=timings)
        failures.extend(result['failure'])
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    failed = [f for f in failures if f]
    return wall, cpu, len(failures) - len(failed), timings, (failed[0] if failed else '')


def measure(quick=False, log=print):
    """{'ellipse': {...}, 'general': {...}} per-body costs (s) and rates (bodies/s)."""
    found = {}
    quantities(chunk_bodies([1.0], [0.5]))                        # first calls apart
    ellipse = (_ellipse_body, _ellipse_mass)
    for key, exponent, shape, chunk, factories in (
            ('ellipse', 2.0, (8, 4) if quick else ELLIPSE_GRID, DEFAULT_CHUNK_SIZE, None),
            ('scalar', 2.0, (2, 1) if quick else GENERAL_GRID, GENERAL_CHUNK_SIZE, ellipse),
            ('general', GENERAL_EXPONENT, (2, 1) if quick else GENERAL_GRID,
             GENERAL_CHUNK_SIZE, None)):
        b, d = _grid(shape)
        wall, cpu, done, timings, failure = _timed(b, d, exponent, chunk, factories)
        row = dict(exponent=exponent, bodies=int(b.size), computed=done, chunk=chunk,
                   wall=wall, cpu=cpu, failure=failure,
                   per_body=wall / done if done else float('nan'),
                   rate=done / wall if done and wall > 0 else float('nan'),
                   stages={k: v / b.size for k, v in timings.items()})
        found[key] = row
        log(f'   n = {exponent:g} ({key}): {done}/{b.size} bodies in {wall:.2f} s'
            + (f' ({row["rate"]:.2f} bodies/s)' if done else f' (none computed: {failure})'))
    return found


def report_lines(m):
    """Markdown lines of the table for docs/benchmarks.md."""
    out = ['## The sweep along the exponent axis: n = 2 (batched) and n = 4 (general)\n',
           'One core, no Dask (a task\'s own work), the same representative map (b/a in '
           f'{list(B_RANGE)}, Δ/a in {list(D_RANGE)}), default tasks; '
           'benchmarks/sweep_exponent.py.\n',
           '| exponent | path | bodies (computed) | task size | wall per body | bodies/s | '
           'request.py\'s estimate per body |',
           '|---|---|---|---|---|---|---|']
    estimates = {'ellipse': CORE_SECONDS_PER_BODY, 'scalar': CORE_SECONDS_PER_BODY,
                 'general': GENERAL_CORE_SECONDS_PER_BODY}
    for key, label in (('ellipse', 'batched closed forms'),
                       ('scalar', 'per body, EllipseBody (general path, closed forms)'),
                       ('general', 'per body, LaminaBody')):
        row = m[key]
        per_body = (f'{1e3 * row["per_body"]:.1f} ms' if row['computed'] else 'n/a')
        rate = f'{row["rate"]:.2f}' if row['computed'] else 'n/a'
        out.append(f'| {row["exponent"]:g} | {label} | {row["bodies"]} ({row["computed"]}) | '
                   f'{row["chunk"]} | {per_body} | {rate} | '
                   f'{1e3 * estimates[key]:.0f} ms |')
    general, ellipse = m['general'], m['ellipse']
    out.append('')
    if general['computed'] and ellipse['computed']:
        out.append(f'The general path costs {general["per_body"] / ellipse["per_body"]:.0f}× '
                   'the batched one per body. Its stages (ms per body): '
                   + ', '.join(f'{s} {1e3 * general["stages"].get(s, 0.0):.1f}'
                               for s in STAGES if s in general['stages']) + '.\n')
    else:
        out.append(f'The general path computed no body: {general["failure"]}\n')
    return out


def main():
    args = _arguments()
    print('\n'.join(report_lines(measure(args.quick))))


if __name__ == '__main__':
    main()

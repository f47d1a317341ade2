#!/usr/bin/env python3
"""Bodies of any laminae: the general path's cost and accuracy beside the ellipse's closed forms.

Part of ``make bench`` (docs/benchmarks.md, section "Laminae other than ellipses"). Measured
side by side in one run, for the shapes of ``SHAPES``:

* **build**: ``LaminaBody(lamina, delta)`` and ``RollingCycle(body)`` (the cycle tables) in
  seconds, best of ``REPEATS``; target ≤ 1 s for a non-elliptic shape;
* **poses**: ``RollingCycle.positions`` on 1e6 phases over three cycles, samples/s, best of
  ``REPEATS``; target ≥ 1e6/s;
* **error** of those poses (fraction of the body's size): for the ellipse through the general
  path, G against EllipseBody's closed-form cycle at the same pose (the closed body's phase of
  the general body's θ and branch; phases within 0.05 rad of a turning point are left out,
  where θ ↦ u amplifies rounding as √), an independent construction of the same body; for the
  other shapes, A's ground trace against DOP853 integration of the trace equations (rtol 1e-13)
  on the same body: the error of the cycle's spectral integration and tables, not of the
  body's own tables (those are checked by tests/test_lamina_body.py); target ≤ 1e-10;
* **equilibria**: ``RollingDynamics(body, laminae 1 kg).equilibria_with_periods()`` (the
  certified search, stability, order and periods; the node's start and the sweep per body) in
  seconds, best of ``REPEATS`` on fresh dynamics objects (it is cached); target ≤ 1 s;
* the same build and pose rate for EllipseBody itself (the closed forms), as the ratio.

Run: ``python benchmarks/general_shapes.py [--quick]``.
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

from twodisk_ros.physics.bodies.ellipse import EllipseBody  # noqa: E402
from twodisk_ros.physics.bodies.cycle import RollingCycle, integrate_contact_trace  # noqa: E402
from twodisk_ros.physics.motion.dynamics import RollingDynamics  # noqa: E402
from twodisk_ros.physics.laminae.shapes import Ellipse, Superellipse  # noqa: E402
from twodisk_ros.physics.laminae.support import Egg  # noqa: E402
from twodisk_ros.physics.bodies.lamina_body import LaminaBody  # noqa: E402
from twodisk_ros.physics.mass.models import mass_properties_of  # noqa: E402

REPEATS = 3
SAMPLES = 1_000_000
TARGET_BUILD = 1.0
TARGET_RATE = 1e6
TARGET_ERROR = 1e-10
TARGET_EQUILIBRIA = 1.0
#: name → (description, lamina factory, Δ (m)); the ellipse first (the side-by-side reference)
SHAPES = {
    'ellipse': ('ellipse a = 1, b = 0.8, Δ = 0.45 (general path)',
                lambda: Ellipse(1.0, 0.8), 0.45),
    'superellipse4': ('superellipse n = 4, a = b = 1, Δ = 0.5', lambda: Superellipse(1.0, 1.0, 4.0),
                      0.5),
    'superellipse3': ('superellipse n = 3, a = b = 1, Δ = 0.5 (odd exponent)',
                      lambda: Superellipse(1.0, 1.0, 3.0), 0.5),
    'superellipse10': ('superellipse n = 10, a = b = 1, Δ = 0.5',
                       lambda: Superellipse(1.0, 1.0, 10.0), 0.5),
    'egg': ('egg a = 1, b = 0.8, ε = 0.05, Δ = 0.45', lambda: Egg(1.0, 0.8, 0.05), 0.45),
}


def _best(function, repeats):
    walls, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        walls.append(time.perf_counter() - start)
    return min(walls), result


def _matched_error(cycle, closed_cycle, u, size):
    """max |G_general(u) − G_closed(u_c)| / size, u_c the closed body's phase of the same pose."""
    body, closed = cycle.body, closed_cycle.body
    u = u[np.abs(np.remainder(u, math.pi) - math.pi / 2) > 0.05]
    geometry = body.phase_geometry(u)
    u_closed = closed.phase_from_theta(geometry.theta, geometry.branch)
    u_closed = u + np.remainder(u_closed - u + math.pi, 2 * math.pi) - math.pi
    return float(np.max(np.abs(cycle.positions(u)[0] - closed_cycle.positions(u_closed)[0]))) / size


def _trace_error(cycle, u, size):
    """max |A(u) − A_DOP853(u)| / size over u ∈ [0, max u] (A's trace from the origin)."""
    u = np.sort(u[u >= 0])
    reference = integrate_contact_trace(cycle.body, float(u[-1]), u_eval=u)
    trace = cycle.positions(u)[1][:, :2]
    return float(np.max(np.abs(trace - reference.y[1:].T))) / size


def _equilibria_time(body, mass, cycle):
    """Seconds of one ``equilibria_with_periods()`` on a fresh RollingDynamics (it caches)."""
    dynamics = RollingDynamics(body, mass, cycle=cycle)
    start = time.perf_counter()
    dynamics.equilibria_with_periods()
    return time.perf_counter() - start


def measure(quick=False, log=print):
    """The measurements (a dict) of every shape of :data:`SHAPES`."""
    repeats = 1 if quick else REPEATS
    samples = SAMPLES // 10 if quick else SAMPLES
    u = np.linspace(-2 * math.pi, 4 * math.pi, samples)
    rows = []
    for name, (text, lamina_of, delta) in SHAPES.items():
        lamina = lamina_of()
        build, (body, cycle) = _best(lambda: (lambda b: (b, RollingCycle(b)))(
            LaminaBody(lamina, delta)), repeats)
        rate_wall, _ = _best(lambda: cycle.positions(u), repeats)
        mass = mass_properties_of('laminae', body, 1.0)
        equilibria_wall = min(_equilibria_time(body, mass, cycle) for _ in range(repeats))
        row = dict(name=name, text=text, build=build, resolution=cycle.resolution,
                   rate=samples / rate_wall, size=body.size, equilibria=equilibria_wall)
        if isinstance(lamina, Ellipse):
            closed = EllipseBody(lamina.a, lamina.b, delta)
            closed_build, closed_cycle = _best(lambda: RollingCycle(closed), repeats)
            closed_wall, _ = _best(lambda: closed_cycle.positions(u), repeats)
            row.update(error=_matched_error(cycle, closed_cycle, u[::97], body.size),
                       error_kind='vs closed forms', closed_build=closed_build,
                       closed_rate=samples / closed_wall)
        else:
            row.update(error=_trace_error(cycle, u[::997], body.size),
                       error_kind='trace of A vs DOP853 on the same body')
        log(f'   {name}: build {row["build"]:.3f} s, {row["rate"] / 1e6:.2f} M poses/s, '
            f'error {row["error"]:.1e} ({row["error_kind"]}), equilibria '
            f'{row["equilibria"]:.3f} s')
        rows.append(row)
    return dict(rows=rows, samples=samples, repeats=repeats)


def report_lines(m):
    """The report's section (Markdown lines)."""
    lines = []
    w = lines.append
    w('## Laminae other than ellipses\n')
    w(f'`benchmarks/general_shapes.py`: `LaminaBody(lamina, Δ)` + `RollingCycle(body)` (build, '
      f'best of {m["repeats"]}), `RollingCycle.positions` on {m["samples"]:.0e} phases over '
      f'three cycles (samples/s, best of {m["repeats"]}) and the error of those poses as a '
      f'fraction of the size; `RollingDynamics(body, laminae 1 kg).equilibria_with_periods()` '
      f'(certified equilibria, stability, periods; best of {m["repeats"]}, fresh objects). '
      f'Targets: build ≤ {TARGET_BUILD:g} s, ≥ {TARGET_RATE:.0e} poses/s, error ≤ '
      f'{TARGET_ERROR:.0e}, equilibria ≤ {TARGET_EQUILIBRIA:g} s.\n')
    w('| shape | build (s) | nodes | poses/s | pose error | error measured | equilibria (s) | '
      'closed forms: build (s), poses/s |')
    w('|---|---|---|---|---|---|---|---|')
    for r in m['rows']:
        closed = (f'{r["closed_build"]:.3f}, {r["closed_rate"] / 1e6:.2f} M/s (general path '
                  f'{r["build"] / r["closed_build"]:.1f}× the build, '
                  f'{r["closed_rate"] / r["rate"]:.2f}× the pose time)'
                  if 'closed_build' in r else '—')
        w(f'| {r["text"]} | {r["build"]:.3f} | {r["resolution"]} | {r["rate"] / 1e6:.2f} M | '
          f'{r["error"]:.1e} | {r["error_kind"]} | {r.get("equilibria", math.nan):.3f} | '
          f'{closed} |')
    w('')
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--quick', action='store_true', help='shorter runs (a smoke test)')
    args = parser.parse_args(argv)
    result = measure(quick=args.quick)
    print('\n'.join(report_lines(result)))
    return 0


if __name__ == '__main__':
    sys.exit(main())

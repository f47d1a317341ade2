#!/usr/bin/env python3
"""``twodisk-explore`` in headless Chromium: frames a second, the server's CPU, the time from a
slider's change to the new motion on screen, the size of a lesson. Writes its section of
docs/benchmarks.md (between the markers ``<!-- explore:begin -->`` and ``<!-- explore:end -->``,
appended when absent) and prints JSON.

- fps: requestAnimationFrame callbacks a second of the live page (config/oloid.yaml), Debian's
  chromium with software GL (SwiftShader through ANGLE), at two viewport sizes;
- server CPU: the command as users run it (``python -m twodisk_ros.explore --params-file
  config/oloid.yaml``) with that page connected, its CPU time over ``--seconds`` of wall time
  from /proc (1 = one core), and the browser's whole process tree beside it;
- slider → new motion: the End key on the slider of ``a`` (0.1 → 0.3 m: the body three times
  larger) until a screenshot shows at least twice the body's pixels of the last one before,
  repeated; the server's share of it (key → the restarted motion's first frame sent) beside;
- a lesson: ``--export`` of 20 s of the oloid and of the egg (bytes).

Run ``python benchmarks/explore_rate.py [--quick] [--out docs/benchmarks.md]`` (PYTHONPATH = the
repository); ``make bench`` runs it after benchmarks/run_all.py. ``--baseline DIR`` measures the
page of another checkout (its ``twodisk_ros``, e.g. the main branch) the same way, with this
script and this browser set-up, interleaved with this one, and reports both side by side.
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import time

from sections import replace_section

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BEGIN, END = '<!-- explore:begin -->', '<!-- explore:end -->'


def _parser():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--quick', action='store_true', help='short windows (a smoke run)')
    parser.add_argument('--out', default=os.path.join(ROOT, 'docs', 'benchmarks.md'),
                        help='the report whose section is written (default docs/benchmarks.md)')
    parser.add_argument('--no-write', action='store_true', help='print the JSON only')
    parser.add_argument('--baseline', metavar='DIR',
                        help="also measure the page of the checkout DIR (its twodisk_ros)")
    parser.add_argument('--code', metavar='DIR', help=argparse.SUPPRESS)   # the page measured
    return parser


def _ticks(pid):
    fields = open(f'/proc/{pid}/stat').read().rsplit(')', 1)[1].split()
    return int(fields[11]) + int(fields[12])


def _tree_ticks(root):
    """CPU ticks of ``root`` and all its descendants."""
    parents, ticks = {}, {}
    for name in os.listdir('/proc'):
        if name.isdigit():
            try:
                fields = open(f'/proc/{name}/stat').read().rsplit(')', 1)[1].split()
            except OSError:
                continue
            parents[int(name)] = int(fields[1])
            ticks[int(name)] = int(fields[11]) + int(fields[12])
    children = {}
    for pid, parent in parents.items():
        children.setdefault(parent, []).append(pid)
    total, todo = 0, [root]
    while todo:
        pid = todo.pop()
        total += ticks.get(pid, 0)
        todo += children.get(pid, [])
    return total


def _open(browser, url):
    browser.goto(url)
    browser.wait_for("document.body !== null && document.body.innerText.includes('rolling')",
                     timeout=60)
    browser.evaluate("document.querySelectorAll('.mantine-Notification-closeButton')"
                     ".forEach(b => b.click())")


def server_cpu(seconds, code=ROOT):
    """The command with one page connected: its CPU share and the browser's (1 = a core)."""
    from chromium import Chromium
    env = dict(os.environ, PYTHONPATH=code)
    process = subprocess.Popen(
        [sys.executable, '-m', 'twodisk_ros.explore', '--params-file',
         os.path.join(ROOT, 'config', 'oloid.yaml')], stdout=subprocess.PIPE, text=True,
        env=env, start_new_session=True)
    browser = None
    try:
        line = process.stdout.readline()
        url = re.search(r'http://\S+/', line).group(0)
        browser = Chromium(1280, 800)
        _open(browser, url)
        time.sleep(2.0)
        tick = os.sysconf('SC_CLK_TCK')
        s0, b0, t0 = _ticks(process.pid), _tree_ticks(browser.process.pid), time.monotonic()
        time.sleep(seconds)
        s1, b1, t1 = _ticks(process.pid), _tree_ticks(browser.process.pid), time.monotonic()
        return {'server_cpu': (s1 - s0) / tick / (t1 - t0),
                'browser_cpu': (b1 - b0) / tick / (t1 - t0), 'window_s': t1 - t0}
    finally:
        if browser is not None:
            browser.close()
        process.terminate()
        process.wait(timeout=20)


def _slider(browser, label):
    browser.evaluate(
        "(() => { const label = Array.from(document.querySelectorAll('label, div, span'))"
        f".find(e => e.children.length === 0 && e.innerText === {label!r}); "
        "let row = label; while (row && !row.querySelector('[role=slider]')) "
        "row = row.parentElement; row.querySelector('[role=slider]').focus(); })()")


def page_measures(repeats, fps_seconds):
    """fps at two sizes, and slider → new motion on screen, with an in-process server."""
    sys.path.insert(0, os.path.join(ROOT, 'tests'))
    from chromium import Chromium
    from test_explore_browser import body_pixels
    from twodisk_ros.explore.cli import _server, stop_server
    from twodisk_ros.explore.motion import open_motion
    from twodisk_ros.explore.page import Explorer
    from twodisk_ros.runs import settings_from
    settings = settings_from(os.path.join(ROOT, 'config', 'oloid.yaml'), realtime=True)
    server = _server('127.0.0.1', 0)
    explorer = Explorer(server, open_motion(settings=settings)).start()
    url = f'http://127.0.0.1:{server.get_port()}/'
    result = {'fps': {}}
    try:
        for width, height in ((1280, 800), (800, 500)):
            browser = Chromium(width, height)
            try:
                _open(browser, url)
                time.sleep(2.0)
                result['fps'][f'{width}x{height}'] = browser.fps(fps_seconds)
                explorer.plots_control.value = False
                explorer._show_plots()
                time.sleep(1.0)
                result['fps'][f'{width}x{height}, plots hidden'] = browser.fps(fps_seconds)
                explorer.plots_control.value = True
                explorer._show_plots()
                if width == 800:
                    result.update(_latencies(browser, explorer, body_pixels, repeats))
            finally:
                browser.close()
    finally:
        explorer.stop()
        stop_server(server)
    return result


def empty_page_fps(fps_seconds):
    """Frames a second of an empty page of the same client (the served one, with explore/
    client.py's script): no node but one frame without axes, moved 30 times a second so
    that the page draws every frame, at the two sizes: what software GL costs here before
    anything is drawn."""
    import threading
    from chromium import Chromium
    from twodisk_ros.explore.cli import _server, stop_server
    server = _server('127.0.0.1', 0)
    node = server.scene.add_frame('/moved', show_axes=False)
    stop = threading.Event()

    def move():
        k = 0
        while not stop.wait(1.0 / 30):
            k += 1
            node.position = (1e-3 * (k % 2), 0.0, 0.0)
    thread = threading.Thread(target=move, daemon=True)
    thread.start()
    fps = {}
    try:
        for width, height in ((1280, 800), (800, 500)):
            browser = Chromium(width, height)
            try:
                browser.goto(f'http://127.0.0.1:{server.get_port()}/')
                browser.wait_for("document.querySelector('canvas') !== null", timeout=60)
                time.sleep(2.0)
                fps[f'{width}x{height}'] = browser.fps(fps_seconds)
            finally:
                browser.close()
    finally:
        stop.set()
        thread.join()
        stop_server(server)
    return fps


def _latencies(browser, explorer, body_pixels, repeats):
    """End on the slider of a (0.1 → 0.3 m) until a frame of the page's screencast (the
    compositor's frames, each with its own timestamp) shows at least twice the body's pixels
    of a screenshot before."""
    on_screen, sent, heard = [], [], []
    for _ in range(repeats):
        explorer.change('a', 0.1)
        explorer.controls['a'].value = 0.1
        time.sleep(1.0)
        before = body_pixels(browser.screenshot()).sum()
        _slider(browser, 'a')
        restarts = explorer.motion.restarts
        start, clock = time.time(), time.monotonic()
        for kind in ('rawKeyDown', 'keyUp'):
            browser.send('Input.dispatchKeyEvent', type=kind, key='End', code='End',
                         windowsVirtualKeyCode=35, nativeVirtualKeyCode=35)
        latency = browser.watch(lambda image: body_pixels(image).sum() >= 2 * before, start,
                                timeout=15.0)
        on_screen.append(math.inf if latency is None else latency)
        if explorer.motion.restarts > restarts:
            heard.append(explorer.changed_at - clock)
            sent.append(explorer.restart_shown - clock)
    explorer.change('a', 0.1)
    return {'latency_s': on_screen, 'server_heard_s': heard, 'server_sent_s': sent}


#: Changes timed on every body of config/: one of the start, one of the body.
CHANGES = (('theta0', lambda s: round(0.8 * s.theta0, 6) or 0.1),
           ('a', lambda s: round(1.1 * s.a, 6)))


def restart_times(repeats):
    """Server side, per config: a control's change to the new motion's first frame drawn
    (Explorer.change then Explorer.step, no browser), the slowest of ``repeats`` changes
    back and forth (s): the first builds the new body, later ones find it cached."""
    import glob
    from twodisk_ros.explore.cli import _server, stop_server
    from twodisk_ros.explore.motion import open_motion
    from twodisk_ros.explore.page import Explorer
    from twodisk_ros.runs import settings_from
    server = _server('127.0.0.1', 0)
    times = {}
    try:
        for path in sorted(glob.glob(os.path.join(ROOT, 'config', '*.yaml'))):
            settings = settings_from(path, realtime=True)
            explorer = Explorer(server, open_motion(settings=settings))
            explorer.step(1 / 30)
            name = os.path.basename(path)[:-5]
            times[name] = {}
            for parameter, value in CHANGES:
                if settings.shape == 'points' and parameter == 'a':
                    continue
                runs = []
                for k in range(repeats):
                    new = value(settings) if k % 2 == 0 else getattr(settings, parameter)
                    start = time.perf_counter()
                    reason = explorer.change(parameter, new)
                    explorer.step(1 / 30)
                    runs.append(time.perf_counter() - start if reason is None else math.nan)
                times[name][parameter] = max(runs)
            server.scene.reset()
            server.gui.reset()
    finally:
        stop_server(server)
    return times


def lesson_sizes(seconds):
    from twodisk_ros.explore.cli import export
    from twodisk_ros.explore.motion import open_motion
    from twodisk_ros.runs import settings_from
    import tempfile
    sizes = {}
    for name in ('oloid', 'egg'):
        settings = settings_from(os.path.join(ROOT, 'config', f'{name}.yaml'), realtime=True)
        with tempfile.TemporaryDirectory() as tmp:
            start = time.monotonic()
            sizes[name] = {'bytes': export(open_motion(settings=settings),
                                           os.path.join(tmp, 'lesson.html'), seconds),
                           'export_s': time.monotonic() - start}
    return sizes


def _median(values):
    values = sorted(values)
    return values[len(values) // 2] if values else float('nan')


def _before(r, pick):
    """' | a / b' of the baseline's two runs, or '' without a baseline."""
    if 'baseline' not in r:
        return ''
    return ' | ' + ' / '.join(pick(run) for run in r['baseline']['runs'])


def section(r):
    fps = r['fps']
    lat = r['latency_s']
    base = 'baseline' in r
    head = ('| measure | this page | before (baseline, run before / after) | target |'
            if base else '| measure | value | target |')
    rule = '| --- | --- | --- | --- |' if base else '| --- | --- | --- |'
    blank = ' | -' if base else ''
    lines = [
        BEGIN, '## The page in a browser (twodisk-explore)', '',
        '`benchmarks/explore_rate.py` (`make bench`): the live page of config/oloid.yaml in '
        "Debian's headless chromium with software GL for WebGL (SwiftShader through ANGLE) "
        'and software compositing, as Chrome runs without a usable GPU (tests/chromium.py), '
        f'on this shared machine (load average {r["load"]:.1f} at the start, '
        f'{r.get("load_end", r["load"]):.1f} at the end).'
        + (f' Before: the page of `{r["baseline"]["dir"]}` measured the same way, just before '
           'and just after this one.' if base else ''), '',
        head, rule,
        *[f'| page frames a second, {size} | {value:.1f} fps'
          + _before(r, lambda run, size=size: f'{run["fps"][size]:.1f}') + ' | >= 30 fps |'
          for size, value in fps.items()],
        *[f'| an empty page of the same client (one node moved 30 times a second), {size} | '
          f'{value:.1f} fps{blank} | - |' for size, value in r.get('empty_fps', {}).items()],
        f'| server CPU at real time (oloid, one page connected) | {100 * r["server_cpu"]:.1f} '
        '% of a core' + _before(r, lambda run: f'{100 * run["server_cpu"]:.1f} %')
        + ' | <= 25 % |',
        f'| the browser meanwhile (all its processes) | {100 * r["browser_cpu"]:.0f} % of a '
        'core' + _before(r, lambda run: f'{100 * run["browser_cpu"]:.0f} %') + ' | - |',
        f'| slider change to the new motion on screen, median of {len(lat)} (max) | '
        f'{_median(lat):.2f} s ({max(lat):.2f} s)'
        + _before(r, lambda run: f'{_median(run["latency_s"]):.2f} s '
                  f'({max(run["latency_s"]):.2f} s)') + ' | <= 0.5 s |',
        f'| of which: key press to the server\'s callback, median | '
        f'{_median(r["server_heard_s"]):.3f} s'
        + _before(r, lambda run: f'{_median(run["server_heard_s"]):.3f} s') + ' | - |',
        f'| key press to the new motion\'s first frame sent, median | '
        f'{_median(r["server_sent_s"]):.3f} s'
        + _before(r, lambda run: f'{_median(run["server_sent_s"]):.3f} s') + ' | - |',
        *[f'| lesson of {r["lesson_seconds"]:g} s, {name} (`--export`) | '
          f'{v["bytes"] / 1e6:.2f} MB, written in {v["export_s"]:.1f} s{blank} | a few MB |'
          for name, v in r['lessons'].items()],
        '',
        'Server side, a change of a control to the first frame of the new motion '
        '(`Explorer.change` then one frame, no browser; the slowest of '
        f'{r["restart_repeats"]} changes back and forth, s): a change of theta0 reuses the '
        'body\'s tables (the same body, mass model and gravity), a change of a builds a new '
        'body (its lamina, cycle tables and equilibria: the superellipse of '
        'rounded_square.yaml takes longest).', '',
        '| config | theta0 | a |', '| --- | --- | --- |',
        *[f'| {name} | {v.get("theta0", math.nan):.3f} | {v.get("a", math.nan):.3f} |'
          for name, v in r['restart_s'].items()],
        '',
        *_where_the_time_goes(r), END]
    return '\n'.join(lines) + '\n'


def _where_the_time_goes(r):
    """The section's closing paragraphs: what a frame costs and why, and the targets."""
    empty = r.get('empty_fps', {})
    reach = ', '.join(f'{size}: {value:.0f} fps' for size, value in empty.items())
    below = [size for size, value in empty.items() if value < 30]
    return [
        'Where a frame goes under software GL: the browser\'s GPU process (SwiftShader) '
        'takes most of the CPU of a frame, the page\'s renderer (JavaScript, the panel, '
        'the plots) a fifth to a third of it. Two defaults cost most: viser\'s client asks '
        'WebGL for multisampling, which SwiftShader pays about twice for (the page\'s script, '
        'explore/client.py, turns it off when the browser names a software renderer; a '
        'browser with a GPU keeps it), and viser\'s lines are instanced quads, one instance '
        'per segment, whose cost in SwiftShader grows with the instances: the traces (about '
        '1000 segments in some 45 line nodes) took most of the frame, and are now meshes '
        '(strips of two crossed rectangles, about 15 meshes; a finished chunk keeps only the '
        'points needed to pass within 1e-3 body sizes of every sample), but for the current '
        'chunk of each trace (at most 64 segments, resent at every frame sent): a line costs '
        'the server a quarter of a strip\'s vertices to build and send. The environment map '
        'and shadow maps were already off; the grid, the two disks\' meshes, the arrows and '
        'the plots (redrawn 5 times a second) cost the rest.', '',
        f'The targets under software GL on this 2-core machine: an empty page of the same '
        f'client draws {reach} (rows above), which bounds the page\'s rate'
        + (f'; at {" and ".join(below)} it is below 30 fps before anything is drawn, so 30 fps '
           'cannot be reached there with software GL' if below else '')
        + '. The slider\'s latency is measured on the page\'s screencast frames (each '
        'with its own timestamp), so it includes the frames of the software renderer until '
        'the new body shows; the server\'s share (key press to the first frame sent) '
        'includes the new body\'s build (table above) on the loaded machine.']


def page(args):
    """The measures of the page of the code imported (fps, server CPU, latency)."""
    results = page_measures(2 if args.quick else 5, 1.0 if args.quick else 3.0)
    results.update(server_cpu(3.0 if args.quick else 10.0, args.code or ROOT))
    return results


def baseline(args):
    """The page measures of the checkout ``args.baseline`` (a run of this script with
    ``--code``)."""
    command = [sys.executable, os.path.abspath(__file__), '--code', args.baseline, '--no-write']
    if args.quick:
        command.append('--quick')
    env = dict(os.environ, PYTHONPATH=args.baseline)
    output = subprocess.run(command, env=env, capture_output=True, text=True, check=True).stdout
    return json.loads(output[output.index('{'):])


def main():
    args = _parser().parse_args()
    sys.path.insert(0, os.path.join(ROOT, 'tests'))
    code = args.code or ROOT
    if code not in sys.path:
        sys.path.insert(0, code)
    from chromium import missing
    reason = missing()
    if reason:
        print(f'explore_rate: skipped: {reason}', file=sys.stderr)
        return 0
    load = os.getloadavg()[0]
    if args.code:                     # a baseline's page measures only
        print(json.dumps(page(args)))
        return 0
    results = {'load': load}
    before = baseline(args) if args.baseline else None
    results.update(page(args))
    if args.baseline:                 # before, after, before again: the machine's load drifts
        again = baseline(args)
        results['baseline'] = {'dir': args.baseline, 'runs': [before, again]}
    results['empty_fps'] = empty_page_fps(1.0 if args.quick else 3.0)
    results['restart_repeats'] = 2 if args.quick else 4
    results['restart_s'] = restart_times(results['restart_repeats'])
    results['lesson_seconds'] = 5.0 if args.quick else 20.0
    results['lessons'] = lesson_sizes(results['lesson_seconds'])
    results['load_end'] = os.getloadavg()[0]
    print(json.dumps(results, indent=1))
    if not args.no_write:
        replace_section(args.out, section(results), BEGIN, END)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

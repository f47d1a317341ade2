"""The set-up's extra seconds for building tf2_msgs/msg/TFMessage (part of ``make bench``).

``make venv`` builds TFMessage from interfaces/tf2_msgs with tools/build_interfaces.py. This
times that script into a fresh temporary prefix (what a fresh clone pays once), split into its
steps as the build log records them (``# step NAME: S s``), and a second run on the same
prefix (what every later ``make venv`` pays when make's stamp is stale but nothing changed;
when the stamp is fresh make does not start the script at all).

Run: ``python benchmarks/setup_cost.py``.
"""

import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / 'tools' / 'build_interfaces.py'
STEP = re.compile(r'^# step (.+): ([0-9.]+) s, exit status 0$', re.MULTILINE)


def _timed(args):
    start = time.perf_counter()
    result = subprocess.run([sys.executable, str(SCRIPT), *map(str, args)],
                            capture_output=True, text=True, stdin=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    if result.returncode != 0:
        raise RuntimeError(f'tools/build_interfaces.py failed: {result.stderr.strip()}')
    return wall


def build_cost(repeats=2):
    """Seconds of the TFMessage build into a fresh prefix (best of ``repeats``), its steps
    (of that best run), and of a second, up-to-date run."""
    runs = []
    for _ in range(repeats):
        with tempfile.TemporaryDirectory(prefix='tf2_msgs-bench-') as root:
            root = Path(root)
            args = ['--prefix', root / 'prefix', '--stamp', root / 'stamp',
                    '--log', root / 'build.log']
            wall = _timed(args)
            steps = {name: float(s) for name, s in
                     STEP.findall((root / 'build.log').read_text(encoding='utf-8'))}
            again = _timed(args)
            files = sum(1 for p in (root / 'prefix').rglob('*') if p.is_file())
            size = sum(p.stat().st_size for p in (root / 'prefix').rglob('*') if p.is_file())
        runs.append({'wall': wall, 'steps': steps, 'up_to_date': again, 'files': files,
                     'bytes': size})
    best = min(runs, key=lambda r: r['wall'])
    best['repeats'] = repeats
    best['walls'] = [r['wall'] for r in runs]
    return best


def report_lines(cost):
    """The report's section (Markdown lines)."""
    steps = ', '.join(f'{name} {seconds:.1f} s' for name, seconds in cost['steps'].items())
    return [
        '## Set-up: building tf2_msgs/TFMessage\n',
        '`make venv` builds TFMessage (not a wheel) from `interfaces/tf2_msgs` with '
        '`tools/build_interfaces.py`, once per venv. Timed here into a fresh temporary prefix, '
        f'best of {cost["repeats"]} (runs: '
        + ', '.join(f'{w:.1f} s' for w in cost['walls']) + '):\n',
        '| build, whole script (s) | its steps (s) | installed | second run, up to date (s) |',
        '|---|---|---|---|',
        f'| {cost["wall"]:.1f} | {steps} | {cost["files"]} files, '
        f'{cost["bytes"] / 1024:.0f} KiB | {cost["up_to_date"]:.2f} |',
        '\nThe pip install of the tool chain it needs (pinned in requirements.txt) is part of '
        'the ordinary `pip install -r requirements.txt` and not included. When make\'s stamp '
        '`.venv/.tf2_msgs` is newer than its inputs, `make venv` does not start the script.\n',
    ]


def main():
    cost = build_cost()
    print('\n'.join(report_lines(cost)))


if __name__ == '__main__':
    import argparse
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    main()

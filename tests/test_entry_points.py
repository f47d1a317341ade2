"""A newcomer's first commands: every entry point answers ``--help``, and the set-up installs
the package so that the README's commands run from any directory.

``make`` (what ``make test`` runs first) installs twodisk_ros into ``.venv``; these tests run
the installed console scripts from an empty directory, with no ``PYTHONPATH``, and check that
``--help`` prints help, exits 0 and leaves no file or directory behind (the subprocess timeout
only guards against a hang; tests/test_figures.py and tests/test_cli_outputs.py check that help
does no heavy work by refusing the heavy imports).
"""

import configparser
import os
import re
import subprocess
import sys
from pathlib import Path

from package_helpers import console_scripts
from PIL import Image
from zygote import Zygote

import pytest

REPO = Path(__file__).resolve().parents[1]
VENV_BIN = Path(sys.executable).parent
ENV = {key: value for key, value in os.environ.items() if key != 'PYTHONPATH'}
ENV.update(ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID='96', MPLBACKEND='Agg')


def _console_scripts():
    return console_scripts()


def _main_modules():
    """Every module of the package and of benchmarks/ that runs as a program."""
    found = []
    for path in sorted((REPO / 'twodisk_ros').rglob('*.py')):
        text = path.read_text(encoding='utf-8')
        if "__name__ == '__main__'" in text or path.name == '__main__.py':
            parts = path.relative_to(REPO).with_suffix('').parts
            if parts[-1] == '__main__':
                parts = parts[:-1]
            found.append('.'.join(parts))
    return found


SCRIPTS = _console_scripts()
MODULES = _main_modules()
BENCHMARKS = sorted(path.name for path in (REPO / 'benchmarks').glob('*.py')
                    if "__name__ == '__main__'" in path.read_text(encoding='utf-8'))


def _help(command, cwd, env=ENV):
    result = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True,
                            timeout=60, stdin=subprocess.DEVNULL)
    return result, None


def _assert_help(result, elapsed, cwd, label):
    assert result.returncode == 0, f'{label}: exit {result.returncode}\n{result.stderr[-2000:]}'
    assert 'usage' in result.stdout.lower(), f'{label} printed no usage:\n{result.stdout}'
    assert 'Traceback' not in result.stderr, result.stderr
    assert list(Path(cwd).iterdir()) == [], f'{label} --help wrote {list(Path(cwd).iterdir())}'


def test_setup_installs_every_console_script():
    """``make`` puts each console script of setup.py into .venv/bin (not only colcon)."""
    missing = [name for name in SCRIPTS if not (VENV_BIN / name).is_file()]
    assert not missing, f'not in {VENV_BIN}: {missing} (run make venv)'
    assert set(SCRIPTS) >= {'roller', 'twodisk-inspect', 'twodisk-animate', 'twodisk-sweep'}


def test_setup_installs_the_parameter_files():
    """The README's ``$VIRTUAL_ENV/share/twodisk_ros/config/...`` paths exist after ``make``."""
    share = Path(sys.prefix) / 'share' / 'twodisk_ros' / 'config'
    for path in sorted((REPO / 'config').iterdir()):
        assert (share / path.name).read_bytes() == path.read_bytes(), path.name


@pytest.mark.parametrize('name', sorted(SCRIPTS))
@pytest.mark.parametrize('flag', ['--help', '-h'])
def test_console_script_help_from_another_directory(tmp_path, name, flag):
    result, elapsed = _help([str(VENV_BIN / name), flag], tmp_path)
    _assert_help(result, elapsed, tmp_path, f'{name} {flag}')


@pytest.fixture(scope='module')
def forked_help(tmp_path_factory):
    """``--help`` of every program module and benchmark script, each in an empty directory
    of its own, in children of one fork server (tests/zygote.py: the interpreter's start-up
    paid once, not 31 times); label -> (result, its directory)."""
    root = tmp_path_factory.mktemp('help')
    jobs = [(f'python -m {m} --help', ['-m', m]) for m in MODULES] + [
        (f'benchmarks/{s} --help', [str(REPO / 'benchmarks' / s)]) for s in BENCHMARKS]
    results = {}
    with Zygote(dict(ENV, PYTHONPATH=str(REPO))) as zygote:
        for k, (label, args) in enumerate(jobs):
            cwd = root / f'cwd{k}'
            cwd.mkdir()
            results[label] = (zygote.run([*args, '--help'], cwd=cwd, timeout=60), cwd)
    return results


@pytest.mark.parametrize('module', MODULES)
def test_module_help_has_no_side_effects(forked_help, module):
    label = f'python -m {module} --help'
    result, cwd = forked_help[label]
    _assert_help(result, None, cwd, label)


@pytest.mark.parametrize('script', BENCHMARKS)
def test_benchmark_help_has_no_side_effects(forked_help, script):
    label = f'benchmarks/{script} --help'
    result, cwd = forked_help[label]
    _assert_help(result, None, cwd, label)


def test_roller_version(tmp_path):
    result, _ = _help([str(VENV_BIN / 'roller'), '--version'], tmp_path)
    version = re.search(r'<version>([^<]+)</version>',
                        (REPO / 'package.xml').read_text(encoding='utf-8')).group(1)
    assert result.returncode == 0 and version in result.stdout, result
    assert list(tmp_path.iterdir()) == []


def test_readme_python_block_runs_as_a_saved_script_anywhere(tmp_path):
    """The README's library example, saved to a file, runs from another directory."""
    text = (REPO / 'README.md').read_text(encoding='utf-8')
    blocks = re.findall(r'^```python[ \t]*\n(.*?)^```', text, re.MULTILINE | re.DOTALL)
    assert blocks
    for number, code in enumerate(blocks):
        script = tmp_path / f'example{number}.py'
        script.write_text(code, encoding='utf-8')
        result = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=ENV,
                                capture_output=True, text=True, timeout=300)
        assert result.returncode == 0, result.stderr[-3000:]


def test_readme_names_only_commands_that_exist():
    """Every ``.venv/bin/X`` and every console script the README names is installed."""
    text = (REPO / 'README.md').read_text(encoding='utf-8')
    for name in re.findall(r'\.venv/bin/([\w-]+)', text):
        assert (VENV_BIN / name).is_file(), f'README names .venv/bin/{name}'


def test_setup_cfg_keeps_the_ros2_run_layout():
    """colcon installs the scripts where ``ros2 run`` looks (lib/twodisk_ros)."""
    config = configparser.ConfigParser()
    config.read(REPO / 'setup.cfg')
    assert config['install']['install_scripts'] == '$base/lib/twodisk_ros'


def test_readme_quick_start_commands_run_from_another_directory(tmp_path):
    """The README's "from any directory" block, as written, in an empty directory.

    Only the checkout's path is filled in; no PYTHONPATH, no active venv beforehand.
    """
    text = (REPO / 'README.md').read_text(encoding='utf-8')
    blocks = re.findall(r'^```sh[ \t]*\n(.*?)^```', text, re.MULTILINE | re.DOTALL)
    block = next(b for b in blocks if 'source /path/to/twodisk_ros/.venv/bin/activate' in b)
    script = 'set -euo pipefail\n' + block.replace('/path/to/twodisk_ros', str(REPO))
    env = {key: value for key, value in ENV.items() if key not in ('VIRTUAL_ENV',)}
    env['PATH'] = ':'.join(p for p in env.get('PATH', '').split(':')
                           if not p.startswith(str(VENV_BIN)))
    result = subprocess.run(['bash', '-c', script], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    for name in ('run.mcap', 'run.png', 'run.csv', 'run.gif'):
        assert (tmp_path / name).stat().st_size > 0, name
    assert 'usage' in result.stdout.lower()


def test_replaced_outputs_get_the_mode_of_a_plain_open(tmp_path):
    """Outputs written through ``outputs.replacing`` are not left private (mkstemp's 0600)."""
    from twodisk_ros.outputs import replacing
    target = tmp_path / 'out.txt'
    umask = os.umask(0o022)
    try:
        with replacing(target) as temporary:
            Path(temporary).write_text('x')
    finally:
        os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o644
    assert [p.name for p in tmp_path.iterdir()] == ['out.txt']


@pytest.mark.slow
def test_make_demo_works_twice(tmp_path):
    """``make demo`` (the README's first command) succeeds, and again in the same place.

    The first run records and checks the README's 20 s but animates 1 s of it instead of 6
    (``GIF_SECONDS``: the GIF's length changes the number of frames drawn, nothing else;
    the README's quick start below animates 4 s, tests/test_animation.py make demo's
    480 × 360 frame); the second,
    over the outputs of the first, records 2 s and animates 0.5 s (``DEMO_SECONDS``): its
    claim is that the existing files are replaced, which does not depend on their length.
    """
    out = tmp_path / 'out'
    for run, span in ((1, ['GIF_SECONDS=1']), (2, ['DEMO_SECONDS=2.0', 'GIF_SECONDS=0.5'])):
        env = {k: v for k, v in ENV.items() if k not in ('MAKEFLAGS', 'MFLAGS', 'MAKELEVEL')}
        result = subprocess.run(['make', '-C', str(REPO), 'demo', f'OUT={out}', *span],
                                env=env, capture_output=True, text=True, timeout=600)
        assert result.returncode == 0, f'run {run}:\n{result.stdout[-2000:]}{result.stderr[-2000:]}'
        assert 'result: PASS' in result.stdout, result.stdout[-2000:]
        frames = Image.open(out / 'oloid.gif').n_frames
        if run == 1:
            first = (frames, (out / 'oloid.mcap').stat().st_size)
    assert sorted(p.name for p in out.iterdir()) == ['oloid.gif', 'oloid.mcap', 'oloid.png']
    # the second run's shorter recording (2 s of 20) and GIF (0.5 s of 1) replaced the first's
    assert frames < first[0] and (out / 'oloid.mcap').stat().st_size < 0.2 * first[1]

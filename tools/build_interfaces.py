#!/usr/bin/env python3
"""Build tf2_msgs/msg/TFMessage from interfaces/tf2_msgs into a prefix (the venv), once.

tf2_msgs is not a wheel on the package index. ``make venv`` runs this script with the venv's
Python; it generates and compiles TFMessage with the rosidl tool chain of the ROS 2 Jazzy
wheels (pinned in requirements.txt: rosidl_default_generators, ament_cmake, cmake, ninja) and
installs the result into the prefix, so that ``from tf2_msgs.msg import TFMessage`` works and
rclpy can publish it.

- Prerequisites are checked first (cmake, ninja and the rosidl tool chain in the venv, a C and
  a C++ compiler, the Python headers); a missing one is one line naming it and what to install.
- The build runs in a temporary directory and installs into a staging copy of the prefix
  (``DESTDIR``); the staged package is imported and a TFMessage round-tripped through
  rclpy.serialization before anything is copied into the prefix. A failure at any step leaves
  no tf2_msgs file in the prefix and no stamp; the full log is kept in the file it names.
- The stamp (JSON) records a digest of the inputs (the interface package, this script, the
  interpreter, the versions of the tool chain's distributions) and the installed files; a
  second run with the same inputs does nothing. The stamp is also ``make``'s target.

Exit status: 0 built or up to date, 1 a prerequisite is missing or the build failed,
2 bad arguments.
"""

import argparse
import hashlib
import importlib.metadata
import json
import os
from pathlib import Path
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time

REPO = Path(__file__).resolve().parents[1]
PACKAGE = 'tf2_msgs'
WHAT = 'tf2_msgs/TFMessage'
MARKER = 'tools/build_interfaces.py'   # the interface package's package.xml names this script
INSTALL_TOOLS = 'pip install -r requirements.txt into the venv (make venv does)'
# the cmake package's module shims in the venv, the build's tools
TOOLS = ('cmake', 'ninja')
C_COMPILERS = ('cc', 'gcc', 'clang')
CXX_COMPILERS = ('c++', 'g++', 'clang++')

SMOKE_TEST = '''
import sys
from pathlib import Path
import tf2_msgs
from tf2_msgs.msg import TFMessage
from geometry_msgs.msg import TransformStamped
from rclpy.serialization import deserialize_message, serialize_message
assert Path(tf2_msgs.__file__).is_relative_to(sys.argv[1]), tf2_msgs.__file__
message = TFMessage(transforms=[TransformStamped(child_frame_id='a'),
                                TransformStamped(child_frame_id='b')])
assert deserialize_message(serialize_message(message), TFMessage) == message
'''


class Failure(Exception):
    """One line for the user: what is missing or failed, and what to do."""


def _shown(path):
    """A path as the user typed it: relative to the working directory when inside it."""
    path = Path(path)
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def _tool_prefix():
    """The prefix of the running interpreter: where the rosidl tool chain is installed."""
    return Path(sys.prefix)


def _bin_dir():
    return Path(sys.executable).parent


def find_compiler(variable, names, path=None):
    """The compiler CMake would use: ``$CC``/``$CXX`` if set, else the first of ``names``."""
    chosen = os.environ.get(variable)
    if chosen:
        return shutil.which(chosen, path=path), chosen
    for name in names:
        found = shutil.which(name, path=path)
        if found:
            return found, name
    return None, names[0]


def check_prerequisites(package_dir):
    """The compilers ``{'C': path, 'CXX': path}``; raises Failure naming the first missing one."""
    if not (package_dir / 'package.xml').is_file():
        raise Failure(f'no interface package in {_shown(package_dir)} (package.xml missing)')
    for tool in TOOLS:
        if shutil.which(tool, path=str(_bin_dir())) is None:
            raise Failure(f'{tool} is not in {_shown(_bin_dir())}: {INSTALL_TOOLS}')
    generators = (_tool_prefix() / 'share' / 'rosidl_default_generators' / 'cmake'
                  / 'rosidl_default_generatorsConfig.cmake')
    if not generators.is_file():
        raise Failure(f'the rosidl tool chain (rosidl_default_generators) is not in '
                      f'{_shown(_tool_prefix())}: {INSTALL_TOOLS}')
    compilers = {}
    for language, variable, names in (('C', 'CC', C_COMPILERS), ('C++', 'CXX', CXX_COMPILERS)):
        found, name = find_compiler(variable, names)
        if found is None:
            how = f'{variable}={name} is not a program' if os.environ.get(variable) \
                else f'none of {", ".join(names)} on PATH'
            raise Failure(f'no {language} compiler ({how}): apt install gcc g++')
        compilers[variable] = found
    headers = Path(sysconfig.get_paths()['include'])
    if not (headers / 'Python.h').is_file():
        raise Failure(f'no Python headers (Python.h is not in {headers}): apt install '
                      f'python3-dev (the headers of Python {sys.version_info[0]}.'
                      f'{sys.version_info[1]})')
    return compilers


def input_digest(package_dir, prefix):
    """SHA-256 over everything the built files depend on."""
    digest = hashlib.sha256()

    def add(*parts):
        for part in parts:
            data = part if isinstance(part, bytes) else str(part).encode()
            digest.update(len(data).to_bytes(8, 'little') + data)

    for path in sorted(p for p in package_dir.rglob('*') if p.is_file()):
        add(path.relative_to(package_dir).as_posix(), path.read_bytes())
    add(Path(__file__).read_bytes(), sys.version, sys.executable, prefix)
    versions = sorted(
        f'{d.metadata["Name"]}=={d.version}' for d in importlib.metadata.distributions()
        if d.metadata['Name'] and d.metadata['Name'].lower().replace('_', '-').startswith(
            ('ros-', 'cmake', 'ninja', 'numpy', 'catkin-pkg')))
    add(*versions)
    return digest.hexdigest()


def read_stamp(stamp):
    try:
        data = json.loads(stamp.read_text(encoding='utf-8'))
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}


def is_up_to_date(stamp, digest, prefix):
    data = read_stamp(stamp)
    files = data.get('files') or []
    return data.get('digest') == digest and bool(files) \
        and all((prefix / f).is_file() for f in files)


def _run_logged(name, command, log, env, cwd):
    """Run one step with its output in the log, and its wall time (``# step NAME: S s``)."""
    log.write(f'\n$ {" ".join(map(str, command))}\n')
    log.flush()
    start = time.monotonic()
    status = subprocess.run([str(c) for c in command], stdout=log, stderr=subprocess.STDOUT,
                            stdin=subprocess.DEVNULL, env=env, cwd=cwd).returncode
    log.write(f'# step {name}: {time.monotonic() - start:.2f} s, exit status {status}\n')
    log.flush()
    return status


def build_environment():
    """The environment of the build: the venv's tools first, its prefix as the ROS prefix."""
    env = {k: v for k, v in os.environ.items()
           if k not in ('AMENT_PREFIX_PATH', 'CMAKE_PREFIX_PATH', 'COLCON_PREFIX_PATH',
                        'DESTDIR', 'MAKEFLAGS')}
    env['PATH'] = f'{_bin_dir()}{os.pathsep}{env.get("PATH", "")}'
    env['AMENT_PREFIX_PATH'] = env['CMAKE_PREFIX_PATH'] = str(_tool_prefix())
    env['PYTHONDONTWRITEBYTECODE'] = '1'
    return env


def build(package_dir, prefix, work, log, compilers, jobs):
    """Configure, build and stage-install into ``work/stage``; returns the staged prefix."""
    env = build_environment()
    source, binary, stage = work / 'source', work / 'build', work / 'stage'
    # a copy, so that nothing is written next to the sources
    shutil.copytree(package_dir, source)
    cmake = _bin_dir() / 'cmake'
    steps = (
        ('configure', [cmake, '-S', source, '-B', binary, '-G', 'Ninja',
                       f'-DCMAKE_MAKE_PROGRAM={_bin_dir() / "ninja"}',
                       f'-DCMAKE_INSTALL_PREFIX={prefix}', '-DCMAKE_BUILD_TYPE=Release',
                       '-DBUILD_TESTING=OFF', f'-DCMAKE_C_COMPILER={compilers["CC"]}',
                       f'-DCMAKE_CXX_COMPILER={compilers["CXX"]}',
                       f'-DPython3_EXECUTABLE={sys.executable}',
                       f'-DPYTHON_EXECUTABLE={sys.executable}']),
        ('compile', [cmake, '--build', binary, '--parallel', str(jobs)]),
        ('install', [cmake, '--install', binary]),
    )
    for name, command in steps:
        step_env = dict(env, DESTDIR=str(stage)) if name == 'install' else env
        status = _run_logged(name, command, log, step_env, work)
        if status != 0:
            raise Failure(f'the {name} step failed (exit status {status})')
    staged = stage / prefix.relative_to(prefix.anchor)
    if not (staged / 'share' / PACKAGE / 'package.xml').is_file():
        raise Failure(f'the install step put no {PACKAGE} into the staging prefix')
    return staged


def smoke_test(staged, log):
    """Import the staged package and round-trip a TFMessage through rclpy.serialization."""
    purelib = Path(sysconfig.get_path('purelib', vars={'base': str(staged),
                                                       'platbase': str(staged)}))
    env = build_environment()
    env['PYTHONPATH'] = os.pathsep.join(
        [str(purelib)] + [p for p in os.environ.get('PYTHONPATH', '').split(os.pathsep) if p])
    env['LD_LIBRARY_PATH'] = os.pathsep.join(
        [str(staged / 'lib'), str(_tool_prefix() / 'lib')]
        + [p for p in os.environ.get('LD_LIBRARY_PATH', '').split(os.pathsep) if p])
    status = _run_logged('smoke test', [sys.executable, '-c', SMOKE_TEST, purelib], log, env,
                         staged)
    if status != 0:
        raise Failure('the built package does not import or serialise a TFMessage')
    for cache in [p for p in staged.rglob('__pycache__') if p.is_dir()]:
        shutil.rmtree(cache)


def staged_files(staged):
    """Relative paths of the staged files, and the staged directories named like the package."""
    files, owned = [], []
    for path in sorted(staged.rglob('*')):
        relative = path.relative_to(staged)
        if path.is_dir() and not path.is_symlink():
            if path.name == PACKAGE and not any(relative.is_relative_to(o) for o in owned):
                owned.append(relative)
        elif '__pycache__' not in relative.parts:
            files.append(relative)
    return files, owned


def remove_installed(prefix, files, owned):
    """Remove the given files and whole package directories from ``prefix``."""
    for directory in owned:
        shutil.rmtree(prefix / directory, ignore_errors=True)
    for relative in files:
        try:
            (prefix / relative).unlink()
        except (FileNotFoundError, NotADirectoryError):
            pass


def previous_install(prefix, stamp, owned):
    """(files, owned dirs) of an earlier build by this script; Failure if another tf2_msgs."""
    data = read_stamp(stamp)
    files = [Path(f) for f in data.get('files') or []]
    dirs = [Path(d) for d in data.get('dirs') or []]
    package_xml = prefix / 'share' / PACKAGE / 'package.xml'
    if package_xml.is_file() and Path('share', PACKAGE, 'package.xml') not in files:
        if MARKER not in package_xml.read_text(encoding='utf-8', errors='replace'):
            raise Failure(f'a {PACKAGE} not built by this script is in {_shown(prefix)} '
                          f'({_shown(package_xml)}): use it, or remove it first')
        dirs += owned   # built by this script, stamp lost: its directories are ours
    return files, dirs


def install(staged, prefix, stamp, digest):
    """Copy the staged tree into ``prefix``; on any failure remove every tf2_msgs file."""
    files, owned = staged_files(staged)
    old_files, old_dirs = previous_install(prefix, stamp, owned)
    # directories this install creates (the prefix too, if new): removed again on failure
    created = sorted({d for f in files for d in [prefix, *(prefix / f).parents]
                      if d.is_relative_to(prefix) and not d.exists()},
                     key=lambda d: len(d.parts), reverse=True)
    stamp.unlink(missing_ok=True)
    try:
        remove_installed(prefix, old_files, old_dirs)
        for relative in files:
            target = prefix / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            partial = target.with_name(f'.{target.name}.partial')
            shutil.copy2(staged / relative, partial, follow_symlinks=False)
            os.replace(partial, target)
        record = {'what': WHAT, 'digest': digest, 'files': [f.as_posix() for f in files],
                  'dirs': [d.as_posix() for d in owned]}
        partial = stamp.with_name(f'.{stamp.name}.partial')
        partial.write_text(json.dumps(record, indent=1) + '\n', encoding='utf-8')
        os.replace(partial, stamp)
    except BaseException:
        remove_installed(prefix, files + [f.with_name(f'.{f.name}.partial') for f in files],
                         owned)
        for directory in created:
            try:
                directory.rmdir()
            except OSError:
                pass
        stamp.unlink(missing_ok=True)
        raise


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        """Bad arguments: one line, exit status 2."""
        self.exit(2, f'{self.prog}: error: {message} (see --help)\n')


def parse_arguments(argv):
    parser = _Parser(
        description='Build tf2_msgs/msg/TFMessage from interfaces/tf2_msgs with the rosidl '
                    'tool chain of the venv and install it into a prefix (make venv runs '
                    'this). Needs gcc/g++ and the Python headers.')
    parser.add_argument('--prefix', type=Path, default=Path(sys.prefix),
                        help='install prefix (default: this interpreter\'s venv, %(default)s)')
    parser.add_argument('--package', type=Path, default=REPO / 'interfaces' / PACKAGE,
                        help='the interface package (default: %(default)s)')
    parser.add_argument('--stamp', type=Path, default=None,
                        help='stamp file (default: PREFIX/.tf2_msgs)')
    parser.add_argument('--log', type=Path, default=None,
                        help='build log (default: PREFIX/tf2_msgs-build.log)')
    parser.add_argument('--jobs', type=int, default=os.cpu_count() or 1,
                        help='parallel compile jobs (default: %(default)s)')
    parser.add_argument('--check', action='store_true',
                        help='only say whether the prefix is up to date (exit 0) or not (1)')
    parser.add_argument('--force', action='store_true', help='build even if up to date')
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error(f'--jobs must be at least 1, got {args.jobs}')
    args.prefix = args.prefix.absolute()
    args.package = args.package.absolute()
    args.stamp = (args.stamp or args.prefix / '.tf2_msgs').absolute()
    args.log = (args.log or args.prefix / 'tf2_msgs-build.log').absolute()
    return args


def run(args):
    digest = input_digest(args.package, args.prefix) if args.package.is_dir() else ''
    fresh = bool(digest) and is_up_to_date(args.stamp, digest, args.prefix)
    where = _shown(args.prefix)
    if args.check:
        print(f'{WHAT} in {where} is {"up to date" if fresh else "not built or out of date"}')
        return 0 if fresh else 1
    if fresh and not args.force:
        os.utime(args.stamp)   # make's target is newer than its inputs again
        print(f'{WHAT} in {where} is up to date')
        return 0
    compilers = check_prerequisites(args.package)
    start = time.monotonic()
    args.log.parent.mkdir(parents=True, exist_ok=True)
    with open(args.log, 'w', encoding='utf-8') as log, \
            tempfile.TemporaryDirectory(prefix='tf2_msgs-build-') as work:
        log.write(f'building {WHAT} from {args.package} into {args.prefix}\n')
        try:
            staged = build(args.package, args.prefix, Path(work), log, compilers, args.jobs)
            smoke_test(staged, log)
            install(staged, args.prefix, args.stamp, digest)
        except Failure as failure:
            raise Failure(f'{failure}; the log is {_shown(args.log)}') from None
        except OSError as error:
            log.write(f'\n{error!r}\n')
            raise Failure(f'installing into {where} failed ({error.strerror or error}); '
                          f'the log is {_shown(args.log)}') from None
    print(f'built {WHAT} into {where} ({time.monotonic() - start:.0f} s)')
    return 0


def main(argv=None):
    args = parse_arguments(argv)
    try:
        return run(args)
    except Failure as failure:
        print(f'cannot build {WHAT}: {failure}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f'cannot build {WHAT}: interrupted; nothing was installed', file=sys.stderr)
        return 130


if __name__ == '__main__':
    sys.exit(main())

"""tf2_msgs/msg/TFMessage built from interfaces/tf2_msgs by tools/build_interfaces.py.

``make venv`` builds it into .venv; these tests check what it built against independent
references (the type hash that rosbags' Jazzy type store computes from its own definitions,
the CDR bytes of rosbags' serialiser), and the build's set-up behaviour on a temporary prefix
(the venv's compiled files replayed through the script when ``make venv`` built them from this
checkout, a real build otherwise): quiet, a second run does nothing, a missing compiler is one line and leaves the prefix untouched, an
install that fails half-way leaves no tf2_msgs file behind. ROS domain 30 (given to
``rclpy.init``, not set in ``os.environ``: that would leak into the worker's later modules),
localhost.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'

import importlib.util  # noqa: E402
import json  # noqa: E402
from pathlib import Path  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import pytest  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
SCRIPT = REPO / 'tools' / 'build_interfaces.py'
PACKAGE_DIR = REPO / 'interfaces' / 'tf2_msgs'
VENV_BIN = Path(sys.executable).parent
DOMAIN = 30
TYPE = 'tf2_msgs/msg/TFMessage'
#: the hash of Jazzy's own tf2_msgs/msg/TFMessage, as the ROS 2 Jazzy type support reports it
#: (ros2 topic info -v on a Jazzy /tf); rosbags computes it from its own definitions below
JAZZY_HASH = 'RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087'


def _load_script():
    spec = importlib.util.spec_from_file_location('build_interfaces', SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


build_interfaces = _load_script()


def _run_script(*args, env=None, cwd=None):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], cwd=cwd or REPO,
                          env=env, capture_output=True, text=True, timeout=600,
                          stdin=subprocess.DEVNULL)


def _tree(root):
    """Every path under ``root`` with its size, mtime and inode (what a write would change)."""
    return {p.relative_to(root).as_posix(): (p.stat().st_size, p.stat().st_mtime_ns,
                                             p.stat().st_ino)
            for p in sorted(root.rglob('*'))}


def _no_tf2_msgs(root):
    return [p for p in root.rglob('*') if 'tf2_msgs' in p.name]


# -- the package the set-up built into the venv ------------------------------------------------

def test_interface_package_is_tfmessage_only():
    msgs = sorted(p.relative_to(PACKAGE_DIR).as_posix() for p in PACKAGE_DIR.rglob('*.msg'))
    assert msgs == ['msg/TFMessage.msg']
    text = (PACKAGE_DIR / 'msg' / 'TFMessage.msg').read_text(encoding='utf-8')
    assert text.split() == ['geometry_msgs/TransformStamped[]', 'transforms']
    assert not any(PACKAGE_DIR.rglob('*.srv')) and not any(PACKAGE_DIR.rglob('*.action'))
    # colcon in a ROS workspace takes the distribution's tf2_msgs, never this one
    assert (PACKAGE_DIR / 'COLCON_IGNORE').is_file()


def test_type_hash_equals_jazzys():
    """Three hashes agree: rosbags' (its own Jazzy definitions), the installed type
    description (msgdefs.type_hash, what the recorder writes) and rclpy's publisher."""
    from rosbags.typesys import Stores, get_typestore
    from twodisk_ros.recordings.msgdefs import type_hash
    rosbags_hash = get_typestore(Stores.ROS2_JAZZY).hash_rihs01(TYPE)
    assert rosbags_hash == JAZZY_HASH
    assert type_hash(TYPE) == rosbags_hash

    import rclpy
    from tf2_msgs.msg import TFMessage
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=DOMAIN)
    try:
        node = rclpy.create_node('tf2_msgs_hash', context=context)
        node.create_publisher(TFMessage, '/tf_hash_check', 1)
        deadline = time.monotonic() + 30.0
        infos = []
        while not infos and time.monotonic() < deadline:
            infos = node.get_publishers_info_by_topic('/tf_hash_check')
            if not infos:
                time.sleep(0.05)
        assert [str(i.topic_type_hash) for i in infos] == [rosbags_hash]
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)


def _two_transforms():
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage
    first, second = TransformStamped(), TransformStamped()
    first.header.stamp.sec, first.header.stamp.nanosec = 12, 345_678_901
    first.header.frame_id, first.child_frame_id = 'odom', 'twodisk_body'
    first.transform.translation.x, first.transform.translation.z = 0.25, 0.0707
    first.transform.rotation.z, first.transform.rotation.w = 0.6, 0.8
    second.header.frame_id, second.child_frame_id = 'twodisk_body', 'disk_1'
    second.transform.translation.y = -0.05
    second.transform.rotation.x = second.transform.rotation.w = 0.5 ** 0.5
    return TFMessage(transforms=[first, second])


def test_rclpy_serialization_round_trip_matches_rosbags_bytes():
    """rclpy serialises the built type to the CDR that rosbags reads and writes for Jazzy's."""
    from rclpy.serialization import deserialize_message, serialize_message
    from rosbags.typesys import Stores, get_typestore
    from tf2_msgs.msg import TFMessage
    message = _two_transforms()
    data = serialize_message(message)
    back = deserialize_message(data, TFMessage)
    assert back == message
    assert [t.child_frame_id for t in back.transforms] == ['twodisk_body', 'disk_1']

    store = get_typestore(Stores.ROS2_JAZZY)
    decoded = store.deserialize_cdr(data, TYPE)
    assert [t.header.frame_id for t in decoded.transforms] == ['odom', 'twodisk_body']
    assert decoded.transforms[0].header.stamp.nanosec == 345_678_901
    assert decoded.transforms[0].transform.rotation.z == 0.6
    # rosbags' bytes (zero padding; Fast CDR leaves its padding bytes unset) decode in rclpy
    # to the same message, and have the same length
    theirs = bytes(store.serialize_cdr(decoded, TYPE))
    assert len(theirs) == len(data)
    assert deserialize_message(theirs, TFMessage) == message


# -- the build on a temporary prefix ---------------------------------------------------------

VENV_PREFIX = Path(sys.prefix)

#: The build step as the venv's own build ran it, without compiling again: it prints what CMake
#: and Ninja print (on stdout and stderr, through the script's logged runner) and stages the
#: files ``make venv`` built into this venv from this checkout. Everything around it runs as in
#: a real build: the prerequisites, the log, the smoke test (a subprocess imports the staged
#: package and round-trips a TFMessage), the install and the stamp.
REPLAYED_BUILD = r"""
import importlib.util, json, shutil, sys
from pathlib import Path
spec = importlib.util.spec_from_file_location('build_interfaces', sys.argv[1])
tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tool)
venv = Path(sys.argv[2])

def build(package_dir, prefix, work, log, compilers, jobs):
    env = tool.build_environment()
    for name, out in (('configure', '-- Configuring done'),
                      ('compile', '[9/36] Linking C shared library libtf2_msgs__rosidl_generator_c.so')):
        tool._run_logged(name, ['sh', '-c', f'echo "{out}"; echo "{name}: a warning" >&2'],
                         log, env, work)
    staged = work / 'stage' / prefix.relative_to(prefix.anchor)
    for name in json.loads((venv / '.tf2_msgs').read_text(encoding='utf-8'))['files']:
        (staged / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(venv / name, staged / name, follow_symlinks=False)
    return staged

tool.build = build
sys.exit(tool.main(sys.argv[3:]))
"""


def _venv_build_is_current():
    """``make venv`` built tf2_msgs into this venv from this checkout's inputs, and logged it."""
    digest = build_interfaces.input_digest(PACKAGE_DIR, VENV_PREFIX)
    return (VENV_PREFIX / 'tf2_msgs-build.log').is_file() and build_interfaces.is_up_to_date(
        VENV_PREFIX / '.tf2_msgs', digest, VENV_PREFIX)


@pytest.fixture(scope='module')
def built(tmp_path_factory):
    """A build into a temporary prefix, as ``make venv`` builds into .venv.

    Where the venv's own build is current (``make test`` makes it first), the compile is not
    repeated (~20 s): the build step is :data:`REPLAYED_BUILD`, and the real compile's log is
    checked in :func:`test_the_venv_build_compiled_into_its_log`. Otherwise the real build runs.
    """
    root = tmp_path_factory.mktemp('tf2_build')
    prefix, stamp, log = root / 'prefix', root / 'stamp.json', root / 'build.log'
    args = ('--prefix', prefix, '--stamp', stamp, '--log', log)
    if _venv_build_is_current():
        result = subprocess.run([sys.executable, '-c', REPLAYED_BUILD, SCRIPT, VENV_PREFIX,
                                 *map(str, args)], cwd=REPO, capture_output=True, text=True,
                                timeout=600, stdin=subprocess.DEVNULL)
    else:
        result = _run_script(*args)
    assert result.returncode == 0, result.stderr + log.read_text(errors='replace')[-3000:]
    return prefix, stamp, log, result


def test_the_venv_build_compiled_into_its_log():
    """The venv's build (make venv) compiled the libraries, and its output went to the log."""
    if not _venv_build_is_current():
        pytest.skip('tf2_msgs in this venv was not built by make venv from this checkout')
    text = (VENV_PREFIX / 'tf2_msgs-build.log').read_text(encoding='utf-8')
    assert 'Linking C shared library libtf2_msgs__rosidl_generator_c.so' in text
    assert '# step compile: ' in text and '# step smoke test: ' in text


@pytest.mark.slow
def test_build_is_quiet_and_installs_the_type(built):
    prefix, stamp, log, result = built
    assert result.stderr == ''
    lines = result.stdout.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f'built tf2_msgs/TFMessage into {prefix} ')
    description = json.loads((prefix / 'share' / 'tf2_msgs' / 'msg' / 'TFMessage.json')
                             .read_text(encoding='utf-8'))
    hashes = {h['type_name']: h['hash_string'] for h in description['type_hashes']}
    assert hashes[TYPE] == JAZZY_HASH
    assert any(prefix.glob('lib/python3*/site-packages/tf2_msgs/msg/_tf_message.py'))
    assert any(prefix.glob('lib/libtf2_msgs__rosidl_typesupport_c.so'))
    # the stamp lists exactly the installed files, and none is a build leftover
    files = json.loads(stamp.read_text(encoding='utf-8'))['files']
    installed = sorted(p.relative_to(prefix).as_posix() for p in prefix.rglob('*')
                       if p.is_file() and '__pycache__' not in p.parts)
    assert sorted(files) == installed
    assert not any(name.endswith('.partial') for name in installed)
    # what the build step printed went to the log, and nothing of it to stdout or stderr
    assert 'Linking C shared' in log.read_text(encoding='utf-8')
    assert '# step smoke test: ' in log.read_text(encoding='utf-8')


@pytest.mark.slow
def test_second_run_does_nothing(built):
    prefix, stamp, log, _ = built
    before, log_before = _tree(prefix), log.stat().st_mtime_ns
    result = _run_script('--prefix', prefix, '--stamp', stamp, '--log', log)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f'tf2_msgs/TFMessage in {prefix} is up to date'
    assert _tree(prefix) == before
    assert log.stat().st_mtime_ns == log_before


@pytest.mark.slow
def test_check_sees_a_changed_definition(built, tmp_path):
    prefix, stamp, log, _ = built
    copy = tmp_path / 'tf2_msgs'
    shutil.copytree(PACKAGE_DIR, copy)
    same = _run_script('--check', '--package', copy, '--prefix', prefix, '--stamp', stamp)
    assert same.returncode == 0, same.stdout + same.stderr
    with open(copy / 'msg' / 'TFMessage.msg', 'a', encoding='utf-8') as fh:
        fh.write('# a comment\n')
    changed = _run_script('--check', '--package', copy, '--prefix', prefix, '--stamp', stamp)
    assert changed.returncode == 1 and 'out of date' in changed.stdout


def test_make_rebuilds_only_when_an_input_changes(tmp_path):
    """The Makefile's stamp: up to date after a build, stale when an interface file or the
    script changes (make -q asks without running anything; -W pretends a file changed)."""
    env = {k: v for k, v in os.environ.items() if k not in ('MAKEFLAGS', 'MFLAGS', 'MAKELEVEL')}
    venv = tmp_path / 'venv'
    venv.mkdir()
    (venv / '.installed').touch()
    (venv / '.tf2_msgs').touch()
    future = time.time() + 3600   # newer than every input of the checkout
    for stamp in ('.installed', '.tf2_msgs'):
        os.utime(venv / stamp, (future, future + (stamp == '.tf2_msgs')))

    def question(*what_if):
        args = ['make', '-q', '-C', str(REPO), f'VENV={venv}', f'{venv}/.tf2_msgs']
        for path in what_if:
            args[2:2] = ['-W', path]
        return subprocess.run(args, env=env, capture_output=True, text=True,
                              timeout=60).returncode

    assert question() == 0
    assert question('interfaces/tf2_msgs/msg/TFMessage.msg') == 1
    assert question('interfaces/tf2_msgs/CMakeLists.txt') == 1
    assert question('interfaces/tf2_msgs/package.xml') == 1
    assert question('tools/build_interfaces.py') == 1
    assert question('README.md') == 0


# -- failures: one line, nothing installed --------------------------------------------------

def _prefix_with_sentinel(tmp_path):
    prefix = tmp_path / 'prefix'
    (prefix / 'lib').mkdir(parents=True)
    (prefix / 'lib' / 'sentinel.txt').write_text('untouched')
    return prefix


def _assert_one_line_failure(result, *needles):
    assert result.returncode == 1, result.stdout + result.stderr
    assert result.stdout == ''
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith('cannot build tf2_msgs/TFMessage: ')
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert 'Traceback' not in result.stderr


def test_no_compiler_on_path_is_one_line_and_installs_nothing(tmp_path):
    prefix = _prefix_with_sentinel(tmp_path)
    before = _tree(prefix)
    env = {k: v for k, v in os.environ.items() if k not in ('CC', 'CXX')}
    env['PATH'] = str(VENV_BIN)   # python, cmake, ninja; no compiler
    stamp, log = tmp_path / 'stamp', tmp_path / 'build.log'
    result = _run_script('--prefix', prefix, '--stamp', stamp, '--log', log, env=env)
    _assert_one_line_failure(result, 'no C compiler', 'apt install gcc g++')
    assert _tree(prefix) == before
    assert not stamp.exists() and not log.exists()


def test_missing_cc_program_is_named(tmp_path):
    prefix = _prefix_with_sentinel(tmp_path)
    before = _tree(prefix)
    env = dict(os.environ, CC=str(tmp_path / 'no-such-cc'))
    result = _run_script('--prefix', prefix, '--stamp', tmp_path / 'stamp', env=env)
    _assert_one_line_failure(result, f'CC={tmp_path / "no-such-cc"}', 'apt install gcc g++')
    assert _tree(prefix) == before


def test_failing_compiler_names_the_log_and_installs_nothing(tmp_path):
    """A compiler that exists but fails: CMake's configure step fails, the log says why."""
    prefix = _prefix_with_sentinel(tmp_path)
    before = _tree(prefix)
    env = dict(os.environ, CC=shutil.which('false'))
    stamp, log = tmp_path / 'stamp', tmp_path / 'build.log'
    result = _run_script('--prefix', prefix, '--stamp', stamp, '--log', log, env=env)
    _assert_one_line_failure(result, 'the configure step failed', f'the log is {log}')
    assert _tree(prefix) == before
    assert not stamp.exists()
    assert 'CMAKE_C_COMPILER' in log.read_text(encoding='utf-8') or \
        'C compiler' in log.read_text(encoding='utf-8')


def test_missing_python_headers_are_named(monkeypatch, tmp_path):
    monkeypatch.setattr(build_interfaces.sysconfig, 'get_paths',
                        lambda: {'include': str(tmp_path)})
    with pytest.raises(build_interfaces.Failure, match='no Python headers .*python3-dev'):
        build_interfaces.check_prerequisites(PACKAGE_DIR)


def _staged_tree(root):
    """A small tree shaped like the build's staged prefix."""
    for relative in ('include/tf2_msgs/tf2_msgs/msg/tf_message.h',
                     'lib/libtf2_msgs__rosidl_generator_c.so',
                     'lib/python3.11/site-packages/tf2_msgs/__init__.py',
                     'share/ament_index/resource_index/packages/tf2_msgs',
                     'share/tf2_msgs/package.xml'):
        (root / relative).parent.mkdir(parents=True, exist_ok=True)
        (root / relative).write_text(f'{relative} {build_interfaces.MARKER}\n')
    return root


def test_install_failing_half_way_leaves_no_tf2_msgs(tmp_path):
    staged = _staged_tree(tmp_path / 'stage')
    prefix = _prefix_with_sentinel(tmp_path)
    # a file where the site-packages directory must go: the copy fails after the headers
    # and the libraries are in place
    (prefix / 'lib' / 'python3.11').write_text('in the way')
    stamp = tmp_path / 'stamp'
    with pytest.raises(OSError):
        build_interfaces.install(staged, prefix, stamp, 'digest')
    assert _no_tf2_msgs(prefix) == []
    assert sorted(p.name for p in prefix.rglob('*')) == ['lib', 'python3.11', 'sentinel.txt']
    assert not stamp.exists()


def test_install_replaces_its_own_build_and_refuses_another_tf2_msgs(tmp_path):
    staged = _staged_tree(tmp_path / 'stage')
    prefix, stamp = tmp_path / 'prefix', tmp_path / 'stamp'
    build_interfaces.install(staged, prefix, stamp, 'one')
    (prefix / 'include' / 'tf2_msgs' / 'stale.h').write_text('from an older build')
    build_interfaces.install(staged, prefix, stamp, 'two')
    assert not (prefix / 'include' / 'tf2_msgs' / 'stale.h').exists()
    assert json.loads(stamp.read_text())['digest'] == 'two'

    other = tmp_path / 'other'
    (other / 'share' / 'tf2_msgs').mkdir(parents=True)
    (other / 'share' / 'tf2_msgs' / 'package.xml').write_text('<package/>')
    with pytest.raises(build_interfaces.Failure, match='not built by this script'):
        build_interfaces.install(staged, other, tmp_path / 'other_stamp', 'x')
    assert (other / 'share' / 'tf2_msgs' / 'package.xml').read_text() == '<package/>'


def test_help_has_no_side_effects(tmp_path):
    result = _run_script('--help', cwd=tmp_path)
    assert result.returncode == 0 and 'usage' in result.stdout.lower()
    assert 'gcc/g++' in result.stdout
    assert list(tmp_path.iterdir()) == []


def test_bad_argument_exits_2(tmp_path):
    result = _run_script('--jobs', '0', cwd=tmp_path)
    assert result.returncode == 2 and '--jobs' in result.stderr
    assert len(result.stderr.splitlines()) == 1 and result.stdout == ''
    assert list(tmp_path.iterdir()) == []


def test_importing_the_module_leaves_ros_domain_id_alone():
    """Module-level settings stay in the module: the worker's later modules keep their own."""
    code = ('import os, sys; os.environ.pop("ROS_DOMAIN_ID", None); '
            f'sys.path.insert(0, {str(REPO / "tests")!r}); import test_tf2_msgs_build; '
            'print(os.environ.get("ROS_DOMAIN_ID"))')
    done = subprocess.run([sys.executable, '-c', code], cwd=REPO, capture_output=True,
                          text=True, timeout=120, stdin=subprocess.DEVNULL,
                          env=dict(os.environ, PYTHONPATH=str(REPO)))
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == 'None'

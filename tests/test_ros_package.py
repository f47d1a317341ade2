"""The ROS 2 package: package.xml metadata, a colcon build, and ``ros2 run``-style execution.

The package is built with colcon into a temporary workspace, the executable is resolved
through ament_index_python exactly as ``ros2 run twodisk_ros roller`` does, and run from the
install space (not the source tree) in batch mode with recording. ROS domain 83, localhost.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ.setdefault('ROS_DOMAIN_ID', '83')

import ast  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import sysconfig  # noqa: E402
import xml.etree.ElementTree as ET  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pytest  # noqa: E402

pytestmark = pytest.mark.ros

REPO = Path(__file__).resolve().parents[1]
PACKAGE = 'twodisk_ros'
DOMAIN = 83
PACKAGE_FILES = ('package.xml', 'setup.py', 'setup.cfg', 'resource', PACKAGE, 'config')
VENV_BIN = Path(sys.executable).parent
VENV_PREFIX = Path(sys.prefix)


# -- package.xml ---------------------------------------------------------------------------

def _package_xml():
    return ET.parse(REPO / 'package.xml').getroot()


def _depends(root, *tags):
    return {e.text.strip() for tag in tags for e in root.findall(tag)}


def _ros_interface_imports(path):
    """Top-level packages of ``pkg.msg`` / ``pkg.srv`` / ``pkg.action`` imports, and rclpy."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        elif isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        else:
            continue
        for name in names:
            parts = name.split('.')
            if parts[0] == 'rclpy' or (len(parts) >= 2 and parts[1] in ('msg', 'srv', 'action')):
                found.add(parts[0])
    return found


def test_package_xml_format_and_build_type():
    root = _package_xml()
    assert root.tag == 'package' and root.get('format') == '3'
    assert root.findtext('name').strip() == PACKAGE
    assert root.findtext('export/build_type').strip() == 'ament_python'
    assert root.findall('license') and root.findall('maintainer')


def test_package_xml_version_matches_setup_py():
    tree = ast.parse((REPO / 'setup.py').read_text(encoding='utf-8'))
    versions = [kw.value.value for node in ast.walk(tree) if isinstance(node, ast.Call)
                for kw in node.keywords
                if kw.arg == 'version' and isinstance(kw.value, ast.Constant)]
    assert versions == [_package_xml().findtext('version').strip()]


def test_exec_depends_cover_imported_ros_packages():
    exec_depends = _depends(_package_xml(), 'exec_depend', 'depend')
    modules = [REPO / PACKAGE / 'node' / 'messages.py', REPO / PACKAGE / 'node' / 'roller.py']
    imported = set().union(*(_ros_interface_imports(m) for m in modules))
    # the scan itself works: the node's known imports are found
    assert {'rclpy', 'geometry_msgs', 'sensor_msgs', 'diagnostic_msgs'} <= imported
    assert imported - exec_depends == set(), 'imported but not an exec_depend'


def test_exec_depends_cover_every_module_of_the_package():
    exec_depends = _depends(_package_xml(), 'exec_depend', 'depend')
    imported = set().union(*(_ros_interface_imports(m)
                             for m in sorted((REPO / PACKAGE).rglob('*.py'))))
    assert imported - exec_depends == set(), 'imported but not an exec_depend'


def test_resource_marker_and_data_files():
    assert (REPO / 'resource' / PACKAGE).is_file()
    assert (REPO / 'config' / 'oloid.yaml').is_file()


# -- colcon build ----------------------------------------------------------------------------

def _clean_env(**extra):
    env = {k: v for k, v in os.environ.items()
           if k not in ('AMENT_PREFIX_PATH', 'COLCON_PREFIX_PATH', 'PYTHONPATH',
                        'CMAKE_PREFIX_PATH')}
    env.update(PATH=f'{VENV_BIN}{os.pathsep}{env.get("PATH", "")}',
               ROS_DOMAIN_ID=str(DOMAIN), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    env.update(extra)
    return env


@pytest.fixture(scope='module')
def workspace(tmp_path_factory):
    root = tmp_path_factory.mktemp('ws')
    source = root / 'src' / PACKAGE
    source.mkdir(parents=True)
    for name in PACKAGE_FILES:
        src = REPO / name
        if src.is_dir():
            shutil.copytree(src, source / name,
                            ignore=shutil.ignore_patterns('__pycache__', '*.pyc'))
        else:
            shutil.copy2(src, source / name)
    colcon = VENV_BIN / 'colcon'
    result = subprocess.run(
        [str(colcon), 'build', '--packages-select', PACKAGE, '--base-paths', 'src',
         '--build-base', 'build', '--install-base', 'install',
         '--event-handlers', 'console_direct+'],
        cwd=root, env=_clean_env(COLCON_HOME=str(root / 'colcon_home'),
                                 COLCON_LOG_PATH=str(root / 'log')),
        capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-4000:]
    return root


@pytest.fixture(scope='module')
def installed(workspace):
    """ament_index as ``ros2 run`` sees it, and the environment the install space needs."""
    import ament_index_python
    prefix_path = f'{workspace / "install" / PACKAGE}{os.pathsep}{VENV_PREFIX}'
    saved = os.environ.get('AMENT_PREFIX_PATH')
    os.environ['AMENT_PREFIX_PATH'] = prefix_path
    try:
        prefix = Path(ament_index_python.get_package_prefix(PACKAGE))
        share = Path(ament_index_python.get_package_share_directory(PACKAGE))
    finally:
        if saved is None:
            del os.environ['AMENT_PREFIX_PATH']
        else:
            os.environ['AMENT_PREFIX_PATH'] = saved
    purelib = sysconfig.get_path('purelib', vars={'base': str(prefix),
                                                  'platbase': str(prefix)})
    env = _clean_env(AMENT_PREFIX_PATH=prefix_path, PYTHONPATH=purelib)
    return prefix, share, env


def test_ament_index_resolves_the_install_space(workspace, installed):
    prefix, share, _ = installed
    assert prefix == workspace / 'install' / PACKAGE
    executable = prefix / 'lib' / PACKAGE / 'roller'
    assert executable.is_file() and os.access(executable, os.X_OK)
    assert (share / 'package.xml').is_file()
    assert (share / 'config' / 'oloid.yaml').is_file()
    assert (share / 'package.xml').read_bytes() == (REPO / 'package.xml').read_bytes()


def test_installed_script_uses_the_venv_python(installed):
    prefix, _, _ = installed
    first = (prefix / 'lib' / PACKAGE / 'roller').read_text().splitlines()[0]
    assert first.startswith('#!')
    interpreter = Path(first[2:].strip().split()[0])
    assert interpreter.parent == VENV_BIN, first


def test_installed_package_is_imported_from_the_install_space(tmp_path, installed):
    prefix, _, env = installed
    result = subprocess.run(
        [sys.executable, '-c', 'import twodisk_ros.roller, twodisk_ros; '
                               'print(twodisk_ros.__file__)'],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert Path(result.stdout.strip()).is_relative_to(prefix)


def test_every_console_script_resolves(tmp_path, installed):
    """Each installed console script's entry point imports (setup.py names no missing module)."""
    prefix, _, env = installed
    code = ('import importlib.metadata as m\n'
            'for ep in m.distribution("twodisk-ros").entry_points:\n'
            '    if ep.group == "console_scripts":\n'
            '        ep.load(); print(ep.name)\n')
    result = subprocess.run([sys.executable, '-c', code], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr[-2000:]
    names = set(result.stdout.split())
    assert 'roller' in names
    assert names == {p.name for p in (prefix / 'lib' / PACKAGE).iterdir()}


def test_ros2_run_style_batch_with_params_file(tmp_path, installed):
    from twodisk_ros.recordings import read_recording
    prefix, share, env = installed
    target = tmp_path / 'run.mcap'
    result = subprocess.run(
        [str(prefix / 'lib' / PACKAGE / 'roller'), '--ros-args',
         '--params-file', str(share / 'config' / 'oloid.yaml'),
         '-p', 'rate:=50.0', '-p', 'realtime:=false', '-p', 'duration:=1.0',
         '-p', f'record:={target}'],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr[-3000:]
    assert 'Traceback' not in result.stderr
    assert target.is_file()
    recording = read_recording(target, decode=lambda topic: topic in ('/pose',
                                                                       '/rolling_state'))
    assert not recording.truncated
    poses = [m for m in recording.messages if m.topic == '/pose']
    assert len(poses) == 51
    stamps = [m.msg.header.stamp.sec * 10**9 + m.msg.header.stamp.nanosec for m in poses]
    assert np.all(np.diff(stamps) == 20_000_000)
    # the params file was applied: the oloid's theta0 = 0.3 is the first recorded theta
    states = [m for m in recording.messages if m.topic == '/rolling_state']
    assert len(states) == 51
    assert list(states[0].msg.name) == ['theta', 'psi', 'phase']
    assert states[0].msg.position[0] == pytest.approx(0.3, abs=1e-9)
    flat = {k: v for record in recording.metadata.values() for k, v in record.items()}
    assert flat.get('delta') == '0.05' and flat.get('mode') == 'dynamic'


def test_installed_executable_rejects_invalid_start_value(tmp_path, installed):
    prefix, share, env = installed
    result = subprocess.run(
        [str(prefix / 'lib' / PACKAGE / 'roller'), '--ros-args',
         '--params-file', str(share / 'config' / 'oloid.yaml'), '-p', 'delta:=0.5'],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 2, result.stderr
    assert len(result.stderr.splitlines()) == 1 and 'Traceback' not in result.stderr


def test_readme_workspace_route_records_and_inspects(workspace, tmp_path):
    """As the README: source install/setup.bash (colcon-bash), record a run, inspect it."""
    setup = workspace / 'install' / 'setup.bash'
    assert setup.is_file(), 'colcon-bash did not write install/setup.bash'
    lib = workspace / 'install' / PACKAGE / 'lib' / PACKAGE
    share = workspace / 'install' / PACKAGE / 'share' / PACKAGE
    script = (f'source {setup} && {lib / "roller"} --ros-args --params-file '
              f'{share / "config" / "oloid.yaml"} -p realtime:=false -p duration:=2.0 '
              f'-p record:=run.mcap && {lib / "twodisk-inspect"} run.mcap')
    result = subprocess.run(['bash', '-c', script], cwd=tmp_path, capture_output=True,
                            text=True, timeout=180,
                            env=_clean_env(COLCON_HOME=str(tmp_path / 'colcon_home')))
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert 'result: PASS' in result.stdout

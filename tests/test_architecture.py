"""The package's architecture, as issue-independent rules that a refactoring must keep.

- the physics imports neither rclpy nor matplotlib;
- reading and checking a recording works where rclpy cannot be imported;
- no module reads another module's private names;
- no module is far over 500 lines.
"""

import ast
import os
from pathlib import Path
import subprocess
import sys

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / 'twodisk_ros'
ENV = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST', ROS_DOMAIN_ID='84')


def _run(code, **env):
    return subprocess.run([sys.executable, '-c', code], cwd=REPO, capture_output=True,
                           text=True, timeout=120, env=dict(ENV, **env))


def test_physics_imports_without_rclpy_or_matplotlib():
    result = _run('import sys, twodisk_ros.physics, twodisk_ros; '
                  'print(sorted(m for m in ("rclpy", "matplotlib") if m in sys.modules))')
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == '[]'


def test_a_default_node_run_does_not_import_scipy_spatial(tmp_path):
    """scipy.spatial costs half a second of CPU at import (k-d trees, sparse matrices, qhull),
    and the node needs only rotation matrices to quaternions of it (Markley's method in
    physics/bodies/orientation.py, checked against scipy in tests/test_poses.py)."""
    record = tmp_path / 'run.mcap'
    code = ('import sys\n'
            'from twodisk_ros.node.main import main\n'
            'status = main(["roller", "--ros-args", "--params-file", "config/oloid.yaml",'
            ' "-p", "realtime:=false", "-p", "duration:=0.2",'
            f' "-p", "record:={record}"])\n'
            'print(sorted(m for m in sys.modules if m.startswith("scipy.spatial")))\n'
            'sys.exit(status)\n')
    result = _run(code)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip().splitlines()[-1] == '[]'


BLOCK_RCLPY = '''
import sys
class _Refuse:
    def find_spec(self, name, path=None, target=None):
        if name == 'rclpy' or name.startswith('rclpy.'):
            raise ImportError('rclpy refused by the test')
sys.meta_path.insert(0, _Refuse())
'''


def test_inspector_runs_where_rclpy_cannot_be_imported(tmp_path):
    # record a short run with the node (rclpy available: the roller's entry function in this
    # process, tests/batch_recording.py), then inspect it in an interpreter without rclpy
    from batch_recording import record
    out = record(tmp_path / 'run.mcap', domain=int(ENV['ROS_DOMAIN_ID']), duration=0.5)
    code = BLOCK_RCLPY + (
        'from twodisk_ros.inspector.cli import main\n'
        f'status = main([{str(out)!r}])\n'
        'assert "rclpy" not in sys.modules\n'
        'sys.exit(status)\n')
    result = _run(code)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-2000:]
    assert 'result: PASS' in result.stdout
    # and the guard itself works: importing rclpy fails in that interpreter
    assert _run(BLOCK_RCLPY + 'import rclpy').returncode != 0


def _modules():
    return sorted(PACKAGE.rglob('*.py'))


#: Standard-library names that are public though they start with an underscore.
PUBLIC_UNDERSCORED = {('os', '_exit')}


def _private_reach_ins(path):
    """(line, text) of every access to a private name of another module of the package."""
    tree = ast.parse(path.read_text(encoding='utf-8'))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module is not None:
            inside = node.level > 0 or node.module.startswith('twodisk_ros')
            for alias in node.names:
                if inside and alias.name.startswith('_') and not alias.name.startswith('__'):
                    found.append((node.lineno, f'from {node.module} import {alias.name}'))
        if isinstance(node, ast.Attribute) and node.attr.startswith('_') \
                and not node.attr.startswith('__'):
            owner = node.value
            if isinstance(owner, ast.Name) and owner.id not in ('self', 'cls') \
                    and (owner.id, node.attr) not in PUBLIC_UNDERSCORED:
                found.append((node.lineno, f'{owner.id}.{node.attr}'))
            elif isinstance(owner, ast.Attribute):
                found.append((node.lineno, f'….{owner.attr}.{node.attr}'))
    return found


@pytest.mark.parametrize('path', _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_module_reads_private_names_of_another(path):
    assert _private_reach_ins(path) == []


@pytest.mark.parametrize('path', _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_modules_stay_small(path):
    lines = len(path.read_text(encoding='utf-8').splitlines())
    assert lines <= 520, f'{path.name} has {lines} lines: split it by concept'


def test_import_linter_contracts_hold_and_place_every_module():
    """The layers of .importlinter (import-linter: every import, deferred ones too), the
    ROS-free and matplotlib-free rules, no import cycles, the physics' own layers; and every
    subpackage and top-level module of the package, and every subpackage of the physics, has
    its place in the layers (a new one must be placed), and the physics has no module outside
    a subpackage."""
    import configparser
    config = configparser.ConfigParser()
    config.read(REPO / '.importlinter', encoding='utf-8')
    layers = config['importlinter:contract:layers']['layers'].split()
    placed = {name.split('.', 1)[1] for name in layers if name != '|'}
    present = {p.stem if p.is_file() else p.name for p in PACKAGE.iterdir()
               if (p.suffix == '.py' and p.stem != '__init__')
               or (p.is_dir() and (p / '__init__.py').is_file())}
    assert placed == present, (sorted(present - placed), sorted(placed - present))
    physics = config['importlinter:contract:physics-layers']['layers'].split()
    concepts = {p.name for p in (PACKAGE / 'physics').iterdir()
                if p.is_dir() and (p / '__init__.py').is_file()}
    assert {name for name in physics if name != '|'} == concepts
    assert [p.name for p in (PACKAGE / 'physics').glob('*.py')] == ['__init__.py']
    lint = Path(sys.executable).parent / 'lint-imports'
    result = subprocess.run([str(lint), '--config', str(REPO / '.importlinter'),
                             '--no-cache'], cwd=REPO, capture_output=True, text=True,
                            timeout=120, env=ENV)
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert 'Contracts: 5 kept, 0 broken.' in result.stdout, result.stdout[-2000:]


NOTHING_IMPORTED_WHILE_SAMPLING = '''
import sys
import numpy as np
from twodisk_ros.run.parameters import DEFAULTS
from twodisk_ros.run.simulation import Simulation
simulation = Simulation(DEFAULTS.with_values(**{values}).checked())
before = set(sys.modules)
for k in range(3):                       # the first blocks of a run, as the node takes them
    simulation.sample(np.linspace(0.5 * k, 0.5 * (k + 1), 51)[:-1])
print(sorted(m for m in set(sys.modules) - before if m.split('.')[0] == 'scipy'))
'''


@pytest.mark.parametrize('values', [{'damping': 0.01}, {'method': 'direct'}],
                         ids=['scene-DOP853', 'direct-DOP853'])
def test_a_run_imports_what_it_integrates_with_before_its_first_sample(values):
    """scipy.integrate costs ~0.6 s to import: inside a real-time node's loop that stall
    dropped up to 360 samples at 1 kHz. The streams that integrate import it when built."""
    result = _run(NOTHING_IMPORTED_WHILE_SAMPLING.format(values=values))
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip().splitlines()[-1] == '[]'


# -- type switches on bodies, laminae, scenes and their motions (issue 29) ------------------

#: Where a class decides what it does, not its callers: the kinds whose instances must not be
#: told apart outside their classes (every class of the bodies, laminae, scenes and motion
#: subpackages, and the mirrored lamina of the hull), but for the protocols themselves
#: (checking that an argument is a Lamina or a RollingBody is validation, not a switch).
KIND_FOLDERS = ('physics/bodies', 'physics/laminae', 'physics/scenes', 'physics/motion',
                'physics/mass/hull_laminae.py')
PROTOCOLS = {'Lamina', 'SupportLamina', 'RollingBody', 'RollingDynamics', 'Scene',
             'SceneTerms'}
#: names under which bodies, laminae, scenes, streams and solutions are passed around: a
#: ``hasattr`` or a defaulted ``getattr`` on them asks what kind of thing it is
SUBJECTS = {'body', 'lamina', 'scene', 'stream', 'solution', 'sol', 'candidate'}


def _kind_classes():
    names = set()
    for path in PACKAGE.rglob('*.py'):
        if path.relative_to(PACKAGE).as_posix().startswith(KIND_FOLDERS):
            names.update(node.name for node in ast.walk(ast.parse(path.read_text('utf-8')))
                         if isinstance(node, ast.ClassDef))
    return names - PROTOCOLS


def _name(node):
    return node.id if isinstance(node, ast.Name) else \
        node.attr if isinstance(node, ast.Attribute) else None


def type_switches():
    """(module, what) of every isinstance / type() comparison against a kind class and every
    hasattr / defaulted getattr on a body, lamina, scene, stream or solution in the package."""
    kinds, found = _kind_classes(), []
    for path in sorted(PACKAGE.rglob('*.py')):
        module = path.relative_to(PACKAGE).as_posix()
        for node in ast.walk(ast.parse(path.read_text('utf-8'))):
            what = None
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
                args = node.args
                if node.func.id == 'isinstance' and len(args) == 2:
                    names = [_name(e) for e in getattr(args[1], 'elts', [args[1]])]
                    if kinds.intersection(names):
                        what = f'isinstance {names}'
                elif (node.func.id == 'hasattr' or (node.func.id == 'getattr'
                                                     and len(args) == 3)) \
                        and len(args) >= 2 and _name(args[0]) in SUBJECTS \
                        and isinstance(args[1], ast.Constant) and args[1].value != 'isatty':
                    what = f'{node.func.id}({_name(args[0])}, {args[1].value})'
            elif isinstance(node, ast.Compare) and isinstance(node.left, ast.Call) \
                    and _name(node.left.func) == 'type':
                names = [_name(c) for c in node.comparators]
                if kinds.intersection(names):
                    what = f'type() {names}'
            if what is not None:
                found.append((module, what))
    return sorted(found)


def test_no_type_switches():
    """Outside their classes, bodies, laminae, scenes and their motions are not told apart
    by type or by the attributes they happen to have: each kind answers for itself through
    its methods (issue 29: the count is 0; a new switch fails here)."""
    assert 'EllipseBody' in _kind_classes() and 'Ellipse' in _kind_classes()
    assert type_switches() == []

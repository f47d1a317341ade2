"""``roller``'s command line: help, arguments outside ``--ros-args``, declared types, hostile
parameter files. The node's real entry point runs in subprocesses (refusals of most kinds:
one or two as processes, the others through the same entry function in process,
tests/roller_here.py); the loader's typing is compared with rclpy's own parse
(rcl_yaml_param_parser) in process.

Subprocess nodes use ROS_DOMAIN_ID from the environment (88 if unset), localhost only.
"""

import os

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ.setdefault('ROS_DOMAIN_ID', '88')

import difflib  # noqa: E402
import math  # noqa: E402
from pathlib import Path  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tracemalloc  # noqa: E402

from hypothesis import given, HealthCheck, settings, strategies as st  # noqa: E402
import pytest  # noqa: E402

import twodisk_ros  # noqa: E402
from twodisk_ros.node.arguments import (ArgumentError, check_arguments, node_fqn,  # noqa: E402
                                        rclpy_type_hint)
from roller_here import run_roller_main  # noqa: E402
from twodisk_ros.run.params_yaml import (MAX_ENTRIES, load_params_file,  # noqa: E402
                                         node_matches, params_file_values, parse_value)

REPO = Path(__file__).resolve().parents[1]
MEMORY_LIMIT = 2 << 30     # bytes of address space: a refused run needs about 0.5 GiB (VmPeak)
BATCH = ('-p', 'realtime:=false', '-p', 'duration:=0.05')


def node_env():
    return dict(os.environ, PYTHONPATH=str(REPO), PYTHONUNBUFFERED='1')


def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


#: Runs ``python -m twodisk_ros.roller`` with rclpy and numpy refused at import: an answer
#: that needs neither (--help, --version, a misplaced argument) cannot have started a run.
LIGHT = """
import runpy, sys
class _Refuse:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('rclpy', 'numpy'):
            raise ImportError(name + ' refused by the test: the answer needs no run')
sys.meta_path.insert(0, _Refuse())
sys.argv = ['roller', *sys.argv[1:]]
runpy.run_module('twodisk_ros.roller', run_name='__main__', alter_sys=True)
"""


def roller(*args, cwd=REPO, timeout=30.0, light=False):
    """(exit code, stdout, stderr) of ``python -m twodisk_ros.roller *args`` (``light``: with
    rclpy and numpy refused at import). ``timeout`` is a hang guard only."""
    start = ['-c', LIGHT] if light else ['-m', 'twodisk_ros.roller']
    try:
        result = subprocess.run([sys.executable, *start, *args], cwd=cwd,
                                env=node_env(), capture_output=True, text=True,
                                timeout=timeout, preexec_fn=limit_memory)
    except subprocess.TimeoutExpired as error:
        pytest.fail(f'roller {" ".join(args)} still running after {timeout} s: {error.stderr}')
    return result.returncode, result.stdout, result.stderr


def here(args, monkeypatch, capfd):
    """(exit code, stderr) of ``roller --ros-args *args`` refused through the entry function
    in this process (tests/roller_here.py), on this module's domain."""
    return run_roller_main(args, monkeypatch, capfd, domain=os.environ['ROS_DOMAIN_ID'])


#: A node that only reads its parameter overrides (rcl parses them from the context's
#: arguments in Node.__init__ whatever these flags): without the parameter services and
#: the /rosout publisher each costs about half as much
BARE = dict(start_parameter_services=False, enable_rosout=False)


def one_line(stderr):
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and 'Traceback' not in stderr, stderr[-3000:]
    assert lines[0].startswith('roller: '), stderr
    return lines[0]


# -- --help, --version, arguments outside --ros-args ----------------------------------------

@pytest.mark.parametrize('flag', ['--help', '-h'])
def test_help_prints_usage_and_exits_0_writing_nothing(flag, tmp_path):
    # rclpy and numpy refused: a run (the old code ran for ever) fails instead of answering
    code, out, err = roller(flag, cwd=tmp_path, timeout=10.0, light=True)
    assert code == 0 and err == '', err
    assert out.startswith('usage: roller')
    for words in ('--ros-args', '-p NAME:=VALUE', '--params-file', 'rate:=50.0',
                  'python -m twodisk_ros.run.parameters', 'README', 'examples:'):
        assert words in out, words
    assert list(tmp_path.iterdir()) == []


def test_version_prints_the_package_version(tmp_path):
    code, out, err = roller('--version', cwd=tmp_path, timeout=10.0, light=True)
    assert code == 0 and err == ''
    assert out.strip() == f'roller (twodisk_ros) {twodisk_ros.__version__}'


def test_help_imports_neither_rclpy_nor_numpy():
    code = ('import runpy, sys\n'
            "sys.argv = ['roller', '--ros-args', '-p', 'rate:=50.0', '--', '--help']\n"
            'try:\n'
            "    runpy.run_module('twodisk_ros.roller', run_name='__main__')\n"
            'except SystemExit as end:\n'
            '    status = end.code\n'
            "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('rclpy', 'numpy'))\n"
            "print(status, heavy, file=sys.stderr)\n")
    result = subprocess.run([sys.executable, '-c', code], env=node_env(), capture_output=True,
                            text=True, timeout=30)
    assert result.stderr.strip() == '0 []', result.stderr
    assert result.stdout.startswith('usage: roller')


@pytest.mark.parametrize('args, expected', [
    (['-p', 'duration:=1.0'],
     "roller: '-p duration:=1.0' is outside --ros-args: write roller --ros-args -p "
     'duration:=1.0'),
    (['--params-file', 'x.yaml', '--ros-args', '-p', 'rate:=50.0'],
     "roller: '--params-file x.yaml' is outside --ros-args: write roller --ros-args "
     '--params-file x.yaml -p rate:=50.0'),
    (['duration:=1.0'],
     "roller: 'duration:=1.0' is outside --ros-args: write roller --ros-args -p duration:=1.0"),
    (['stray'], "roller: unexpected argument 'stray'"),
    (['--ros-args', '-p', 'rate:=50.0', '--', 'stray'], "roller: unexpected argument 'stray'"),
])
def test_arguments_outside_ros_args_exit_2(args, expected, tmp_path):
    code, _, err = roller(*args, cwd=tmp_path, timeout=10.0, light=True)
    assert code == 2, err
    assert one_line(err).startswith(expected), err
    assert list(tmp_path.iterdir()) == []


def test_several_ros_args_sections_run(tmp_path):
    """launch appends its own ``--ros-args`` sections: every section counts, nothing is stray."""
    code, _, err = roller('--ros-args', '-r', '__node:=roller', '--params-file',
                             'config/oloid.yaml', '--', '--ros-args', *BATCH, timeout=60.0)
    assert code == 0 and 'Traceback' not in err, err


# -- declared types, repeated values, sections that apply -------------------------------------

@pytest.mark.parametrize('argument, expected', [
    ('path_length:=1.0', 'roller: -p path_length:=1.0: path_length is an integer: write 1, '
                         'not 1.0'),
    ('rate:=50', 'roller: -p rate:=50: rate is a double: write 50.0, not 50'),
    ('tolerance:=1', 'roller: -p tolerance:=1: tolerance is a double: write 1.0, not 1'),
    ('principal_moments:=[1, 2, 3]', 'principal_moments is a list of doubles: write '
                                     '[1.0, 2.0, 3.0], not [1, 2, 3]'),
    ('frame_id:=12', "frame_id is a string, got the integer 12: quote it to make it one: '12'"),
])
def test_type_mismatch_hint_quotes_the_value_and_the_declared_type(argument, expected,
                                                                   monkeypatch, capfd):
    """Through the entry function in this process (rate:=50 as a real process, refused by
    the same check, is in test_node_reliability.py)."""
    code, err = here(['-p', argument, *BATCH], monkeypatch, capfd)
    assert code == 2
    assert expected in one_line(err)


def test_type_mismatch_in_a_params_file_names_file_and_line(tmp_path, monkeypatch, capfd):
    params = tmp_path / 'p.yaml'
    params.write_text('/**:\n  ros__parameters:\n    a: 0.1\n    rate: 50\n')
    code, err = here(['--params-file', str(params), *BATCH], monkeypatch, capfd)
    assert code == 2
    assert one_line(err) == (f'roller: --params-file {params}, line 4: rate is a double: write '
                             '50.0, not 50 (a double needs a decimal point)')


def test_a_repeated_parameter_with_an_invalid_last_value_is_refused(monkeypatch, capfd):
    """rcl keeps 0.05 here and drops 'abc' silently (see test_rcl_keeps_a_value_of_another_type)."""
    code, err = here(['-p', 'duration:=0.05', '-p', 'duration:=abc', '-p', 'realtime:=false'],
                     monkeypatch, capfd)
    assert code == 2
    assert one_line(err) == "roller: -p duration:=abc: duration is a double, got the string 'abc'"


def test_rcl_keeps_a_value_of_another_type():
    """Why every value is type-checked: of two values of different types rcl keeps the double
    (``duration:=abc`` after ``duration:=0.05`` is dropped); of equal types, the last."""
    rclpy = pytest.importorskip('rclpy')
    from rclpy.node import Node
    for args, expected in ([['duration:=0.05', 'duration:=abc'], 0.05],
                           [['duration:=0.05', 'duration:=0.07'], 0.07]):
        context = rclpy.Context()
        rclpy.init(args=['x', '--ros-args', *[a for v in args for a in ('-p', v)]],
                   context=context)
        try:
            node = Node('roller', context=context, **BARE)
            assert node.declare_parameter('duration', 0.0).value == expected
            node.destroy_node()
        finally:
            rclpy.try_shutdown(context=context)


def test_a_params_file_for_other_nodes_says_nothing_was_applied(tmp_path, monkeypatch, capfd):
    """The run through the entry function in this process (the several sections above run
    as a real process)."""
    params = tmp_path / 'other.yaml'
    params.write_text('other:\n  ros__parameters:\n    rate: 50.0\n'
                      '/ns/roller:\n  ros__parameters:\n    rate: 50.0\n')
    code, err = here(['--params-file', str(params), *BATCH], monkeypatch, capfd)
    assert code == 0, err
    # the run logs its start and end lines at INFO; the warning is the only other line
    line = one_line('\n'.join(x for x in err.splitlines() if not x.startswith('[INFO]')))
    assert line.startswith(f'roller: warning: nothing from --params-file {params} was applied')
    assert "'other', '/ns/roller'" in line and "'/**'" in line and "'/roller'" in line
    # under the namespace /ns the second section applies: no warning
    assert check_arguments(['roller', '--ros-args', '-r', '__ns:=/ns', '--params-file',
                            str(params)]) == []


KEYS = ['/**', '**', '*', '/*', 'roller', '/roller', '/ns/roller', 'ns/roller', '/**/roller',
        '/*/roller', 'other', '/ns/*', '/ns/**', '/**/*', '/other/roller']


@pytest.mark.parametrize('namespace', ['/', '/ns'])
def test_section_keys_select_the_node_as_rclpy_does(namespace, tmp_path):
    rclpy = pytest.importorskip('rclpy')
    from rclpy.node import Node
    fqn = node_fqn(['-r', f'__ns:={namespace}'])
    assert fqn == ('/roller' if namespace == '/' else '/ns/roller')
    for key in KEYS:
        params = tmp_path / 'k.yaml'
        params.write_text(f'"{key}":\n  ros__parameters:\n    x: 1\n')
        context = rclpy.Context()
        rclpy.init(args=['x', '--ros-args', '--params-file', str(params)], context=context)
        try:
            node = Node('roller', namespace=namespace, context=context, **BARE)
            assert node_matches(key, fqn) == ('x' in node._parameter_overrides), key
            node.destroy_node()
        finally:
            rclpy.try_shutdown(context=context)


def test_rclpy_type_hint_quotes_the_value():
    message = ("Trying to set parameter 'path_length' to '1.0' of type 'DOUBLE', expecting "
               "type 'INTEGER': path_length")
    assert rclpy_type_hint(message) == ' (path_length is an integer: write 1, not 1.0)'
    message = ("Trying to set parameter 'rate' to '50' of type 'INTEGER', expecting type "
               "'DOUBLE': rate")
    assert rclpy_type_hint(message) == ' (rate is a double: write 50.0, not 50)'
    assert rclpy_type_hint('something else') == ''


# -- hostile parameter files, through the real entry point -----------------------------------

def _bomb(kind):
    """39 levels of aliased pairs: 2^39 leaves if expanded."""
    if kind == 'list':
        lines = ['a0: &a0 [0.1, 0.1]'] + [f'a{i}: &a{i} [*a{i - 1}, *a{i - 1}]'
                                           for i in range(1, 40)]
    else:
        lines = ['a0: &a0 {x: 0.1, y: 0.1}'] + [f'a{i}: &a{i} {{x: *a{i - 1}, y: *a{i - 1}}}'
                                                for i in range(1, 40)]
    return ('/**:\n  ros__parameters:\n' + ''.join(f'    {line}\n' for line in lines)).encode()


HOSTILE = {
    'self_alias': (b'/**: {ros__parameters: &r {a: 0.1, self: *r}}\n', 'aliases'),
    'deep_list': (b'/**:\n  ros__parameters:\n    a: ' + b'[' * 5000 + b']' * 5000 + b'\n',
                  'a list may hold only'),
    'deep_mapping': (b'/**:\n  ros__parameters:\n    a: ' + b'{a: ' * 5000 + b'1'
                     + b'}' * 5000 + b'\n', 'nested more than 32'),
    'binary': (bytes(range(256)) * 16, 'not UTF-8 text'),
    'list_bomb': (_bomb('list'), 'aliases'),
    'mapping_bomb': (_bomb('mapping'), 'aliases'),
    'entries_100k': (('/**: {ros__parameters: {' + ','.join(f'{i:x}: 1' for i in range(100_000))
                      + '}}\n').encode(), f'more than {MAX_ENTRIES} entries'),
    'over_1_MiB': (b'/**:\n  ros__parameters:\n    frame_id: "' + b'x' * (1 << 20) + b'"\n',
                   '1 MiB'),
}


#: Hostile files run as real processes (under the address-space limit); the others go
#: through the same entry function in this process (refused before rclpy.init: nothing built).
HOSTILE_PROCESSES = ('mapping_bomb', 'over_1_MiB')


@pytest.fixture(scope='module')
def hostile_runs(tmp_path_factory):
    """{name: (exit code, stderr)} of roller on the HOSTILE_PROCESSES files, side by side."""
    folder = tmp_path_factory.mktemp('hostile')
    runs = {}
    for name in HOSTILE_PROCESSES:
        path = folder / f'{name}.yaml'
        path.write_bytes(HOSTILE[name][0])
        runs[name] = subprocess.Popen(
            [sys.executable, '-m', 'twodisk_ros.roller', '--ros-args', '--params-file',
             str(path), *BATCH], cwd=folder, env=node_env(), stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True, preexec_fn=limit_memory)
    results = {}
    for name, process in runs.items():
        try:
            _, err = process.communicate(timeout=60.0)     # a hang guard
            results[name] = (process.returncode, err)
        except subprocess.TimeoutExpired:
            process.kill()
            _, err = process.communicate()
            results[name] = (None, err)
    return results


@pytest.mark.parametrize('name', list(HOSTILE))
def test_hostile_params_file_is_refused_in_one_line(hostile_runs, name, tmp_path, monkeypatch,
                                                    capfd):
    if name in HOSTILE_PROCESSES:
        code, err = hostile_runs[name]
    else:
        path = tmp_path / f'{name}.yaml'
        path.write_bytes(HOSTILE[name][0])
        code, err = here(['--params-file', path, *BATCH], monkeypatch, capfd)
    assert code == 2, (name, err[-3000:])
    assert HOSTILE[name][1] in one_line(err)


def test_many_unknown_names_are_summarised(tmp_path, monkeypatch):
    """Bounded work: close matches are looked up only for the 5 names shown, not 9000."""
    params = tmp_path / 'unknown.yaml'
    params.write_text('/**:\n  ros__parameters:\n'
                      + ''.join(f'    unknown_{i}: 1.0\n' for i in range(9000)))
    looked_up = []
    close_matches = difflib.get_close_matches

    def counted(word, *args, **kwargs):
        looked_up.append(word)
        return close_matches(word, *args, **kwargs)
    monkeypatch.setattr(difflib, 'get_close_matches', counted)
    warnings = check_arguments(['roller', '--ros-args', '--params-file', str(params)])
    assert looked_up == [f'unknown_{i}' for i in range(5)]
    assert len(warnings) == 6
    assert warnings[-1] == 'and 8995 more unknown parameter names are ignored'


def test_loader_limits_in_process(tmp_path):
    """Each refusal is immediate (no expansion, no recursion) and names the file: the memory
    it takes stays within a few times the file's size (an expanded alias bomb would take
    gigabytes; 0.83 MB of entries_100k peaked at 3.4 MB, the small files at 1.05 MB)."""
    for name, (data, words) in HOSTILE.items():
        path = tmp_path / f'{name}.yaml'
        path.write_bytes(data)
        tracemalloc.start()
        try:
            with pytest.raises(ArgumentError) as error:
                params_file_values(path)
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert peak < 8 * len(data) + (4 << 20), (name, peak)
        assert words in str(error.value) and str(path) in str(error.value)
        assert '\n' not in str(error.value)


# -- the loader's typing is rcl's ------------------------------------------------------------

PIECES = ['0', '1', '7', '9', '10', '.', 'e', 'E', '+', '-', 'x', 'X', 'a', 'f', 'p', '_',
          'inf', 'Inf', 'nan', 'NaN', '.inf', '.nan', 'y', 'n', 'yes', 'on', 'off', 'True',
          'null', '~', 'e308', 'e-320', '999999999999999999999', '(1)', ' ', '"', "'"]
SCALARS = st.one_of(
    st.lists(st.sampled_from(PIECES), min_size=1, max_size=5).map(''.join),
    st.floats(allow_nan=False).map(repr), st.integers().map(str),
    st.lists(st.sampled_from(['1', '1.5', '-2', '.5', 'abc', 'true', '0x1F', '1e3']),
             min_size=1, max_size=4).map(lambda xs: '[' + ', '.join(xs) + ']'))


@pytest.fixture(scope='module')
def rclpy_module():
    return pytest.importorskip('rclpy')


@settings(max_examples=200, deadline=2000, suppress_health_check=[
    HealthCheck.function_scoped_fixture])
@given(text=SCALARS)
def test_value_typing_is_rcls(rclpy_module, text):
    """``-p x:=TEXT``: the loader's value and type are those rclpy hands the node, or both
    refuse the text."""
    from rclpy.node import Node
    rclpy = rclpy_module
    context = rclpy.Context()
    try:
        rclpy.init(args=['x', '--ros-args', '-p', f'x:={text}'], context=context)
    except Exception:   # noqa: BLE001 - rcl refuses the value: so must the loader
        with pytest.raises(ArgumentError):
            parse_value(text, 'x', f'-p x:={text}')
        return
    try:
        node = Node('roller', context=context, **BARE)
        reference = node._parameter_overrides['x'].value
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    try:
        ours = parse_value(text, 'x', f'-p x:={text}').value
    except ArgumentError:
        assert isinstance(reference, (list, type(None))) or reference == [], reference
        return                  # stricter than rcl: nested or empty lists
    if isinstance(reference, float) and math.isnan(reference):
        assert isinstance(ours, float) and math.isnan(ours)
    else:
        assert type(ours) is type(reference) or isinstance(reference, list)
        assert ours == reference, (text, ours, reference)


# -- any file: values or one line, in bounded time ------------------------------------------

KEYS_TEXT = st.one_of(st.sampled_from(['a', 'rate', 'path_length', '/**', 'roller', '*',
                                       'ros__parameters', 'é', '日本', '"q: x"', '&a k', '*a']),
                      st.text(min_size=1, max_size=6))
LEAVES = st.one_of(SCALARS, st.sampled_from(['&a 1.0', '*a', '&b [1, *b]', '!!str 5', '|\n  x',
                                             '', '{}', '[]', '[[1]]']),
                   st.text(max_size=8))


def _yaml_text(tree, indent=0):
    if isinstance(tree, dict):
        return ''.join(f'\n{" " * indent}{key}:{_yaml_text(value, indent + 2)}'
                       for key, value in tree.items())
    return f' {tree}'


TREES = st.recursive(LEAVES, lambda inner: st.dictionaries(KEYS_TEXT, inner, max_size=4),
                     max_leaves=30)


@settings(max_examples=200, deadline=2000, suppress_health_check=[
    HealthCheck.function_scoped_fixture])
@given(tree=TREES, top=st.sampled_from(['/**', 'roller', '/ns/roller', 'other']),
       wrap=st.booleans())
def test_any_params_file_gives_values_or_one_line(tmp_path, tree, top, wrap):
    text = (f'{top}:\n  ros__parameters:{_yaml_text(tree, 4)}\n' if wrap
            else _yaml_text(tree).lstrip('\n') + '\n')
    path = tmp_path / 'fuzz.yaml'
    path.write_text(text, encoding='utf-8', errors='surrogatepass')
    try:
        values = params_file_values(path)
    except ArgumentError as error:
        assert '\n' not in str(error) and str(error).startswith(f'--params-file {path}')
        return
    assert isinstance(values, dict)
    assert len(values) <= MAX_ENTRIES
    for value in values.values():
        assert isinstance(value, (bool, int, float, str, list))


def test_bounds_are_shared_over_every_file_and_override(tmp_path):
    params = tmp_path / 'half.yaml'
    params.write_text('/**:\n  ros__parameters:\n'
                      + ''.join(f'    u{i}: 1.0\n' for i in range(MAX_ENTRIES // 2)))
    # the keys, plus the document, '/**' and 'ros__parameters'
    assert load_params_file(params).entries == MAX_ENTRIES // 2 + 3
    with pytest.raises(ArgumentError, match='in all -p and --params-file arguments'):
        check_arguments(['roller', '--ros-args', '--params-file', str(params),
                         '--params-file', str(params)])

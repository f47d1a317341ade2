"""The figures (plotting/figures.py, contact_forces.py, sweep_maps.py): files written, plotted
data against closed forms, and the figure commands (help, --overwrite)."""

import math
import os
import struct
import subprocess
import sys
import time

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from numpy.testing import assert_allclose  # noqa: E402

from rounding import ulps  # noqa: E402
from twodisk_ros.plotting import figures  # noqa: E402
from twodisk_ros.physics.bodies.ellipse import EllipseBody  # noqa: E402

EXPECTED = ['figure3.png', 'figure4.png', 'oloid_traces.png', 'height.png', 'stability_map.png',
            'laminae_traces.png']
PNG_SIGNATURE = b'\x89PNG\r\n\x1a\n'


def _png_size(path):
    """(width, height) in pixels from the IHDR chunk."""
    with open(path, 'rb') as handle:
        head = handle.read(24)
    assert head[:8] == PNG_SIGNATURE and head[12:16] == b'IHDR'
    return struct.unpack('>II', head[16:24])


def _line(ax, gid):
    lines = [line for line in ax.get_lines() if line.get_gid() == gid]
    assert len(lines) == 1, gid
    return lines[0]


def test_main_overwrites_writes_and_lists(tmp_path, capsys):
    """``twodisk-figures --out DIR --overwrite`` over an older figure: every figure written
    (write_figures, a PNG of a sensible size), listed on stdout in order, the old one replaced.
    One run for the three claims: drawing the figures is what costs (~4 s)."""
    old = tmp_path / 'height.png'
    old.write_bytes(b'an older figure')
    assert figures.main(['--out', str(tmp_path), '--overwrite']) == 0
    printed = capsys.readouterr().out.split()
    assert [p.rsplit('/', 1)[-1] for p in printed] == EXPECTED
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(figures.NAMES) == sorted(EXPECTED)
    assert old.read_bytes()[:8] == PNG_SIGNATURE
    for name in EXPECTED:
        path = tmp_path / name
        width, height = _png_size(path)
        assert 600 <= width <= 3000 and 300 <= height <= 2000, (path.name, width, height)
        assert path.stat().st_size > 20_000, path.name


def test_lamina_outline_is_the_superellipse():
    """The drawn outline of the rounded square lies on |x/b|^4 + |y/a|^4 = 1 (its definition)."""
    title, lamina, *_ = figures.lamina_bodies()[0]
    fig, ax = plt.subplots()
    try:
        figures.plot_outline(lamina, ax)
        x, y = _line(ax, 'outline').get_data()
        assert_allclose(np.abs(x / 0.1) ** 4 + np.abs(y / 0.1) ** 4, 1.0, rtol=1e-13)
        # the whole rim: the outline reaches all four extents
        assert_allclose([x.max(), -x.min(), y.max(), -y.min()], 0.1, rtol=1e-12)
    finally:
        plt.close(fig)


def test_oloid_trace_data():
    """The plotted trace of A ends 2 cycles × 8√3π/9 m along X (elementary oloid trace)."""
    fig, ax = plt.subplots()
    try:
        figures.plot_traces(EllipseBody.oloid(), 2, ax)
        x, y = _line(ax, 'trace A').get_data()
        # A at the origin at u = 0, to the tables' rounding (16 ulps of the size)
        assert_allclose([x[0], y[0]], [0.0, 0.0], atol=ulps(16, EllipseBody.oloid().size))
        assert_allclose([x[-1], y[-1]], [2 * 8 * math.sqrt(3) * math.pi / 9, 0.0], atol=1e-12)
        assert y.min() >= -1e-12
        # the trace of B stays above the trace of A, as in the paper's figures
        _, y_b = _line(ax, 'trace B').get_data()
        assert y_b.min() > y.max() - 1e-9
        assert ax.get_xlabel() == 'X (m)' and ax.get_ylabel() == 'Y (m)'
        assert ax.get_legend() is not None
    finally:
        plt.close(fig)


def test_height_data():
    """TCR at b/√2 throughout; oloid between 1/√2 and 3/4 (Mg = 1: z_G in m)."""
    fig, ax = plt.subplots()
    try:
        figures.plot_height([('Oloid', EllipseBody.oloid()),
                             ('TCR', EllipseBody.two_circle_roller(2.0))], ax)
        _, tcr = _line(ax, 'height TCR').get_data()
        assert_allclose(tcr, 2.0 / math.sqrt(2.0), rtol=0, atol=1e-12)
        u, oloid = _line(ax, 'height Oloid').get_data()
        assert_allclose([u[0], u[-1]], [0.0, 2 * math.pi])
        assert_allclose([oloid.min(), oloid.max()], [1 / math.sqrt(2), 0.75], atol=1e-5)
        # the equilibria are drawn: 8 per body
        markers = [line for line in ax.get_lines() if line.get_gid() is None
                   and len(line.get_xdata()) == 1]
        assert len(markers) == 16
    finally:
        plt.close(fig)


def test_stability_map_neutral_curve():
    fig, ax = plt.subplots()
    try:
        figures.plot_stability_map(ax, resolution=50)
        b, d = _line(ax, 'neutral curve').get_data()
        assert_allclose(d**2 + b**2 / 2, 1.0, atol=1e-12)
        assert ax.get_xlim() == (0.05, 3.0) and ax.get_ylim() == (0.0, 1.0)
    finally:
        plt.close(fig)


def test_core_does_not_import_matplotlib():
    code = ('import sys; import twodisk_ros.physics; '
            'import twodisk_ros.physics.numerics.tables; print("matplotlib" in sys.modules)')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == 'False'


def test_plot_functions_return_their_axes():
    fig, axes = plt.subplots(1, 3)
    try:
        body = EllipseBody(*figures.FIGURE4)
        assert figures.plot_traces(body, 1, axes[0], samples_per_cycle=200) is axes[0]
        assert figures.plot_height([('Fig. 4', body)], axes[1], samples=101) is axes[1]
        assert figures.plot_stability_map(axes[2], resolution=20) is axes[2]
        assert np.isfinite(_line(axes[1], 'height Fig. 4').get_ydata()).all()
    finally:
        plt.close(fig)


def test_contact_force_figures_are_written(tmp_path, capsys):
    from twodisk_ros.plotting import contact_forces
    assert contact_forces.main(['--out', str(tmp_path)]) == 0
    for name in ('contact_forces_cycle.png', 'contact_forces_speed.png'):
        assert (tmp_path / name).stat().st_size > 20_000
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(contact_forces.NAMES)


def test_coinciding_liftoff_speeds_are_named_together():
    """The oloid (8.2810) and the Fig. 3 body (8.2796 rad/s) share one dotted line: said."""
    from twodisk_ros.physics.forces.validity import liftoff_speed
    from twodisk_ros.plotting import contact_forces
    criticals = [liftoff_speed(contact_forces.force_model(shape))[0]
                 for _, shape in contact_forces.BODIES]
    assert abs(criticals[0] - criticals[2]) < 0.005 * criticals[0]      # the claim
    assert contact_forces.coinciding_speeds(criticals) == [[2, 0]]


# -- the command lines: help without side effects, existing outputs refused ---------------
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIGURE_COMMANDS = ('twodisk_ros.plotting.figures', 'twodisk_ros.plotting.contact_forces')


#: Runs ``python -m MODULE ARGS`` with matplotlib's import refused (as tests/test_cli_outputs.py).
NO_MATPLOTLIB = '''
import runpy, sys
class _Refuse:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] == 'matplotlib':
            raise ImportError(name + ' refused: nothing may be drawn')
sys.meta_path.insert(0, _Refuse())
sys.argv = [{module!r}, *sys.argv[1:]]
runpy.run_module({module!r}, run_name='__main__', alter_sys=True)
'''


def _run(module, args, cwd, timeout=60, matplotlib=True):
    """Run the command; without ``matplotlib`` its import is refused (bounded work: nothing
    can be drawn). ``timeout`` only guards against a hang."""
    env = dict(os.environ, PYTHONPATH=REPO, MPLBACKEND='Agg')
    command = [sys.executable, '-m', module] if matplotlib else [
        sys.executable, '-c', NO_MATPLOTLIB.format(module=module)]
    done = subprocess.run([*command, *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)
    return done, None


@pytest.mark.parametrize('module', FIGURE_COMMANDS)
@pytest.mark.parametrize('flag', ['--help', '-h'])
def test_help_exits_0_quickly_and_writes_nothing(tmp_path, module, flag):
    # matplotlib refused: help answers before anything is drawn (and at once for a user)
    done, _ = _run(module, [flag], tmp_path, timeout=60, matplotlib=False)
    assert done.returncode == 0 and 'usage:' in done.stdout and '--overwrite' in done.stdout
    assert 'Traceback' not in done.stderr and 'refused' not in done.stderr, done.stderr
    assert list(tmp_path.iterdir()) == []   # before: a folder named --help


@pytest.mark.parametrize('module', FIGURE_COMMANDS)
def test_existing_figure_refused_without_overwrite(tmp_path, module):
    names = figures.NAMES if module.endswith('figures') else ('contact_forces_cycle.png',
                                                              'contact_forces_speed.png')
    old = tmp_path / names[-1]
    old.write_bytes(b'an older figure')
    # refused before anything is drawn: matplotlib is not even imported
    done, _ = _run(module, ['--out', str(tmp_path)], tmp_path, matplotlib=False)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and 'exists' in lines[0] and '--overwrite' in lines[0]
    assert 'Traceback' not in done.stderr
    assert old.read_bytes() == b'an older figure'
    assert sorted(p.name for p in tmp_path.iterdir()) == [old.name]    # nothing else written


# -- the sweep maps -----------------------------------------------------------------------
def _sweep(b_over_a, delta_over_a):
    import xarray as xr
    from twodisk_ros.physics.stability.equilibria import stability_map
    b, d = np.meshgrid(b_over_a, delta_over_a, indexing='ij')
    return xr.Dataset({
        'stable_family': (('b_over_a', 'delta_over_a'), stability_map(b, d).astype(float),
                          {'units': '1', 'description': 'which equilibria are stable: +1 '
                           'theta = 0 and the turning points, -1 theta = +-pi/2, 0 neutral'}),
        'rollover_speed': (('b_over_a', 'delta_over_a'), 1.0 + b * d,
                           {'units': 'sqrt(g/a)', 'description': 'angular speed |omega| '
                            'with omega_u, 1/2 m du/dt^2, Delta/a <= 1'}),
    }, coords={'b_over_a': b_over_a, 'delta_over_a': delta_over_a})


def test_sweep_map_cells_stay_on_the_grid():
    """No cell is drawn beyond the grid's first and last values (Δ/a outside [0.02, 0.98])."""
    from twodisk_ros.plotting.sweep_maps import plot_map
    b, d = np.linspace(0.2, 3.0, 12), np.linspace(0.02, 0.98, 10)
    for name in ('stable_family', 'rollover_speed'):
        fig, ax = plt.subplots()
        try:
            plot_map(_sweep(b, d), name, ax)
            for mesh in [c for c in ax.collections if hasattr(c, 'get_coordinates')]:
                xy = mesh.get_coordinates()
                assert xy[..., 0].min() == pytest.approx(0.2)
                assert xy[..., 0].max() == pytest.approx(3.0)
                assert xy[..., 1].min() == pytest.approx(0.02)
                assert xy[..., 1].max() == pytest.approx(0.98)
            assert ax.get_ylim() == pytest.approx((0.02, 0.98))
        finally:
            plt.close(fig)


def test_sweep_map_titles_and_bars_use_symbols():
    from twodisk_ros.plotting.sweep_maps import plot_map, symbols
    assert symbols('theta = +-pi/2, Delta/a <= 1, sqrt(g/a), a^2, theta_max') == (
        'θ = ±π/2, Δ/a ≤ 1, √(g/a), a², theta_max')
    b, d = np.linspace(0.2, 3.0, 4), np.linspace(0.02, 0.98, 3)
    for name in ('stable_family', 'rollover_speed'):
        fig, ax = plt.subplots()
        try:
            bar = plot_map(_sweep(b, d), name, ax)
            texts = [ax.get_title(), bar.ax.get_ylabel()] + [
                t.get_text() for t in bar.ax.get_yticklabels()]
            for text in texts:
                for ascii_word in ('theta ', '+-pi', 'pi/2', 'Delta', 'sqrt', '^2', 'omega'):
                    assert ascii_word not in text, (name, text)
        finally:
            plt.close(fig)

"""Tests of :mod:`twodisk_ros.plotting.figures`: files written, and plotted data against closed forms."""

import math
import struct
import subprocess
import sys

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from numpy.testing import assert_allclose  # noqa: E402

from twodisk_ros.plotting import figures  # noqa: E402
from twodisk_ros.physics.body import TwoDiskBody  # noqa: E402

EXPECTED = ['figure3.png', 'figure4.png', 'oloid_traces.png', 'height.png', 'stability_map.png']
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


def test_write_figures(tmp_path):
    written = figures.write_figures(tmp_path / 'out')
    assert [p.name for p in written] == EXPECTED
    for path in written:
        assert path.is_file()
        width, height = _png_size(path)
        assert 600 <= width <= 3000 and 300 <= height <= 2000, (path.name, width, height)
        assert path.stat().st_size > 20_000, path.name


def test_main_writes_and_lists(tmp_path, capsys):
    assert figures.main(['--out', str(tmp_path)]) == 0
    printed = capsys.readouterr().out.split()
    assert [p.rsplit('/', 1)[-1] for p in printed] == EXPECTED


def test_oloid_trace_data():
    """The plotted trace of A ends 2 cycles × 8√3π/9 m along X (elementary oloid trace)."""
    fig, ax = plt.subplots()
    try:
        figures.plot_traces(TwoDiskBody.oloid(), 2, ax)
        x, y = _line(ax, 'trace A').get_data()
        assert_allclose([x[0], y[0]], [0.0, 0.0], atol=1e-15)
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
        figures.plot_height([('Oloid', TwoDiskBody.oloid()),
                             ('TCR', TwoDiskBody.two_circle_roller(2.0))], ax)
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
            'import twodisk_ros.physics.tables; print("matplotlib" in sys.modules)')
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == 'False'


def test_plot_functions_return_their_axes():
    fig, axes = plt.subplots(1, 3)
    try:
        body = TwoDiskBody(*figures.FIGURE4)
        assert figures.plot_traces(body, 1, axes[0], samples_per_cycle=200) is axes[0]
        assert figures.plot_height([('Fig. 4', body)], axes[1], samples=101) is axes[1]
        assert figures.plot_stability_map(axes[2], resolution=20) is axes[2]
        assert np.isfinite(_line(axes[1], 'height Fig. 4').get_ydata()).all()
    finally:
        plt.close(fig)


def test_contact_force_figures_are_written(tmp_path):
    from twodisk_ros.plotting import contact_forces
    contact_forces.main(str(tmp_path))
    for name in ('contact_forces_cycle.png', 'contact_forces_speed.png'):
        assert (tmp_path / name).stat().st_size > 20_000

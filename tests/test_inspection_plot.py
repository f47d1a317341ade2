"""The figure of ``twodisk-inspect --plot`` (inspect/figure.py) shows what it says.

Recordings are made by the real node in batch mode (1 s, 100 Hz; in this process, domain
14): the Two-Circle-Roller (constant height of G), the oloid driven at constant |ω|
(kinematic), and the oloid thrown at ω0 = 9 rad/s, which lifts off and slips. The references
are recomputed here from the recorded rolling_state with the physics (E(u, u̇), |ω_u(u)|) and
from the recorded wrenches.
"""

import os

import numpy as np
import pytest

from batch_recording import record
from twodisk_ros.inspector import inspect_recording
from twodisk_ros.recordings.reader import read_recording
from twodisk_ros.run.parameters import parse_recorded
from twodisk_ros.physics.bodies.ellipse import EllipseBody
from twodisk_ros.physics.motion.dynamics import RollingDynamics
from twodisk_ros.model import palette
from twodisk_ros.inspector.figure import align_zeros, inspection_figure, plot_inspection

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RUNS = {
    'tcr': (os.path.join(REPO, 'config', 'two_circle_roller.yaml'), {}),
    'kinematic': (os.path.join(REPO, 'config', 'oloid.yaml'),
                  {'mode': 'kinematic', 'omega0': 5.0}),
    'liftoff': (os.path.join(REPO, 'config', 'oloid.yaml'), {'omega0': 9.0}),
}


@pytest.fixture(scope='module')
def recordings(tmp_path_factory):
    folder = tmp_path_factory.mktemp('runs')
    return {name: str(record(folder / f'{name}.mcap', params_file, domain=14, duration=1.0,
                             **values))
            for name, (params_file, values) in RUNS.items()}


@pytest.fixture(scope='module')
def figures(recordings):
    out = {}
    for name, path in recordings.items():
        inspection = inspect_recording(path)
        figure = inspection_figure(inspection)
        figure.canvas.draw()
        out[name] = (inspection, figure)
    return out


def axes_named(figure, name):
    return next(ax for ax in figure.axes if ax.get_label() == name)


def recorded_state(path):
    """(settings, u, u̇) of the recorded rolling_state, in stamp order."""
    recording = read_recording(path)
    settings, _ = parse_recorded(recording.metadata['twodisk_ros'])
    rows = sorted((m.log_time_ns, m.msg) for m in recording.messages
                  if m.topic.endswith('rolling_state'))
    phase = np.unwrap([float(msg.position[2]) for _, msg in rows])
    rate = np.array([float(msg.velocity[2]) for _, msg in rows])
    return settings, phase, rate


def zero_height(axes):
    low, high = axes.get_ylim()
    return -low / (high - low)


def test_drift_panel_shows_the_recorded_energy_drift_not_the_fd_error(recordings, figures):
    inspection, figure = figures['tcr']
    settings, phase, rate = recorded_state(recordings['tcr'])
    dynamics = RollingDynamics(EllipseBody(settings.a, settings.b, settings.delta),
                               settings.ellipse_mass_properties(), settings.gravity)
    energy = dynamics.energy(phase, rate)
    reference = np.max(np.abs(energy - energy[0])) / dynamics.energy_scale
    drift = axes_named(figure, 'drift')
    shown = max(float(np.nanmax(np.abs(line.get_ydata()))) for line in drift.lines)
    # the table method keeps E to round-off (~1e-15); the FD check of the poses sees ~1e-8,
    # which the old panel drew as the "drift": the largest curve shown is the recorded drift
    assert reference < 1e-12
    assert shown == pytest.approx(reference, rel=1e-6, abs=1e-16)
    check = next(c for c in inspection.checks if c.name == 'energy')
    assert f'{check.value:.2g}' in drift.get_legend().get_title().get_text()


def test_kinematic_drift_panel_shows_the_drift_of_omega(recordings, figures):
    _, figure = figures['kinematic']
    settings, phase, rate = recorded_state(recordings['kinematic'])
    body = EllipseBody(settings.a, settings.b, settings.delta)
    speed = np.abs(rate) * np.linalg.norm(body.phase_angular_velocity(phase), axis=-1)
    reference = np.max(np.abs(speed - 5.0)) / 5.0
    drift = axes_named(figure, 'drift')
    assert '|ω|' in drift.get_title() and 'energy' not in drift.get_title()
    (line,) = drift.lines
    # the energy varies by ~2 % of M g L here (the drive does work): not what is shown
    assert float(np.max(np.abs(line.get_ydata()))) == pytest.approx(reference, rel=1e-6,
                                                                     abs=1e-16)
    assert reference < 1e-10


def test_force_axes_share_their_zero(figures):
    for name in ('tcr', 'liftoff'):
        _, figure = figures[name]
        forces, mu = axes_named(figure, 'forces'), axes_named(figure, 'mu')
        assert zero_height(forces) == pytest.approx(zero_height(mu), abs=1e-12)
        # every plotted μ_required at or above the zero line: none appears negative
        assert mu.get_ylim()[0] <= 0.0


def test_align_zeros_keeps_both_ranges():
    from matplotlib.figure import Figure
    ax = Figure().subplots()
    twin = ax.twinx()
    ax.set_ylim(-0.2, 0.8)
    twin.set_ylim(0.0, 1.5)
    assert align_zeros(ax, twin) == pytest.approx(0.2)
    assert ax.get_ylim() == pytest.approx((-0.2, 0.8))
    assert twin.get_ylim() == pytest.approx((-0.375, 1.5))


def test_no_additive_tick_offset_and_legend_clear_of_the_title(figures):
    _, figure = figures['tcr']
    for axes in figure.axes:
        # '1e-13+7.071067812e-2' above the constant height of the TCR, before
        assert '+' not in axes.yaxis.get_offset_text().get_text()
    ground = axes_named(figure, 'ground')
    renderer = figure.canvas.get_renderer()
    legend = ground.get_legend().get_window_extent(renderer)
    title = ground.title.get_window_extent(renderer)
    assert not legend.overlaps(title)


def test_liftoff_and_slip_are_shaded_and_clipping_is_said(figures):
    inspection, figure = figures['liftoff']
    data = inspection.series
    forces = axes_named(figure, 'forces')
    lift = (data['normal_a'] < 0) | (data['normal_b'] < 0)
    assert lift.any()
    spans = [(p.get_x(), p.get_x() + p.get_width(), p.get_facecolor()) for p in forces.patches]
    colours = {p[2][:3] for p in spans}
    assert len(colours) == 2     # lift-off and slip
    for t in data['t_forces'][lift]:
        assert any(x0 <= t <= x1 for x0, x1, _ in spans)
    for t in data['t_forces'][~lift & (data['mu_required'] <= 0.5)]:
        assert not any(x0 <= t <= x1 for x0, x1, _ in spans)
    mu = axes_named(figure, 'mu')
    peak = float(np.max(data['mu_required'][np.isfinite(data['mu_required'])]))
    (need,) = [line for line in mu.lines if line.get_label().startswith('μ_required')]
    assert peak > mu.get_ylim()[1] and 'clipped' in need.get_label()


def test_traces_take_the_palette(figures, tmp_path):
    inspection, figure = figures['tcr']
    ground = axes_named(figure, 'ground')
    colours = {line.get_label(): line.get_color() for line in ground.lines}
    assert colours['trace of A'] == palette.A and colours['trace of B'] == palette.B
    png = tmp_path / 'x.png'
    plot_inspection(inspection, png)
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'


def test_drift_scale_is_in_the_label_not_above_the_axis(figures):
    """The drift (~1e-15) was labelled by matplotlib's '1e-15' above the axis, which ran into
    the panel's title on the Two-Circle-Roller; the power of ten is now in the y label and
    each tick label times it is the tick's value."""
    for name in ('tcr', 'kinematic'):
        _, figure = figures[name]
        drift = axes_named(figure, 'drift')
        assert drift.yaxis.get_offset_text().get_text() == ''
        label = drift.get_ylabel()
        exponent = int(label.split('×10$^{')[1].split('}$')[0])
        assert -17 <= exponent <= -9      # round-off drifts, as the tests above show
        for tick in drift.yaxis.get_major_ticks():
            text = tick.label1.get_text().replace('\u2212', '-')
            if text and drift.get_ylim()[0] <= tick.get_loc() <= drift.get_ylim()[1]:
                # the label is the tick's value / 10**exponent, to its 6 printed digits
                assert float(text) * 10.0 ** exponent == pytest.approx(tick.get_loc(),
                                                                       rel=1e-5, abs=1e-30)

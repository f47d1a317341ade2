"""``twodisk-animate``: GIFs from the library and from a recording, and its input errors.

The recording is the roller node's batch run, made in this process (domain 94 unless
ROS_DOMAIN_ID is set). The command runs as a process of its own for a GIF of the recording;
the refusals call its ``main`` in this process (test_cli_outputs refuses bad requests to the
command's own process).
"""

import os
from pathlib import Path
import shutil
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image, ImageChops

from batch_recording import record
from twodisk_ros.plotting import animation
from twodisk_ros.runs import RunError, library_run, recorded_run, settings_from

REPO = Path(__file__).resolve().parents[1]
ENV = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
           ROS_DOMAIN_ID=os.environ.get('ROS_DOMAIN_ID', '94'), MPLBACKEND='Agg')
SIZE = (160, 120)


def _frames(path):
    """The frames of a GIF as RGB images."""
    with Image.open(path) as image:
        frames = []
        for k in range(image.n_frames):
            image.seek(k)
            frames.append(image.convert('RGB'))
    return frames


def _check_gif(path, count):
    frames = _frames(path)
    assert len(frames) == count
    assert frames[0].size == SIZE
    for first, second in zip(frames, frames[1:]):
        assert ImageChops.difference(first, second).getbbox() is not None


@pytest.fixture(scope='module')
def recording(tmp_path_factory):
    return record(tmp_path_factory.mktemp('anim') / 'run.mcap',
                  domain=int(ENV['ROS_DOMAIN_ID']), duration=1.0)


def test_frame_times():
    assert np.allclose(animation.frame_times(0.0, 0.5, 8), np.arange(5) / 8)
    assert len(animation.frame_times(1.0, 1.05, 10)) == 1


@pytest.mark.parametrize('view', ['3d', 'top'])
def test_library_gif(tmp_path, view):
    settings = settings_from(REPO / 'config' / 'oloid.yaml')
    run = library_run(settings, stop=0.6, forces=True)
    assert run.force_a.shape == run.contact_a.shape
    # the normal forces carry the weight on average (gravity only: no drive)
    assert 0.5 < np.mean(run.force_a[:, 2] + run.force_b[:, 2]) / run.weight < 1.5
    out = tmp_path / f'{view}.gif'
    count = animation.animate(run, out, start=0.1, stop=0.5, fps=10, view=view, size=SIZE,
                              forces=True)
    assert count == 5
    _check_gif(out, 5)
    # The frames (one palette for the whole GIF, frames.one_palette) are the frames
    # matplotlib drew but for the rounding of each colour to the palette: 99.9 % of the
    # pixels within 24 of 255 levels in every channel, a mean difference under 4 levels
    # (measured, the largest over the frames: here 11 and 3.0 (top), 10 and 1.3 (3d); make
    # demo's 480 × 360 oloid 9 and 1.1; Pillow's palette made for each frame 25-34 and 0.1-
    # 0.3). Frames other than the three the palette is made from (the traces grown, the
    # body turned) are held to the same bound.
    shown = run.span(0.1, 0.5)
    frames = np.clip(np.searchsorted(shown.t, animation.frame_times(0.1, 0.5, 10) - 1e-9),
                     0, len(shown) - 1)
    scene = animation._Scene(shown, animation._figure(SIZE), view, 'auto', True, frames)
    for frame, written in enumerate(_frames(out)):
        scene.draw(frame)
        drawn = np.array(animation._render(scene)).reshape(SIZE[1], SIZE[0], 4)[..., :3]
        difference = np.abs(np.asarray(written, dtype=int) - drawn).max(axis=2)
        assert np.percentile(difference, 99.9) <= 24, (frame, np.percentile(difference, 99.9))
        assert difference.mean() < 4.0, (frame, difference.mean())


def test_settings_are_simulated(tmp_path):
    out = tmp_path / 'settings.gif'
    assert animation.animate(settings_from(mode='kinematic', omega0=4.0), out, stop=0.3,
                             fps=10, size=SIZE, camera='follow') == 4
    _check_gif(out, 4)


def test_recording_gif_cli(recording, tmp_path):
    run = recorded_run(recording)
    assert len(run) >= 100 and run.t[0] == 0.0
    assert np.allclose(run.contact_a[:, 2], 0.0, atol=1e-12)
    out = tmp_path / 'rec.gif'
    result = subprocess.run(
        [sys.executable, '-m', 'twodisk_ros.plotting.animate_cli', str(recording), '-o',
         str(out), '--stop', '0.9', '--fps', '5', '--size', '160x120', '--view', 'top'],
        cwd=REPO, capture_output=True, text=True, timeout=120, env=ENV)
    assert result.returncode == 0, result.stderr
    assert 'rec.gif: 5 frames' in result.stdout
    _check_gif(out, 5)


def _cli(*args):
    return subprocess.run([sys.executable, '-m', 'twodisk_ros.plotting.animate_cli', *args],
                          cwd=REPO, capture_output=True, text=True, timeout=120, env=ENV)


def _assert_one_line(status, stderr, words, folder):
    assert status == 2, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], stderr
    assert not (folder / 'x.gif').exists()


@pytest.mark.parametrize('args, words', [
    (['/nonexistent/run.mcap', '-o', 'x.gif'], 'cannot read'),
    (['--params-file', '/nonexistent.yaml', '-o', 'x.gif'],
     '--params-file /nonexistent.yaml: cannot read it'),
    (['-o', 'x.gif', '--start', '3', '--stop', '2'], 'start < stop'),
    (['-o', 'x.gif', '--stop', '-1'], 'start < stop'),
    (['-o', '/nonexistent/dir/x.gif', '--stop', '0.2'], 'does not exist'),
    (['-o', 'x.jpg', '--stop', '0.2'], '.gif, .png (one still) or .mp4'),
    (['-o', 'x.gif', '--size', 'big'], 'WIDTHxHEIGHT'),
    (['-o', 'x.gif', '--delta', '0.5'], 'delta/a'),
    (['-o', 'x.gif', '--fps', '0'], 'fps'),
])
def test_bad_input_one_line_exit_2(tmp_path, monkeypatch, capsys, args, words):
    """``main`` in this process, in a fresh working directory: one line, exit 2, nothing
    written."""
    from twodisk_ros.plotting.animate_cli import main
    monkeypatch.chdir(tmp_path)
    status = main(list(args))
    out, err = capsys.readouterr()
    _assert_one_line(status, err, words, tmp_path)
    assert out == ''


def test_recording_span_past_its_end(recording, tmp_path):
    with pytest.raises(RunError, match='run ends'):
        animation.animate(recorded_run(recording), tmp_path / 'x.gif', stop=5.0, size=SIZE)


@pytest.mark.skipif(shutil.which('ffmpeg') is None, reason='ffmpeg is not installed')
def test_mp4(tmp_path):
    out = tmp_path / 'run.mp4'
    assert animation.animate(library_run(stop=0.3), out, fps=10, size=SIZE) == 4
    assert out.stat().st_size > 1000


@pytest.mark.skipif(shutil.which('ffmpeg') is not None, reason='ffmpeg is installed')
def test_mp4_without_ffmpeg(tmp_path):
    with pytest.raises(RunError, match='ffmpeg'):
        animation.animate(library_run(stop=0.3), tmp_path / 'run.mp4', size=SIZE)


@pytest.mark.parametrize('view', ['3d', 'top'])
def test_legend_readable_at_the_demo_size(view):
    """At 480 × 360 (make demo) the legend's letters are at least 9 px high, it has at most
    5 entries and lies inside the picture, below the view; its colours are the palette's."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from twodisk_ros.model import palette
    run = library_run(settings_from(REPO / 'config' / 'oloid.yaml'), stop=0.2, forces=True)
    figure = Figure(figsize=(4.8, 3.6), dpi=animation.DPI)
    FigureCanvasAgg(figure)
    scene = animation._Scene(run, figure, view, 'fit', True, np.array([0]))
    scene.draw(0)
    figure.canvas.draw()
    (legend,) = figure.legends
    texts = legend.get_texts()
    assert len(texts) <= 5
    for text in texts:
        assert text.get_fontsize() * figure.dpi / 72.0 >= 9.0, text.get_text()
    box = legend.get_window_extent(figure.canvas.get_renderer())
    assert box.x0 >= 0 and box.x1 <= 480 and box.y0 >= 0
    assert scene.trace_a.get_color() == palette.A and scene.trace_b.get_color() == palette.B
    assert scene.segment.get_color() == palette.AB


def test_runs_moved_out_of_plotting_and_the_old_import_still_works():
    # runs are loaded and simulated in twodisk_ros.runs (nothing there plots); the old
    # module re-exports the same objects, and the library module has no command line
    import twodisk_ros.plotting.runs as old
    import twodisk_ros.runs as new
    for name in old.__all__:
        assert getattr(old, name) is getattr(new, name), name
    assert not hasattr(animation, 'main')


def _full_redraw(figure):
    """The frame as matplotlib's PillowWriter grabbed it: a full ``savefig`` (RGBA)."""
    import io
    buffer = io.BytesIO()
    figure.savefig(buffer, format='rgba', dpi=animation.DPI, facecolor='white')
    width, height = figure.canvas.get_width_height()
    return np.frombuffer(buffer.getvalue(), np.uint8).reshape(height, width, 4)


@pytest.mark.parametrize('config, view, camera', [
    ('oloid.yaml', '3d', 'fit'), ('oloid.yaml', 'top', 'fit'), ('slope.yaml', '3d', 'fit'),
    ('slope.yaml', 'top', 'follow'), ('oloid.yaml', '3d', 'follow')])
def test_frames_are_the_pictures_of_a_full_redraw(config, view, camera):
    """A GIF frame drawn over the still background (animation._render) is, pixel for pixel,
    the picture a full redraw of the same figure gives (matplotlib's own ``savefig``, what
    PillowWriter wrote per frame): both draw the same artists with the same Agg renderer in
    the same order, so no difference at all is allowed. Several frames: the background is
    drawn once, the moving artists (forces, slope ground, clock) change."""
    run = library_run(settings_from(REPO / 'config' / config), stop=0.4, forces=True)
    frames = np.array([0, len(run.t) // 2, len(run.t) - 1])
    # two figures of the same scene: one drawn as animate draws it, one redrawn in full
    scenes = [animation._Scene(run, animation._figure(SIZE), view, camera, True, frames)
              for _ in range(2)]
    width, height = scenes[0].figure.canvas.get_width_height()
    for frame in range(len(frames)):
        for scene in scenes:
            scene.draw(frame)
        fast = np.array(animation._render(scenes[0])).reshape(height, width, 4)
        full = _full_redraw(scenes[1].figure)
        assert np.array_equal(fast, full), (
            f'frame {frame}: {np.count_nonzero((fast != full).any(axis=2))} pixels differ')


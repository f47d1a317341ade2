"""One palette for every picture: model/palette.py, used by the figures, the inspection
plot, the animation and the RViz/Foxglove markers (which must not import matplotlib)."""

import ast
import os
from pathlib import Path
import re
import subprocess
import sys

import numpy as np
import pytest

from twodisk_ros.model import palette

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / 'twodisk_ros'
HEX = re.compile(r'^#[0-9a-fA-F]{6}$')
NAMES = ('A', 'B', 'AB', 'G', 'FORCE', 'FORCE_PULLING', 'HULL', 'MU', 'INVALID', 'SLIP')


def test_palette_is_plain_hex_without_imports():
    tree = ast.parse((PACKAGE / 'model' / 'palette.py').read_text(encoding='utf-8'))
    assert not [node for node in ast.walk(tree) if isinstance(node, (ast.Import,
                                                                     ast.ImportFrom))]
    for name in NAMES:
        assert HEX.match(getattr(palette, name)), name
    assert palette.A != palette.B
    assert palette.rgb('#ff8000') == (1.0, 128 / 255, 0.0)
    with pytest.raises(ValueError):
        palette.rgb('red')


def test_markers_import_the_palette_without_matplotlib():
    code = ('import sys; import twodisk_ros.node.messages; '
            'print("matplotlib" in sys.modules)')
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=str(REPO)), timeout=60, check=True)
    assert done.stdout.strip() == 'False'


def _string_constants(path):
    tree = ast.parse(path.read_text(encoding='utf-8'))
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)]


def _sources():
    paths = sorted(PACKAGE.rglob('*.py')) + sorted((REPO / 'benchmarks').glob('*.py'))
    return [p for p in paths if p.name != 'palette.py']


@pytest.mark.parametrize('path', _sources(), ids=lambda p: str(p.relative_to(REPO)))
def test_no_module_hard_codes_a_palette_colour(path):
    """A colour of the palette is written only in palette.py; the others import it (an old
    orange of the figures, '#c8501e', and tab:red / tab:blue for A and B are gone too)."""
    colours = {getattr(palette, name).lower() for name in NAMES} | {'#c8501e'}
    found = [(line, text) for line, text in _string_constants(path)
             if text.lower() in colours]
    assert found == []


def test_figures_and_animation_take_their_colours_from_the_palette():
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    from twodisk_ros.physics.bodies.ellipse import EllipseBody
    from twodisk_ros.plotting import animation, figures
    fig, ax = plt.subplots()
    try:
        figures.plot_traces(EllipseBody.oloid(), 1, ax, samples_per_cycle=50)
        colours = {line.get_gid(): line.get_color() for line in ax.lines if line.get_gid()}
        assert colours == {'trace A': palette.A, 'trace B': palette.B}
    finally:
        plt.close(fig)
    assert (animation.COLOR_1, animation.COLOR_2, animation.COLOR_AB, animation.COLOR_G,
            animation.COLOR_FORCE) == (palette.A, palette.B, palette.AB, palette.G,
                                       palette.FORCE)


def test_marker_colours_are_the_palettes():
    from twodisk_ros.node import messages
    s = np.linspace(0.0, 2 * np.pi, 9)
    disk = np.stack([np.cos(s), np.sin(s), 0 * s], -1)
    specs = {spec.id: spec for spec in messages.body_marker_specs(
        disk, disk + 1.0, (0, 0, 0), (1, 0, 0), 1.0, hull=(disk, disk + 1.0))}
    ids = messages.MARKER_IDS
    for key, colour in (('outline_1', palette.A), ('outline_2', palette.B),
                        ('disk_1', palette.A), ('disk_2', palette.B),
                        ('contact_line', palette.AB), ('hull', palette.HULL)):
        assert tuple(specs[ids[key]].color[:3]) == pytest.approx(palette.rgb(colour)), key
    push, pull = messages.force_arrow_specs([(0, 0, 0), (1, 0, 0)],
                                            [(0, 0, 5.0), (0, 0, -1.0)], 9.81, 1.0)
    assert tuple(push.color[:3]) == pytest.approx(palette.rgb(palette.FORCE))
    assert tuple(pull.color[:3]) == pytest.approx(palette.rgb(palette.FORCE_PULLING))

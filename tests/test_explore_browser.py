"""twodisk-explore in a real browser: headless Debian Chromium (software GL) on the live page
and on an exported lesson, one browser and one server for the module.

References: the body's pixels are checked against the projection of its mesh (the run's
published pose G, q applied to :func:`twodisk_ros.model.mesh.mesh_parts`' vertices, through
the camera the browser reports to the server: position, look-at, up, vertical field of view),
computed here independently of viser; a control's new value is read back from the server's
settings; a refusal's text is the node's own ValueError message. Screenshots are kept under
the pytest tmp dir (``explore_*.png``).
"""

import math
import os
import time

import numpy as np
import pytest

from chromium import Chromium, missing

REASON = missing()
# on CI (CI=true) make test installs chromium: a missing one is a failure there, not a skip
pytestmark = pytest.mark.skipif(REASON is not None and os.environ.get('CI') != 'true',
                                reason=REASON or '')

#: A pixel of the body: disk 1's blue (#1f5fa8) or disk 2's orange (#d9622b), lit or shaded.
#: (The panel's own blue buttons are outside the canvas area checked.)
MARGIN = 6          #: px: the silhouette's edge is antialiased over about 1 px, lines 2-3 px


def body_pixels(image):
    """Pixels of disk 1's blue (#1f5fa8, hue 212 deg) or disk 2's orange (#d9622b, 20 deg),
    lit or in shade: hue within 20 deg of either, saturation > 0.35, value > 0.08."""
    from matplotlib.colors import rgb_to_hsv
    hsv = rgb_to_hsv(image.astype(float) / 255.0)
    hue = 360.0 * hsv[..., 0]
    coloured = (hsv[..., 1] > 0.35) & (hsv[..., 2] > 0.08)
    return coloured & ((abs(hue - 212.0) < 20.0) | (abs(hue - 20.0) < 20.0))


def rotation(q):
    """R body → world of a quaternion (x, y, z, w) (Hamilton, unit)."""
    x, y, z, w = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def project(points, camera, canvas):
    """Pixel (column, row) of world points through a pinhole camera looking from
    ``position`` at ``look_at`` with ``up``, vertical field of view ``fov`` (rad), on a
    canvas (left, top, width, height) in px."""
    left, top, width, height = canvas
    position, look_at, up, fov = camera
    forward = (look_at - position) / np.linalg.norm(look_at - position)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    upward = np.cross(right, forward)
    d = np.asarray(points) - position
    depth = d @ forward
    focal = 0.5 * height / math.tan(0.5 * fov)
    return np.stack([left + 0.5 * width + focal * (d @ right) / depth,
                     top + 0.5 * height - focal * (d @ upward) / depth], axis=1)


def silhouette(triangles_px, width, height, margin=MARGIN):
    """The union of projected triangles (k, 3, 2) filled, and grown by ``margin`` px."""
    from PIL import Image, ImageDraw
    from scipy.ndimage import binary_dilation
    image = Image.new('1', (width, height))
    draw = ImageDraw.Draw(image)
    for triangle in triangles_px:
        draw.polygon([tuple(p) for p in triangle], fill=1)
    mask = np.asarray(image, dtype=bool)
    return mask, binary_dilation(mask, iterations=margin)


def body_triangles(parts, frame, shift):
    """World (scene) triangles (k, 3, 3) of the body's mesh at the last sample of the frame."""
    i = len(frame) - 1
    R, g = rotation(frame.quaternion[i]), frame.position_g[i]
    return np.concatenate([np.asarray(m.vertices)[np.asarray(m.faces)] @ R.T + g + shift
                           for m in parts.values()])


def _canvas(browser):
    """(left, top, width, height) of the scene's canvas (px)."""
    return browser.evaluate("(() => { const r = document.querySelector('canvas')"
                            ".getBoundingClientRect(); return [r.left, r.top, r.width, "
                            "r.height]; })()")


def check_drawn(image, parts, frame, shift, camera, canvas, usable, overlay=None):
    """The body's colour fills its projected silhouette and hardly appears elsewhere (the
    silhouette's outline drawn in green over the screenshot at ``overlay``)."""
    height, width = image.shape[:2]
    triangles = body_triangles(parts, frame, shift)
    px = project(triangles.reshape(-1, 3), camera, canvas).reshape(-1, 3, 2)
    hull, grown = silhouette(px, width, height)
    if overlay is not None:
        from PIL import Image
        from scipy.ndimage import binary_erosion
        marked = image.copy()
        marked[hull & ~binary_erosion(hull)] = (0, 255, 0)
        Image.fromarray(marked).save(overlay)
    seen = body_pixels(image) & usable
    # the traces of A and B share the disks' colours: lines a few px wide, which an opening
    # by a 5 x 5 square removes (the body's projection is wider except where a plate is
    # seen edge-on, inside the silhouette anyway)
    from scipy.ndimage import binary_opening
    bulk = binary_opening(seen, structure=np.ones((5, 5), dtype=bool))
    assert (seen & hull).sum() > 0.9 * (hull & usable).sum(), (seen.sum(), hull.sum())
    assert (bulk & grown).sum() >= 0.98 * bulk.sum(), ((bulk & grown).sum(), bulk.sum())
    return hull, seen


#: The browser's window (CSS px): small, because software GL's cost of a frame grows with its
#: pixels; the scene checks collapse the control panel, which would cover the body.
WINDOW = (640, 400)


@pytest.fixture(scope='module')
def live(tmp_path_factory):
    from twodisk_ros.explore.cli import _server, stop_server
    from twodisk_ros.explore.motion import open_motion
    from twodisk_ros.explore.page import Explorer
    from twodisk_ros.runs import settings_from
    settings = settings_from('config/oloid.yaml', realtime=True)
    server = _server('127.0.0.1', 0)
    explorer = Explorer(server, open_motion(settings=settings))
    explorer.toggle()            # paused: a test plays the motion only while it needs it
    explorer.start()
    browser = None
    try:
        browser = Chromium(*WINDOW)
        browser.goto(f'http://127.0.0.1:{server.get_port()}/')
        browser.wait_for("document.body !== null && document.body.innerText.includes('rolling')")
        _dismiss(browser)
        yield explorer, browser, server, tmp_path_factory.mktemp('explore_shots')
    finally:
        if browser is not None:
            browser.close()
        explorer.stop()
        stop_server(server)


def _dismiss(browser):
    """Close viser's 'software WebGL' notice (it covers the scene's top left)."""
    browser.evaluate("document.querySelectorAll('.mantine-Notification-closeButton')"
                     ".forEach(b => b.click())")


def _camera(server):
    (client,) = server.get_clients().values()
    c = client.camera
    return (np.asarray(c.position, dtype=float), np.asarray(c.look_at, dtype=float),
            np.asarray(c.up_direction, dtype=float), float(c.fov))


def _panel(browser, collapsed):
    """Collapse (or open) the control panel with its own minimize button; wait until its
    Play/Pause button is hidden (or shown)."""
    button = "document.querySelector('[data-dock-minimize]')"
    if browser.evaluate(f"{button}.getAttribute('aria-expanded') === 'true'") == collapsed:
        browser.evaluate(f"{button}.click()")
    browser.wait_for("Array.from(document.querySelectorAll('button')).some(b => "
                     "/^(Play|Pause)$/.test(b.innerText) && "
                     f"b.getBoundingClientRect().height > 0) === {str(not collapsed).lower()}")


def _usable(browser, height, width):
    """Pixels of the scene not under the collapsed control panel (its title bar, from 30 px
    left of its cloud icon and 30 px below its minimize button) nor under the axes gizmo (the
    bottom left 70 px square)."""
    left, bottom = browser.evaluate(
        "[document.querySelector('.tabler-icon-cloud-check').getBoundingClientRect().left, "
        "document.querySelector('[data-dock-minimize]').getBoundingClientRect().bottom]")
    usable = np.ones((height, width), dtype=bool)
    usable[:int(bottom) + 30, int(left) - 30:] = False
    usable[-70:, :70] = False
    return usable


#: The page's three.js position of the body's node (viser's E2E hook ``__viserMutable``).
BODY_NODE = "__viserMutable.nodeRefFromName['/world/body'].position"


def _shown_on_page(browser, frame):
    """Wait until the page has drawn ``frame``'s pose: the body node's position is G (the
    client applies a pose in its render loop, just before drawing the frame)."""
    g = [float(x) for x in frame.position_g[-1]]
    browser.wait_for(f"(() => {{ const p = {BODY_NODE}; const g = {g}; "
                     "return Math.hypot(p.x - g[0], p.y - g[1], p.z - g[2]) "
                     "<= 1e-9 * (1 + Math.hypot(...g)); })()", timeout=20)


def _play_until(explorer, t, timeout=20.0):
    """Play until the page's last frame is at simulated time >= t (s), then pause."""
    if not explorer.playing:
        explorer.toggle()
    _until(lambda: explorer.shown is not None and explorer.shown.t[-1] >= t, timeout)
    explorer.toggle()


def _paused_shot(explorer, browser, path):
    """Pause, let the last frame reach the page, screenshot; (image, frame, shift)."""
    if explorer.playing:
        explorer.toggle()
    frame = explorer.shown
    _shown_on_page(browser, frame)
    image = browser.screenshot(path)
    assert explorer.shown is frame
    return image, frame, explorer.scene.shift(frame.position_g[-1])


def test_the_body_is_drawn_where_its_pose_projects_and_it_moves(live):
    explorer, browser, server, shots = live
    explorer.reset()
    _panel(browser, collapsed=True)
    try:
        _play_until(explorer, 0.5)
        first, frame1, shift1 = _paused_shot(explorer, browser, shots / 'explore_live_1.png')
        usable = _usable(browser, *first.shape[:2])
        camera, canvas = _camera(server), _canvas(browser)
        parts = explorer.scene.parts
        hull1, seen1 = check_drawn(first, parts, frame1, shift1, camera, canvas, usable,
                                   shots / 'explore_live_1_projected.png')
        _play_until(explorer, frame1.t[-1] + 0.5)
        second, frame2, shift2 = _paused_shot(explorer, browser, shots / 'explore_live_2.png')
        hull2, seen2 = check_drawn(second, parts, frame2, shift2, camera, canvas, usable)
        assert frame2.t[-1] > frame1.t[-1] + 0.2
        # it moved: the projected silhouettes differ, and so do the drawn bodies
        assert (hull1 ^ hull2).sum() > 0.05 * hull1.sum()
        assert (seen1 ^ seen2).sum() > 0.05 * seen1.sum()
    finally:
        _panel(browser, collapsed=False)


def _slider(browser, label):
    """Focus the slider thumb of the control ``label``; return its value (aria-valuenow)."""
    return browser.evaluate(
        "(() => { const label = Array.from(document.querySelectorAll('label, div, span'))"
        f".find(e => e.children.length === 0 && e.innerText === {label!r}); "
        "let row = label; while (row && !row.querySelector('[role=slider]')) "
        "row = row.parentElement; const t = row.querySelector('[role=slider]'); t.focus(); "
        "return Number(t.getAttribute('aria-valuenow')); })()")


def _frames(browser, count):
    """Wait for ``count`` animation frames of the page."""
    browser.evaluate("new Promise(done => { let n = %d; const f = () => --n > 0 ? "
                     "requestAnimationFrame(f) : done(true); requestAnimationFrame(f); })"
                     % count)


def _until(predicate, timeout=10.0):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, 'timed out'
        time.sleep(0.02)


def test_a_slider_changes_the_servers_parameter_and_restarts(live):
    explorer, browser, server, _ = live
    before, restarts = explorer.motion.settings.theta0, explorer.motion.restarts
    assert _slider(browser, 'theta0') == pytest.approx(before)
    browser.key('ArrowRight', 'ArrowRight', 39)
    _until(lambda: explorer.motion.restarts > restarts)
    # the slider's step is 0.01 rad: the new theta0 is the old one plus a step
    assert explorer.motion.settings.theta0 == pytest.approx(before + 0.01, abs=1e-12)
    assert explorer.motion.t < 1.0 and explorer.refused is None
    browser.key('ArrowLeft', 'ArrowLeft', 37)
    _until(lambda: explorer.motion.settings.theta0 == pytest.approx(before, abs=1e-12))


def test_a_refused_value_shows_the_nodes_reason_and_the_motion_goes_on(live):
    explorer, browser, server, shots = live
    settings, restarts = explorer.motion.settings, explorer.motion.restarts
    _slider(browser, 'delta')
    browser.key('End', 'End', 35)                     # delta = 3 max(a, b) > a: refused
    _until(lambda: explorer.attempted is not None and explorer.attempted[0] == 'delta')
    value = explorer.attempted[1]
    assert value > settings.a
    with pytest.raises(ValueError) as node:
        settings.with_values(delta=value).checked()
    reason = ' '.join(str(node.value).split())
    assert explorer.refused == reason
    browser.wait_for(f"document.body.innerText.includes({('refused: ' + reason)!r})")
    assert explorer.motion.settings == settings and explorer.motion.restarts == restarts
    t = explorer.motion.t
    explorer.toggle()                                  # play: the previous motion goes on
    try:
        _until(lambda: explorer.motion.t > t + 0.1)
    finally:
        explorer.toggle()
    assert explorer.motion.restarts == restarts
    # the slider is back at the accepted value
    browser.wait_for(f"Number(document.activeElement.getAttribute('aria-valuenow')) === "
                     f"{settings.delta}")


#: The scene canvas's WebGL context: its antialias attribute, and the browser's renderer
#: name asked here independently of the page's script (WEBGL_debug_renderer_info).
MULTISAMPLING = ("(() => { const c = document.createElement('canvas').getContext('webgl2');"
                 " const name = c.getParameter(c.getExtension('WEBGL_debug_renderer_info')"
                 ".UNMASKED_RENDERER_WEBGL); return [name, document.querySelector('canvas')"
                 ".getContext('webgl2').getContextAttributes().antialias]; })()")


def test_software_gl_draws_the_page_without_multisampling(live):
    """The browser set-up is software GL (SwiftShader, the renderer the browser names), and
    there the page's WebGL context has no multisampling (viser asks for it: the page's
    script, explore/client.py, takes it off); the lesson's check is in the lesson's test."""
    _, browser, _, _ = live
    renderer, antialias = browser.evaluate(MULTISAMPLING)
    assert 'SwiftShader' in renderer
    assert antialias is False


def test_the_exported_lesson_renders_the_same_scene_offline(live, tmp_path):
    """The lesson, paused, against the projection of the frame of the node's run that its
    player shows (frame k is the scene at k / EXPORT_FPS s, its player's time to 1 ms); no
    request leaves the file."""
    from twodisk_ros.explore.cli import EXPORT_FPS, export
    from twodisk_ros.explore.motion import LiveMotion
    from twodisk_ros.explore.scene3d import MESH_RESOLUTION, camera_for
    from twodisk_ros.model.mesh import mesh_parts
    explorer, browser, server, shots = live
    settings = explorer.motion.settings
    path = tmp_path / 'lesson.html'
    export(LiveMotion(settings), path, seconds=3.0)     # paused before it loops
    browser.goto(path.as_uri())
    browser.wait_for("document.querySelector('.tabler-icon-player-pause-filled') !== null")
    _dismiss(browser)
    browser.evaluate("document.querySelector('.tabler-icon-player-pause-filled')"
                     ".closest('button').click()")
    browser.wait_for("document.querySelector('.tabler-icon-player-play-filled') !== null")
    _frames(browser, 2)                                # the paused scene is drawn
    image = browser.screenshot(shots / 'explore_lesson.png')
    seconds = float(browser.evaluate(          # the player's time (s, to 1 ms)
        "document.querySelector('.mantine-Slider-root input[type=hidden]').value"))
    reference = LiveMotion(settings)
    for _ in range(int(math.floor(seconds * EXPORT_FPS + 1e-9)) + 1):
        frame = reference.advance(1.0 / EXPORT_FPS, samples=4)
    position, look_at = camera_for(reference.body.size)
    camera = (position, look_at, np.array([0.0, 0.0, 1.0]), math.radians(75.0))
    usable = np.ones(image.shape[:2], dtype=bool)
    usable[-45:] = False                               # the player's bar
    usable[-115:, :70] = False                         # the axes gizmo
    left, top, right, bottom = browser.evaluate(      # the plots' panel
        "(() => { const r = document.getElementById('lesson-plots').getBoundingClientRect();"
        " return [r.left, r.top, r.right, r.bottom]; })()")
    usable[max(0, int(top) - 2):int(bottom) + 3, max(0, int(left) - 2):int(right) + 3] = False
    # the plots follow the player: the phase marker sits where the lesson puts frame k's
    k = int(math.floor(seconds * EXPORT_FPS + 1e-6))
    import json
    import re
    moves = json.loads(re.search(r'moves = (\{.*?\});', path.read_text(encoding='utf-8'))
                       .group(1))
    dx, dy = (0 if x == 0 else float(x) for x in moves['lesson-phase'][k])
    assert browser.evaluate("document.getElementById('lesson-phase').getAttribute('transform')"
                            ) == f"translate({repr(dx).removesuffix('.0')} " \
                                 f"{repr(dy).removesuffix('.0')})"
    parts = mesh_parts(reference.body, settings.mass_model, resolution=MESH_RESOLUTION)
    g = frame.position_g[-1]
    check_drawn(image, parts, frame, -(g - g[2] * np.array([0.0, 0.0, 1.0])), camera,
                _canvas(browser), usable,
                shots / 'explore_lesson_projected.png')
    assert browser.evaluate(MULTISAMPLING)[1] is False          # software GL, as live
    resources = browser.evaluate("performance.getEntriesByType('resource').map(e => e.name)")
    assert all(name.startswith(('file:', 'data:', 'blob:')) for name in resources), resources

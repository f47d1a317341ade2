"""The page of ``twodisk-explore``: controls, plots and the paced loop (viser; no rclpy).

:class:`Explorer` owns a viser server, the 3D scene (:class:`~twodisk_ros.explore.scene3d.
Scene3D`) and a motion (:mod:`~twodisk_ros.explore.motion`). A thread shows a frame
:data:`FPS` times a second: it advances the motion by ``speed`` / FPS simulated seconds
(sampled every 1 / :data:`TRACE_RATE` s for the traces and the force plots) and draws the
last sample. A control's change is applied at once in viser's callback thread: the motion
restarts at t = 0 (the next frame shows it), or the node's one-line reason is shown and the
control goes back to the accepted value.

Beside the scene: z_G over one cycle on the flat ground with the equilibria (stable green,
unstable red) and the current phase; N_A, N_B and μ_required with the friction μ over the
last :data:`WINDOW` s; a status line (rolling, or the node's words for lift-off, slip or a
flat vertex, :attr:`Simulation.invalid`).
"""

import math
import threading
import time

import numpy as np

from ..model import palette
from ..run.parameters import BY_NAME, SHAPE_ONLY
from .motion import CONTROLLED
from .scene3d import Scene3D, camera_for, rgb255

__all__ = ['FPS', 'SPEEDS', 'TRACE_RATE', 'WINDOW', 'Explorer', 'slider_range']

#: Frames a second the page is sent.
FPS = 30.0
#: Speeds offered (simulated seconds per second).
SPEEDS = ('0.1', '0.25', '0.5', '1', '2', '5', '10')
#: Samples per simulated second for the traces and the force plots.
TRACE_RATE = 100.0
#: Seconds of N_A, N_B, μ_required shown.
WINDOW = 5.0
#: The equilibria's marks on the z_G curve: stability → colour.
STABILITY = {'stable': palette.AB, 'unstable': palette.FORCE_PULLING, 'neutral': palette.HULL}
#: Plots and traces are sent this many times a second.
PLOT_RATE = 5.0


def slider_range(name, settings):
    """(low, high, step) of the page's slider of a float parameter: a range around the
    body (size L = max(a, b)) for lengths, the contract's range for bounded ones. The node's
    rules (delta < a, |theta0| <= theta_max, ...) are checked on change, not here."""
    size = max(settings.a, settings.b)
    step = 10.0 ** math.floor(math.log10(size / 200.0))
    ranges = {'a': (step, 3 * size), 'b': (step, 3 * size), 'delta': (step, 3 * size),
              'exponent': (2.0, 20.0), 'theta0': (-math.pi, math.pi),
              'omega0': (-20.0, 20.0), 'slope': (-0.6, 0.6), 'heading0': (-math.pi, math.pi),
              'damping': (0.0, 10 * settings.mass * size ** 2),
              'rolling_resistance': (0.0, 0.2), 'friction': (0.0, 2.0)}
    p = BY_NAME[name]
    low, high = (float(f'{x:.12g}') for x in ranges.get(name, (p.low, p.high)))
    steps = {'a': step, 'b': step, 'delta': step, 'exponent': 0.1, 'damping': high / 200}
    return low, high, steps.get(name, 0.01 if high - low <= 7 else 0.1)


class Explorer:
    """A served page showing ``motion``.

    Parameters
    ----------
    server : viser.ViserServer
    motion : LiveMotion or RecordedMotion
    speed : float
        Simulated seconds per second at start.
    """

    def __init__(self, server, motion, speed=1.0):
        self.server, self.motion = server, motion
        self.lock = threading.RLock()
        self.playing, self.speed = True, float(speed)
        self.stop_event = threading.Event()
        self.shown = None            #: the last Frame drawn
        self.shown_time = None       #: time.monotonic() when it was sent
        self.refused = None          #: the last refusal (the node's one line)
        self.attempted = None        #: (name, value) of the last change tried
        self.changed_at = None       #: time.monotonic() of the last change tried
        self.restart_shown = None    #: time.monotonic() of the first frame after a restart
        self.frames = 0
        server.scene.set_up_direction('+z')
        # no share button: sharing goes through viser's servers on the internet
        server.gui.configure_theme(show_share_button=False)
        self.scene = Scene3D(server, motion)
        position, look_at = camera_for(self.scene.size)
        server.initial_camera.position = tuple(position)
        server.initial_camera.look_at = tuple(look_at)
        self.controls = {}
        self._reverting = False
        self._gui()
        self._new_plots()
        self._history = None
        self._next_plot = 0.0

    # -- the panel -------------------------------------------------------------------------
    def _gui(self):
        gui = self.server.gui
        m = self.motion
        with gui.add_folder('Run', order=0):
            self.play_button = gui.add_button('Pause')
            self.reset_button = gui.add_button('Reset')
            self.speed_control = gui.add_dropdown('speed (x)', SPEEDS,
                                                  initial_value=_speed_text(self.speed))
            self.status = gui.add_markdown(self._status_text())
            self.plots_control = gui.add_checkbox(
                'plots', True, hint='show the plots (hidden, software GL draws the page '
                '1.4 to 2.3 times as fast: docs/benchmarks.md)')
        self.plots_control.on_update(lambda _: self._show_plots())
        self.play_button.on_click(lambda _: self.toggle())
        self.reset_button.on_click(lambda _: self.reset())
        self.speed_control.on_update(lambda _: self.set_speed(float(self.speed_control.value)))
        groups = (('Body', CONTROLLED[:8]), ('Motion', CONTROLLED[8:11]),
                  ('Scene', CONTROLLED[11:]))
        for order, (title, names) in enumerate(groups, start=10):
            with gui.add_folder(title, order=order, expand_by_default=title != 'Scene'):
                for name in names:
                    self.controls[name] = self._control(name, m.settings)
                if title == 'Scene':
                    self.controls['command'] = gui.add_slider(
                        'command', -20.0, 20.0, 0.1, float(m.command or 0.0),
                        hint='the drive command: rad/s (drive speed) or N m (drive torque)')
        for name, handle in self.controls.items():
            handle.on_update(lambda _, name=name: self._changed(name))
            handle.disabled = not m.live
        self._shape_controls()

    def _shape_controls(self):
        """Show the parameters the shape reads (exponent: superellipse; egg_asymmetry: egg)."""
        shape = self.motion.settings.shape
        for name, owner in SHAPE_ONLY.items():
            if name in self.controls:
                self.controls[name].visible = shape == owner

    def _control(self, name, settings):
        gui, p, value = self.server.gui, BY_NAME[name], getattr(settings, name)
        hint = f'{p.unit + ": " if p.unit else ""}{p.description}'[:300]
        if p.choices is not None:
            return gui.add_dropdown(name, tuple(p.choices), initial_value=value, hint=hint)
        low, high, step = slider_range(name, settings)
        shown = min(max(value, low), high) if math.isfinite(value) else high
        return gui.add_slider(name, low, high, step, shown, hint=hint)

    def _new_plots(self):
        gui, m = self.server.gui, self.motion
        u, z = m.cycle()
        marks = m.equilibria()
        self._u = np.unique(np.concatenate([u, [e[0] for e in marks]]))
        self._z = np.interp(self._u, u, z)
        self._marks = {kind: np.full(len(self._u), np.nan) for kind in STABILITY}
        for phase, height, stability in marks:
            k = int(np.argmin(abs(self._u - phase)))
            self._marks[stability][k] = height
        point = {'show': True, 'size': 9}
        series = ({'label': 'u (rad)'},
                  {'label': 'z_G (m)', 'stroke': palette.G, 'width': 2},
                  *({'label': kind, 'stroke': colour, 'width': 0, 'points': point}
                    for kind, colour in STABILITY.items()),
                  {'label': 'now', 'stroke': palette.B, 'width': 0,
                   'points': {'show': True, 'size': 12}})
        low, high = float(z.min()), float(z.max())
        pad = max(0.1 * (high - low), 0.01 * self.scene.size)
        if getattr(self, 'cycle_plot', None) is not None:
            # a new body: new data and range on the same plots (the client keeps them)
            with self.server.atomic():
                self.cycle_plot.scales = {'x': {'time': False},
                                          'y': {'range': [low - pad, high + pad]}}
                self.cycle_plot.data = self._cycle_data(None)
            return
        self.cycle_plot = gui.add_uplot(
            self._cycle_data(None), series, aspect=1.8, order=1,
            scales={'x': {'time': False}, 'y': {'range': [low - pad, high + pad]}},
            title='z_G over the cycle (flat ground)')
        empty = (np.zeros(2), np.zeros(2), np.zeros(2))
        self.force_plot = gui.add_uplot(
            empty, ({'label': 't (s)'}, {'label': 'N_A (N)', 'stroke': palette.A, 'width': 2},
                    {'label': 'N_B (N)', 'stroke': palette.B, 'width': 2}),
            aspect=1.8, order=2, scales={'x': {'time': False}},
            title='normal forces N_A, N_B')
        self.mu_plot = gui.add_uplot(
            empty, ({'label': 't (s)'}, {'label': 'mu_required', 'stroke': palette.MU,
                                         'width': 2},
                    {'label': 'friction mu', 'stroke': palette.FORCE_PULLING, 'width': 1,
                     'dash': [6, 4]}),
            aspect=1.8, order=3, scales={'x': {'time': False}},
            title='friction needed and available')
        if hasattr(self, 'plots_control'):
            self._show_plots()

    def _show_plots(self):
        with self.lock:
            for handle in (self.cycle_plot, self.force_plot, self.mu_plot):
                handle.visible = bool(self.plots_control.value)

    def _cycle_data(self, phase):
        now = np.full(len(self._u), np.nan)
        if phase is not None and math.isfinite(phase):
            k = int(np.argmin(abs(self._u - phase % (2 * math.pi))))
            now[k] = self._z[k]
        return (self._u, self._z, *self._marks.values(), now)

    def _status_text(self):
        m = self.motion
        source = 'simulated: the node\'s physics' if m.live else f'replay of {m.path}'
        lines = [f'**{source}**, t = {m.t:.2f} s, speed x{_speed_text(self.speed)}'
                 f'{"" if self.playing else " (paused)"}']
        if m.invalid is not None:
            lines.append(f'<span style="color:#d7191c">**outside the rolling model:** '
                         f'{m.invalid}</span>')
        else:
            lines.append('rolling (within the rolling model)')
        if self.refused is not None:
            lines.append(f'<span style="color:#d7191c">**refused:** {self.refused}</span>')
        return '\n\n'.join(lines)

    # -- actions ---------------------------------------------------------------------------
    def toggle(self):
        """Play or pause."""
        with self.lock:
            self.playing = not self.playing
            self.play_button.label = 'Pause' if self.playing else 'Play'
            self.status.content = self._status_text()

    def set_speed(self, speed):
        with self.lock:
            self.speed = float(speed)

    def reset(self):
        """The run again from t = 0 (traces cleared)."""
        with self.lock:
            self.motion.reset()
            self._restarted(rebuild=False)

    def change(self, name, value):
        """Apply a control's value; return None or the node's reason (also shown)."""
        with self.lock:
            self.changed_at = time.monotonic()
            old = self.motion.settings
            reason = self.motion.change(name, value)
            self.refused, self.attempted = reason, (name, value)
            if reason is None:
                body_changed = (self.motion.body is not self.scene_body
                                or old.mass_model != self.motion.settings.mass_model
                                or old.slope != self.motion.settings.slope)
                # the new scene, plots and the new motion's first frame in one message
                # window: the page draws them together, with no frame of a half-built scene
                with self.server.atomic():
                    self._restarted(rebuild=body_changed)
                    if self.playing:
                        self.step(1.0 / FPS)
            else:
                self._revert(name)
            self.status.content = self._status_text()
            return reason

    def _changed(self, name):
        if self._reverting:
            return
        handle = self.controls[name]
        self.change(name, handle.value)

    def _revert(self, name):
        m = self.motion
        value = m.command if name == 'command' else getattr(m.settings, name, None)
        if value is None or (isinstance(value, float) and not math.isfinite(value)):
            return
        self._reverting = True
        try:
            self.controls[name].value = value
        finally:
            self._reverting = False

    @property
    def scene_body(self):
        return self._scene_body

    _scene_body = None

    def _restarted(self, rebuild):
        if rebuild:
            self.scene.rebuild(self.motion)
            self._new_plots()
        else:
            self.scene.traces.clear()
        self._scene_body = self.motion.body
        self._shape_controls()
        self.restart_shown = None
        self._history = None
        self._next_plot = 0.0
        self.status.content = self._status_text()

    # -- the loop --------------------------------------------------------------------------
    def step(self, wall_dt, paused_too=False):
        """Advance by ``wall_dt`` seconds of the show (× speed) and draw; return the Frame
        (None if paused, unless ``paused_too``)."""
        with self.lock:
            if not (self.playing or paused_too):
                return None
            if self._scene_body is None:
                self._scene_body = self.motion.body
            dt = wall_dt * self.speed
            samples = max(1, min(50, int(math.ceil(dt * TRACE_RATE))))
            restarts = self.motion.restarts
            frame = self.motion.advance(dt, samples)
            if self.motion.restarts != restarts:        # a replay started again
                self.scene.traces.clear()
                self._history = None
            now = time.monotonic()
            publish = now >= self._next_plot
            self.scene.show(frame, traces=publish)
            self._record(frame)
            if publish:
                self._next_plot = now + 1.0 / PLOT_RATE
                self._plots(frame)
            self.shown, self.shown_time = frame, time.monotonic()
            if self.restart_shown is None:
                self.restart_shown = self.shown_time
            self.frames += 1
            return frame

    def _record(self, frame):
        if frame.normal_a is None:
            return
        new = np.stack([frame.t, frame.normal_a, frame.normal_b, frame.mu_required])
        old = self._history
        joined = new if old is None else np.concatenate([old, new], axis=1)
        keep = joined[0] >= joined[0, -1] - WINDOW
        self._history = joined[:, keep]

    def _plots(self, frame):
        self.status.content = self._status_text()
        if not self.plots_control.value:
            return
        phase = None if frame.phase is None else float(frame.phase[-1])
        self.cycle_plot.data = self._cycle_data(phase)
        if self._history is not None and self._history.shape[1] >= 2:
            t, n_a, n_b, mu = self._history
            finite = np.where(np.isfinite(mu), mu, np.nan)
            friction = self.motion.settings.friction
            line = np.full(len(t), friction if math.isfinite(friction) else np.nan)
            self.force_plot.data = (t, n_a, n_b)
            self.mu_plot.data = (t, finite, line)

    def run(self):
        """Show frames at :data:`FPS` until :meth:`stop` (call in a thread)."""
        period = 1.0 / FPS
        due = time.monotonic()
        last = due
        while not self.stop_event.is_set():
            now = time.monotonic()
            if self.playing:
                self.step(min(now - last, 0.25) if self.frames else period)
            last = now
            due = max(due + period, now)
            self.stop_event.wait(max(0.0, due - time.monotonic()))

    def start(self):
        self.thread = threading.Thread(target=self.run, name='twodisk-explore', daemon=True)
        self.thread.start()
        return self

    def stop(self):
        self.stop_event.set()
        thread = getattr(self, 'thread', None)
        if thread is not None:
            thread.join(timeout=5)


def _speed_text(speed):
    return f'{speed:g}'

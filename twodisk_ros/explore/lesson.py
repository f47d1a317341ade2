"""The plots of an exported lesson: z_G over the cycle with the equilibria and the phase, N_A
and N_B, μ_required against the friction μ, beside the scene, following its player.

The lesson (:func:`twodisk_ros.explore.cli.export`) is viser's scene player in one HTML file;
its GUI (the live page's uPlot plots) is not recorded, so the plots are drawn here with
matplotlib as one SVG put in a corner of the page. A small script moves the markers (the
current phase on the z_G curve, a line at the current time on the force plots) to the
frame the player shows: frame k at k / fps seconds, read from the player's time slider. No
network: the SVG and the script are inline.
"""

import io
import json
import math

import numpy as np

from ..model import palette

__all__ = ['LessonPlots']

#: Equilibria marks: stability → colour (as on the live page).
STABILITY = {'stable': palette.AB, 'unstable': palette.FORCE_PULLING, 'neutral': palette.HULL}
#: Width of the plots' panel on the page (CSS px).
PANEL_PX = 260


class LessonPlots:
    """Collects what a lesson shows and writes its plots.

    Parameters
    ----------
    motion : LiveMotion or RecordedMotion
        Its cycle curve, equilibria and friction μ (before any frame is added).
    fps : float
        The lesson's frames a second.
    """

    def __init__(self, motion, fps):
        self.cycle = motion.cycle()
        self.marks = motion.equilibria()
        self.friction = float(motion.settings.friction)
        self.fps = float(fps)
        self.phases, self.times = [], []
        self.samples = []       # (t, N_A, N_B, mu_required) arrays of each frame

    def add(self, frame):
        """Record one shown Frame (its last sample is the pose drawn)."""
        phase = None if frame.phase is None else float(frame.phase[-1]) % (2 * math.pi)
        self.phases.append(phase)
        self.times.append(float(frame.t[-1]))
        if frame.normal_a is not None:
            self.samples.append(np.stack([frame.t, frame.normal_a, frame.normal_b,
                                          frame.mu_required]))

    def figure(self):
        """The matplotlib Figure (72 dpi: its display units are the SVG's points)."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        forces = len(self.samples) > 0
        fig = Figure(figsize=(3.6, 6.3 if forces else 2.3), dpi=72)
        FigureCanvasAgg(fig)
        axes = fig.subplots(3 if forces else 1, 1, squeeze=False)[:, 0]
        u, z = self.cycle
        ax = axes[0]
        ax.plot(u, z, color=palette.G, lw=1.5)
        for phase, height, stability in self.marks:
            ax.plot([phase], [height], 'o', ms=5, color=STABILITY.get(stability, palette.HULL),
                    mfc='none' if stability == 'unstable' else STABILITY.get(stability))
        start = self.phases[0] if self.phases and self.phases[0] is not None else math.nan
        self._phase = ax.plot([start], [np.interp(start, u, z)], 'o', ms=8, color=palette.B,
                              gid='lesson-phase')[0]
        ax.set(title='z_G over the cycle (flat ground)', xlabel='u (rad)', ylabel='z_G (m)',
               xlim=(0, 2 * math.pi))
        self._lines = []
        if forces:
            t, n_a, n_b, mu = np.concatenate(self.samples, axis=1)
            axes[1].plot(t, n_a, color=palette.A, lw=1.2, label='N_A')
            axes[1].plot(t, n_b, color=palette.B, lw=1.2, label='N_B')
            axes[1].set(title='normal forces', ylabel='N (N)')
            axes[1].legend(fontsize=7, loc='upper right')
            axes[2].plot(t, np.where(np.isfinite(mu), mu, np.nan), color=palette.MU, lw=1.2,
                         label='mu_required')
            if math.isfinite(self.friction):
                axes[2].axhline(self.friction, color=palette.FORCE_PULLING, lw=1, ls='--',
                                label='friction mu')
            axes[2].set(title='friction needed and available', xlabel='t (s)')
            axes[2].legend(fontsize=7, loc='upper right')
            for k, ax in enumerate(axes[1:], start=1):
                ax.set_xlim(t[0], t[-1])
                self._lines.append(ax.axvline(self.times[0], color='0.3', lw=0.8,
                                              gid=f'lesson-time-{k}'))
        for ax in axes:
            ax.tick_params(labelsize=7)
            ax.title.set_fontsize(8)
            ax.xaxis.label.set_fontsize(7)
            ax.yaxis.label.set_fontsize(7)
        fig.tight_layout()
        return fig, axes

    def offsets(self, fig, axes):
        """Per frame, the SVG translations (pt) of the phase marker and of the time lines
        from where they are drawn (frame 0)."""
        u, z = self.cycle
        phase = np.array([math.nan if p is None else p for p in self.phases])
        display = axes[0].transData.transform(np.stack([phase, np.interp(phase, u, z)], 1))
        moves = {'lesson-phase': np.round(display - display[0], 2)}
        for k, ax in enumerate(axes[1:], start=1):
            x = ax.transData.transform(np.stack([self.times, np.zeros(len(self.times))], 1))
            moves[f'lesson-time-{k}'] = np.round(x - x[0], 2) * [1, 0]
        # SVG's y grows downwards
        return {gid: [[float(dx), float(-dy)] if np.isfinite(dx) else None for dx, dy in v]
                for gid, v in moves.items()}

    def html(self):
        """The plots' panel: the SVG, and the script that follows the player."""
        import re
        fig, axes = self.figure()
        buffer = io.StringIO()
        fig.savefig(buffer, format='svg')
        svg = buffer.getvalue()
        svg = svg[svg.index('<svg'):]
        # scaled to the panel's width (its viewBox, in pt, stays the markers' units)
        svg = re.sub(r'<svg([^>]*?) width="[^"]*" height="[^"]*"', r'<svg\1 width="100%"', svg,
                     count=1)
        moves = self.offsets(fig, axes)
        script = (
            '(() => { const fps = %r, moves = %s; let last = -1;'
            ' function follow() {'
            " const input = document.querySelector('.mantine-Slider-root input[type=hidden]');"
            ' if (input !== null) {'
            ' const k = Math.max(0, Math.min(moves["lesson-phase"].length - 1,'
            ' Math.floor(parseFloat(input.value) * fps + 1e-6)));'
            ' if (k !== last) { last = k; for (const [id, steps] of Object.entries(moves)) {'
            ' const g = document.getElementById(id); const d = steps[k];'
            ' if (g !== null && d !== null) g.setAttribute("transform",'
            ' `translate(${d[0]} ${d[1]})`); } } }'
            ' requestAnimationFrame(follow); } requestAnimationFrame(follow); })();'
            % (self.fps, json.dumps(moves, separators=(',', ':'))))
        return (f'<div id="lesson-plots" style="position:fixed;top:8px;left:8px;'
                f'width:min({PANEL_PX}px,30vw);z-index:1000;background:rgba(255,255,255,0.88);'
                'border-radius:6px;padding:2px;pointer-events:none">'
                f'<div style="width:100%">{svg}</div></div>'
                f'<script>{script}</script>')


def with_plots(html, plots):
    """The lesson's HTML with the plots' panel just before ``</body>``."""
    at = html.rfind('</body>')
    at = len(html) if at < 0 else at
    return html[:at] + plots.html() + html[at:]

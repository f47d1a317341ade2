"""Maps of a parameter sweep (``twodisk-sweep --plot DIR``): one PNG per variable.

Each map shows a variable of the sweep's Dataset over b/a (x) and Δ/a (y), both in units of a,
with a colour bar in the variable's unit; the neutral curve b² = 2(a² − Δ²) and the named
bodies (oloid, Two-Circle-Roller, the paper's Figure 3 and 4 bodies) are marked. Masked points
(a failed body, Δ/a ≥ 1) are light grey; infinite values (a lift-off speed that is never
reached, μ_required above the lift-off speed) are black, beyond the colour bar's end.
Quantities whose positive values span a factor above 20 get a logarithmic scale.

A sweep with several superellipse exponents n (its third axis) gets one panel per exponent in
each PNG (at most :data:`MAX_PANELS`, evenly chosen, the rest named in the title), all on one
colour scale; the neutral curve and the named bodies belong to the ellipse and are drawn on
the n = 2 panel only.
"""

import math
import re
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (after selecting the backend)
import numpy as np  # noqa: E402
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm, Normalize  # noqa: E402

from ..outputs import replacing  # noqa: E402
from .figures import FIGURE3, FIGURE4  # noqa: E402

__all__ = ['NAMED_BODIES', 'MAX_PANELS', 'plot_map', 'plot_panels', 'symbols', 'write_maps',
           'exponent_plane', 'shown_exponents']

#: At most this many exponents are drawn in one map (evenly chosen over the axis).
MAX_PANELS = 12

#: (label, b/a, Δ/a) of the marked bodies.
NAMED_BODIES = [
    ('Oloid', 1.0, 0.5),
    ('Two-Circle-Roller', 1.0, 1.0 / math.sqrt(2.0)),
    ('Fig. 3', FIGURE3[1] / FIGURE3[0], FIGURE3[2] / FIGURE3[0]),
    ('Fig. 4', FIGURE4[1] / FIGURE4[0], FIGURE4[2] / FIGURE4[0]),
]
DPI = 130
_FAMILY_LABELS = {-1: 'θ = ±π/2', 0: 'neutral', 1: 'θ = 0 and\nturning points',
                  2: 'both\n(flat vertices)'}


def _edges(values, low=None, high=None):
    """Cell edges around grid values, clipped to the grid's own range [values[0], values[-1]].

    Inner edges are the midpoints; the outer cells end at the first and last grid values, so
    nothing is drawn where nothing was computed (e.g. Δ/a below 0 or above 1). A single value
    gets a cell of ±2 % (or ±0.01), clipped to [low, high] if given.
    """
    v = np.asarray(values, dtype=float)
    if v.size == 1:
        half = max(0.02 * abs(v[0]), 0.01)
        return np.clip(np.array([v[0] - half, v[0] + half]),
                       -np.inf if low is None else low, np.inf if high is None else high)
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0]], mid, [v[-1]]])


#: ASCII of the Dataset's attributes → the symbols of the figures (whole words only)
_SYMBOLS = ((r'\+-pi/2', '±π/2'), (r'\bDelta\b', 'Δ'), (r'\btheta\b', 'θ'),
            (r'\bomega_u\b', 'ω_u'), (r'\bomega\b', 'ω'), (r'\bpi\b', 'π'), (r'\bmu\b', 'μ'),
            (r'sqrt\(', '√('), (r'\^2', '²'), (r'<=', '≤'), (r'>=', '≥'))


def symbols(text):
    """``text`` (a variable's ASCII description or unit) with the figures' symbols:
    ``theta = +-pi/2`` → ``θ = ±π/2``, ``sqrt(g/a)`` → ``√(g/a)``, ``a^2`` → ``a²``.
    Variable names such as ``theta_max`` or ``mu_required`` are kept."""
    for pattern, symbol in _SYMBOLS:
        text = re.sub(pattern, symbol, text)
    return text


def _norm_and_cmap(name, values):
    """(norm, cmap, extend, ticks) for a variable's finite values."""
    if name == 'stable_family':
        if np.any(values == 2):      # flat vertices: both families stable (exponent > 2)
            cmap = ListedColormap(['#f3b38a', '#f7f7f7', '#8db7de', '#9fd39a'])
            return (BoundaryNorm([-1.5, -0.5, 0.5, 1.5, 2.5], cmap.N),
                    cmap.with_extremes(bad='0.85'), 'neither', [-1, 0, 1, 2])
        cmap = ListedColormap(['#f3b38a', '#f7f7f7', '#8db7de']).with_extremes(bad='0.85')
        return BoundaryNorm([-1.5, -0.5, 0.5, 1.5], cmap.N), cmap, 'neither', [-1, 0, 1]
    cmap = plt.get_cmap('viridis').with_extremes(bad='0.85', over='black')
    finite = values[np.isfinite(values)]
    extend = 'max' if np.any(np.isposinf(values)) else 'neither'
    if finite.size == 0:
        return Normalize(0.0, 1.0), cmap, extend, None
    low, high = float(finite.min()), float(finite.max())
    positive = finite[finite > 0]
    if low > 0 and high / low > 20.0:
        return LogNorm(low, high), cmap, extend, None
    if name in ('barrier', 'rollover_speed') and positive.size and low >= 0 \
            and high / positive.min() > 20.0:
        return LogNorm(positive.min(), high), cmap, extend, None
    if high == low:
        low, high = low - 0.5 * max(abs(low), 1e-12), high + 0.5 * max(abs(high), 1e-12)
    return Normalize(low, high), cmap, extend, None


def exponent_plane(dataset, exponent=None):
    """The (b/a, Δ/a) plane of a sweep Dataset at ``exponent`` (default: its only one); a
    Dataset without the exponent axis (written before it existed) as it is."""
    if 'exponent' not in dataset.dims:
        return dataset
    if exponent is None:
        if dataset.sizes['exponent'] != 1:
            raise ValueError(f'the sweep has {dataset.sizes["exponent"]} exponents: name one')
        return dataset.isel(exponent=0)
    return dataset.sel(exponent=exponent)


def shown_exponents(dataset):
    """The exponents drawn in a map: all, or :data:`MAX_PANELS` evenly chosen (ends kept)."""
    if 'exponent' not in dataset.dims:
        return [None]
    values = [float(x) for x in dataset['exponent'].values]
    if len(values) <= MAX_PANELS:
        return values
    keep = np.unique(np.round(np.linspace(0, len(values) - 1, MAX_PANELS)).astype(int))
    return [values[k] for k in keep]


def plot_map(dataset, name, ax, exponent=None, norm_values=None, colorbar=True):
    """Draw variable ``name`` of a sweep Dataset on ``ax`` (the plane of ``exponent``,
    default the only one); returns the colour bar (None without ``colorbar``).

    ``norm_values`` (array) sets the colour scale (default: this plane's values): the panels
    of one map share it."""
    plane = exponent_plane(dataset, exponent)
    var = plane[name]
    n = float(plane['exponent']) if 'exponent' in plane.coords else 2.0
    b = plane['b_over_a'].values
    d = plane['delta_over_a'].values
    values = np.asarray(var.values, dtype=float)            # (b/a, Δ/a)
    norm, cmap, extend, ticks = _norm_and_cmap(
        name, values if norm_values is None else np.asarray(norm_values, dtype=float))
    shown = np.where(np.isposinf(values), np.inf, values)
    b_edges, d_edges = _edges(b, low=0.0), _edges(d, low=0.0, high=1.0)
    mesh = ax.pcolormesh(b_edges, d_edges, np.ma.masked_invalid(
        np.where(np.isposinf(shown), np.nan, shown)).T, cmap=cmap, norm=norm,
        rasterized=True)
    if np.any(np.isposinf(values)):
        over = np.ma.masked_where(~np.isposinf(values), np.ones_like(values))
        ax.pcolormesh(b_edges, d_edges, over.T,
                      cmap=ListedColormap(['black']), rasterized=True)
    bar = None
    if colorbar:
        bar = _colorbar(ax.figure, mesh, ax, name, var, extend, ticks)
    xlim = (b_edges[0], b_edges[-1])
    ylim = (d_edges[0], d_edges[-1])
    if n == 2.0:                       # the ellipse's neutral curve and named bodies
        b_line = np.linspace(max(xlim[0], 1e-9), min(xlim[1], math.sqrt(2.0)), 400)
        ax.plot(b_line, np.sqrt(np.clip(1.0 - b_line**2 / 2, 0.0, None)), color='k', lw=1.2,
                ls='--', label='neutral: b² = 2(a² − Δ²)')
        for label, x, y in NAMED_BODIES:
            inside = xlim[0] <= x <= xlim[1] and ylim[0] <= y <= ylim[1]
            if inside:
                ax.plot(x, y, 'o', mfc='white', mec='k', ms=5, zorder=4)
                ax.annotate(label, (x, y), xytext=(5, 4), textcoords='offset points',
                            fontsize=7, bbox={'boxstyle': 'round,pad=0.15', 'fc': 'white',
                                              'ec': 'none', 'alpha': 0.7})
        ax.legend(loc='lower left', fontsize=7, framealpha=0.8)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel('b / a  [1]  (a = 1)')
    ax.set_ylabel('Δ / a  [1]')
    if exponent is None:
        ax.set_title(f'{name}: {symbols(var.attrs.get("description", ""))}', fontsize=8,
                     wrap=True)
    else:
        ax.set_title(f'n = {n:g}' + (' (ellipse)' if n == 2.0 else ''), fontsize=9)
    return bar


def _colorbar(fig, mesh, ax, name, var, extend, ticks):
    bar = fig.colorbar(mesh, ax=ax, extend=extend, ticks=ticks)
    units = symbols(var.attrs.get('units', ''))
    bar.set_label(f'{name} [{units}]' + ('   (black: ∞)' if extend == 'max' else ''))
    if name == 'stable_family':
        bar.set_ticklabels([_FAMILY_LABELS[k] for k in ticks])
    return bar


def plot_panels(dataset, name):
    """A figure of variable ``name`` with one panel per exponent (:func:`shown_exponents`),
    on one colour scale; returns the figure (the caller closes it)."""
    exponents = shown_exponents(dataset)
    count = len(exponents)
    cols = min(count, 4)
    rows = math.ceil(count / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols + 1.2, 3.2 * rows + 0.8),
                             squeeze=False, constrained_layout=True)
    chosen = np.asarray(dataset[name].sel(exponent=exponents).values, dtype=float)
    try:
        for ax, n in zip(axes.flat, exponents):
            plot_map(dataset, name, ax, exponent=n, norm_values=chosen, colorbar=False)
        for ax in axes.flat[count:]:
            ax.set_visible(False)
        _, _, extend, ticks = _norm_and_cmap(name, chosen)
        mesh = axes.flat[0].collections[0]         # the first panel's values (shared norm)
        _colorbar(fig, mesh, list(axes.flat[:count]), name, dataset[name], extend, ticks)
        total = dataset.sizes['exponent']
        more = '' if total == count else f' ({count} of {total} exponents shown)'
        fig.suptitle(f'{name}: {symbols(dataset[name].attrs.get("description", ""))}{more}',
                     fontsize=9, wrap=True)
    except BaseException:
        plt.close(fig)
        raise
    return fig


def write_maps(dataset, folder):
    """One PNG per float variable of ``dataset`` into ``folder`` (created if missing).

    Existing maps are replaced (the command line checks them first); each is written
    through a temporary file renamed over it when complete.

    Returns
    -------
    list of pathlib.Path
        The files written, ``folder/NAME.png``.
    """
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, var in dataset.data_vars.items():
        if var.dtype.kind != 'f':
            continue
        panels = 'exponent' in dataset.dims and dataset.sizes['exponent'] > 1
        fig = plot_panels(dataset, name) if panels else plt.figure(figsize=(6.4, 4.6))
        try:
            if not panels:
                plot_map(dataset, name, fig.add_subplot())
            path = out / f'{name}.png'
            with replacing(path) as temporary:      # never a half-written map
                fig.savefig(temporary, dpi=DPI, bbox_inches='tight')
        finally:
            plt.close(fig)
        written.append(path)
    return written

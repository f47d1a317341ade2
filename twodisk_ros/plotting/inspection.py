"""The figure of ``twodisk-inspect --plot``: traces on the ground, height of G, energy and,
for recordings with contact forces, N_A, N_B and μ_required.

Kept apart from :mod:`twodisk_ros.inspect` so that the checks never import matplotlib.
"""

import os

import numpy as np


def plot_inspection(inspection, path):
    """Write a figure of a recording: traces on the ground, height of G, energy over time.

    Parameters
    ----------
    inspection : Inspection
    path : str or os.PathLike
        PNG file to write.

    Notes
    -----
    Uses matplotlib's object-oriented API with the Agg canvas (no pyplot, no display).  The
    left panel shows the traces of A and B and the path of G on the ground with equal aspect,
    as Figures 3-4 of the paper; on the right the height of G and the energy: from the
    recorded poses (central differences), exact E(u, u̇) from the rolling state, and the
    node's diagnostics; for a recording with contact forces, a panel of N_A/(M g), N_B/(M g)
    and μ_required against the recorded friction μ.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    data = inspection.series
    summary = inspection.summary
    params = summary['parameters'] or {}
    figure = Figure(figsize=(14, 8), layout='constrained')
    FigureCanvasAgg(figure)
    limits = _ground_limits(data)
    ratio = 1.0 if limits is None else (limits[1][1] - limits[1][0]) / (
        limits[0][1] - limits[0][0])
    forces = 't_forces' in data
    heights = (min(max(2.8 * ratio, 0.35), 1.4), 1.0) + ((0.8,) if forces else ())
    grid = figure.add_gridspec(len(heights), 3, height_ratios=heights)
    ground = figure.add_subplot(grid[0, :])
    height = figure.add_subplot(grid[1, 0])
    energy = figure.add_subplot(grid[1, 1], sharex=height)
    drift = figure.add_subplot(grid[1, 2], sharex=height)
    for role, label, style in (('contact_a', 'trace of A', dict(color='tab:red', lw=1.0)),
                               ('contact_b', 'trace of B', dict(color='tab:blue', lw=1.0)),
                               ('pose', 'path of G (projection)',
                                dict(color='k', lw=1.4, ls='--'))):
        if role in data:
            ground.plot(data[role][:, 0], data[role][:, 1], label=label, **style)
            ground.plot(data[role][:1, 0], data[role][:1, 1], 'o', color=style['color'], ms=4)
    ground.set_aspect('equal', adjustable='box')
    if limits is not None:
        ground.set_xlim(*limits[0])
        ground.set_ylim(*limits[1])
    ground.set_xlabel('X (m)')
    ground.set_ylabel('Y (m)')
    ground.set_title('on the ground, equal scales (dots: start)', loc='right')
    if 'pose' in data:
        height.plot(data['t_pose'], data['pose'][:, 2], color='k', lw=1.0)
    height.set_ylabel('z_G (m)')
    height.set_xlabel('t (s)')
    height.set_title('height of G')
    energy.set_xlabel('t (s)')
    energy.set_title('energy')
    drift.set_title('relative energy drift')
    scale = float(data['energy_scale']) if 'energy_scale' in data else None
    if 't_fd' in data:
        total = data['kinetic_fd'] + data['potential_fd']
        energy.plot(data['t_fd'], total, color='k', lw=1.2, label='E from poses (FD)')
        energy.plot(data['t_fd'], data['kinetic_fd'], color='tab:orange', lw=0.8, label='T')
        energy.plot(data['t_fd'], data['potential_fd'], color='tab:green', lw=0.8,
                    label='V = M g z_G')
        drift.plot(data['t_fd'], (total - total[0]) / scale, color='k', lw=1.0,
                   label='from poses (FD)')
    if 't_model' in data:
        exact = data['energy_model']
        energy.plot(data['t_model'], exact, color='tab:purple', lw=0.8, ls=':',
                    label='E(u, u̇) of rolling_state')
        drift.plot(data['t_model'], (exact - exact[0]) / scale, color='tab:purple', lw=0.8,
                   ls=':', label='E(u, u̇) of rolling_state')
    if 't_diagnostics' in data:
        recorded = data['energy_diagnostics']
        energy.plot(data['t_diagnostics'], recorded, 's', ms=3, color='tab:red',
                    label='diagnostics')
        if scale:
            drift.plot(data['t_diagnostics'], (recorded - recorded[0]) / scale, 's', ms=3,
                       color='tab:red', label='diagnostics')
    energy.set_ylabel('energy (J)')
    size = _body_size(params, scale)
    drift.set_ylabel('(E − E₀) / (M g L)' + (f',  L = {size:.4g} m = body size' if size
                                              else ',  L = body size'))
    drift.set_xlabel('t (s)')
    if forces:
        _force_panel(figure.add_subplot(grid[2, :], sharex=height), data)
    for axes in (ground, height, energy, drift):
        axes.grid(True, lw=0.3)
    if len(ground.lines) > 1:
        ground.legend(loc='lower left', bbox_to_anchor=(0.0, 1.0), ncol=3, fontsize='small',
                      frameon=False, borderaxespad=0.2)
    # below the panels, never over the curves
    for axes in (energy, drift):
        if len(axes.lines) > 1:
            axes.legend(loc='upper center', bbox_to_anchor=(0.5, -0.13), ncol=2,
                        fontsize='small', frameon=False)
    title = os.path.basename(summary['file'])
    if params:
        title += (f" — a = {_number(params.get('a'))} m, b = {_number(params.get('b'))} m, "
                  f"Δ = {_number(params.get('delta'))} m, {params.get('mass_model')}, "
                  f"{params.get('mode')}")
    title += ' — ' + ('all checks pass' if inspection.passed else 'CHECKS FAIL')
    if summary['truncated']:
        title += ' (truncated file)'
    figure.suptitle(title)
    figure.savefig(path, dpi=110)


def _force_panel(axes, data):
    """N_A/(M g), N_B/(M g) and, on a second axis, μ_required with the friction μ."""
    t, weight = data['t_forces'], float(data['weight'])
    axes.plot(t, data['normal_a'] / weight, color='tab:red', lw=1.0, label='N_A / W (W = M g)')
    axes.plot(t, data['normal_b'] / weight, color='tab:blue', lw=1.0, label='N_B / W')
    axes.axhline(0.0, color='k', lw=0.6)
    axes.set_ylabel('normal force / W')
    axes.set_xlabel('t (s)')
    mu = data['mu_required']
    finite = mu[mu < 1e300]
    other = axes.twinx()
    other.plot(t, mu, color='tab:green', lw=0.9, label='μ_required')
    friction = float(data['friction'])
    if friction < 1e300:
        other.axhline(friction, color='tab:green', lw=0.8, ls='--', label='μ (friction)')
    top = 1.2 * float(finite.max()) if finite.size else 1.0
    if friction < 1e300:   # around μ: what exceeds 3 μ is clipped (it slips anyway)
        top = max(min(top, 3.0 * friction), 1.5 * friction)
    other.set_ylim(0.0, top if top > 0 else 1.0)
    other.set_ylabel('μ_required, μ')
    axes.set_title('contact forces: normal forces (left axis), friction needed and available '
                   '(right axis)', fontsize='medium')
    lines = axes.get_lines()[:2] + other.get_lines()
    axes.legend(lines, [line.get_label() for line in lines], loc='upper center',
                bbox_to_anchor=(0.5, -0.18), ncol=4, fontsize='small', frameon=False)
    return axes


def _number(value):
    """A recorded parameter (text or number) with at most 6 significant digits."""
    try:
        return f'{float(value):.6g}'
    except (TypeError, ValueError):
        return str(value)


def _body_size(params, energy_scale):
    """L (m) from M g L and the recorded mass and gravity (None if unknown)."""
    try:
        gravity = float(params.get('gravity'))
        weight = float(params.get('mass')) * (gravity if gravity > 0 else 1.0)
        return energy_scale / weight if energy_scale and weight > 0 else None
    except (TypeError, ValueError):
        return None


def _ground_limits(data):
    """((x0, x1), (y0, y1)) around the traces and the path of G, or None without data."""
    points = [data[role][:, :2] for role in ('contact_a', 'contact_b', 'pose') if role in data]
    points = [p[np.all(np.isfinite(p), axis=1)] for p in points]
    points = [p for p in points if len(p)]
    if not points:
        return None
    xy = np.concatenate(points)
    low, high = xy.min(axis=0), xy.max(axis=0)
    extent = np.maximum(high - low, 1e-9)
    margin = 0.04 * extent + 0.04 * extent.min()
    return tuple((float(lo - m), float(hi + m)) for lo, hi, m in zip(low, high, margin))

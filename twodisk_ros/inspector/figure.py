"""The figure of ``twodisk-inspect --plot``: traces on the ground, height of G, energy, the
drift of the motion's invariant and, for recordings with contact forces, N_A, N_B and
μ_required, with the stretches outside the rolling model shaded.

Kept apart from :mod:`twodisk_ros.inspector` so that the checks never import matplotlib.
"""

import math
import os

import numpy as np

from ..model import palette

__all__ = ['plot_inspection', 'inspection_figure', 'invariant_drift', 'align_zeros']

#: μ_required is drawn up to this multiple of the friction μ (the rest is clipped, and said)
MU_CLIP = 3.0
#: gap between a panel and the legend below it (font sizes): clear of tick labels and x label
BELOW = 3.4
#: the shading of what fails where the rolling model does not hold
SHADES = (('lift-off', palette.INVALID, 'a contact lifts off (N < 0)'),
          ('slip', palette.SLIP, 'slip (μ_required > μ)'))


def plot_inspection(inspection, path):
    """Write :func:`inspection_figure` of a recording to ``path`` (PNG, 110 dpi)."""
    inspection_figure(inspection).savefig(path, dpi=110)


def inspection_figure(inspection):
    """The figure of a recording: traces on the ground, height of G, energy over time.

    Parameters
    ----------
    inspection : Inspection

    Returns
    -------
    matplotlib.figure.Figure
        On an Agg canvas. Its axes are labelled (``Axes.get_label()``) ``'ground'``,
        ``'height'``, ``'energy'``, ``'drift'`` and, with contact forces, ``'forces'`` and
        ``'mu'`` (the twin axis of μ).

    Notes
    -----
    Uses matplotlib's object-oriented API with the Agg canvas (no pyplot, no display).  Top:
    the traces of A and B and the path of G on the ground with equal aspect, as Figures 3-4 of
    the paper.  Middle: the height of G; the energy (from the recorded poses by central
    differences, and exact E(u, u̇) of the recorded rolling state); the drift of the
    invariant of the motion as recorded (:func:`invariant_drift`: the energy in dynamic mode,
    |ω| in kinematic mode), with the value of the inspector's finite-difference check quoted
    beside it.  Bottom, for a recording with contact forces: N_A/(M g), N_B/(M g) (left axis)
    and μ_required with the recorded friction μ (right axis, zeros aligned).  Stretches where
    the rolling model does not hold (lift-off, slip) are shaded in every panel over time.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    data = inspection.series
    summary = inspection.summary
    params = summary['parameters'] or {}
    figure = Figure(figsize=(14, 9), layout='constrained')
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
    _ground_panel(ground, data, limits)
    _height_panel(height, data, _body_size(params, data))
    _energy_panel(energy, data, params.get('mode'))
    _drift_panel(drift, inspection)
    if forces:
        _force_panel(figure.add_subplot(grid[2, :], sharex=height), data)
    stretches = _invalid_stretches(data)
    for axes in (height, energy, drift):
        _shade(axes, stretches, data)
    for axes in (ground, height, energy, drift):
        axes.grid(True, lw=0.3)
    title = os.path.basename(summary['file'])
    if params:
        shape = params.get('shape', 'ellipse')
        if shape != 'ellipse':
            title += f' — {shape}' + (f" n = {_number(params.get('exponent'))}"
                                      if shape == 'superellipse' else '')
        title += (f" — a = {_number(params.get('a'))} m, b = {_number(params.get('b'))} m, "
                  f"Δ = {_number(params.get('delta'))} m, {params.get('mass_model')}, "
                  f"{params.get('mode')}")
    verdict = getattr(inspection, 'verdict', None) or ('PASS' if inspection.passed else 'FAIL')
    title += ' — ' + {'PASS': 'PASS: all checks pass',
                      'INCOMPLETE': 'INCOMPLETE: the checks pass on the part recovered',
                      }.get(verdict, 'FAIL: checks fail')
    if summary['truncated']:
        title += ' (truncated file)'
    if stretches:
        title += (f'\nshaded: {len(stretches)} stretch(es) outside the rolling model (red: '
                  'lift-off, amber: slip): the motion shown there is not physics')
    figure.suptitle(title)
    for axes, name in ((ground, 'ground'), (height, 'height'), (energy, 'energy'),
                       (drift, 'drift')):
        axes.set_label(name)
    return figure


# -- panels --------------------------------------------------------------------------------
def _ground_panel(ground, data, limits):
    for role, label, style in (('contact_a', 'trace of A', dict(color=palette.A, lw=1.0)),
                               ('contact_b', 'trace of B', dict(color=palette.B, lw=1.0)),
                               ('pose', 'path of G (projection)',
                                dict(color=palette.G, lw=1.4, ls='--'))):
        if role in data:
            ground.plot(data[role][:, 0], data[role][:, 1], label=label, **style)
            ground.plot(data[role][:1, 0], data[role][:1, 1], 'o', color=style['color'], ms=4)
    ground.set_aspect('equal', adjustable='box')
    if limits is not None:
        ground.set_xlim(*limits[0])
        ground.set_ylim(*limits[1])
    ground.set_xlabel('X (m)')
    ground.set_ylabel('Y (m)')
    ground.set_title('on the ground, equal scales (dots: start)')
    if len(ground.lines) > 1:     # beside the panel: never over its title or the traces
        ground.legend(loc='upper left', bbox_to_anchor=(1.01, 1.0), fontsize='small',
                      frameon=False, borderaxespad=0.0)


def _height_panel(height, data, size):
    if 'pose' in data:
        z = data['pose'][:, 2]
        height.plot(data['t_pose'], z, color=palette.G, lw=1.0)
        finite = z[np.isfinite(z)]
        spread = float(np.ptp(finite)) if finite.size else 0.0
        floor = 1e-3 * (size or max(float(np.max(np.abs(finite), initial=0.0)), 1e-3))
        if finite.size and spread < floor:      # constant (TCR): a readable window around it
            middle = 0.5 * (float(finite.min()) + float(finite.max()))
            height.set_ylim(middle - 5 * floor, middle + 5 * floor)
            height.text(0.5, 0.9, f'constant within {spread:.1g} m', ha='center',
                        transform=height.transAxes, fontsize='small')
    _plain_ticks(height)
    height.set_ylabel('z_G (m)')
    height.set_xlabel('t (s)')
    height.set_title('height of G')


def _energy_panel(energy, data, mode):
    if 't_fd' in data:
        total = data['kinetic_fd'] + data['potential_fd']
        energy.plot(data['t_fd'], total, color='k', lw=1.2, label='E from poses (FD)')
        energy.plot(data['t_fd'], data['kinetic_fd'], color='tab:orange', lw=0.8, label='T')
        energy.plot(data['t_fd'], data['potential_fd'], color='tab:green', lw=0.8,
                    label='V = M g z_G')
    if 't_model' in data:
        energy.plot(data['t_model'], data['energy_model'], color='tab:purple', lw=0.8,
                    ls=':', label='E(u, u̇) of rolling_state')
    if 't_diagnostics' in data:
        energy.plot(data['t_diagnostics'], data['energy_diagnostics'], 's', ms=3,
                    color='tab:red', label='diagnostics')
    _plain_ticks(energy)
    energy.set_ylabel('energy (J)')
    energy.set_xlabel('t (s)')
    energy.set_title('energy' + (' (not conserved: the drive does work)'
                                 if mode == 'kinematic' else ''))
    if len(energy.lines) > 1:
        energy.legend(loc='upper center', bbox_to_anchor=(0.5, 0.0), ncol=2,
                      borderaxespad=BELOW, fontsize='small', frameon=False)


def _drift_panel(drift, inspection):
    """The invariant's drift as recorded, and the inspector's FD check quoted beside it."""
    found = invariant_drift(inspection)
    if found is None:
        drift.text(0.5, 0.5, 'the drift cannot be computed:\n'
                   'no phase rates recorded, or omega0 = 0',
                   ha='center', va='center', transform=drift.transAxes)
        drift.set_title('drift of the invariant')
        return
    for t, values, label, style in found['curves']:
        drift.plot(t, values, label=label, **style)
    drift.set_title(found['title'])
    _power_in_label(drift, found['ylabel'])
    drift.set_xlabel('t (s)')
    check = next((c for c in inspection.checks if c.name == found['check']), None)
    note = None   # the legend's title: the FD check quoted, then what L or |ω₀| is
    if check is not None and check.value is not None:
        tolerance = '' if check.tolerance is None else f' (tolerance {check.tolerance:.2g})'
        note = (f'the check from the poses alone (central differences) is FD-limited:\n'
                f'max {found["symbol"]} = {check.value:.2g}{tolerance}')
    note = found['definition'] if note is None else f'{note}\n{found["definition"]}'
    drift.legend(title=note, loc='upper center', bbox_to_anchor=(0.5, 0.0), ncol=1,
                 borderaxespad=BELOW, fontsize='small', title_fontsize='small', frameon=False)


def invariant_drift(inspection):
    """The drift of the motion's invariant along the recording, or None.

    Dynamic mode: (E − E₀) / (M g L) of the exact E(u, u̇) at the recorded phase u and phase
    rate u̇ of ``rolling_state`` (the integrator's drift; ~1e-15 for the table method), and of
    the energies the node reported in ``/diagnostics``. Kinematic mode (energy is not
    conserved there): (|ω| − |omega0|) / |omega0| with |ω| = |u̇| |ω_u(u)| from the recorded
    rolling state and the closed form |ω_u(u)| of the recorded body.

    Returns
    -------
    dict or None
        ``curves``: list of (t in s, values, label, line style); ``title``, ``ylabel``,
        ``symbol``, ``definition`` (of the scale in the label, e.g. L); ``check``: the name of the inspector's FD check of the same invariant.
    """
    data = inspection.series
    params = inspection.summary.get('parameters') or {}
    if params.get('mode') == 'kinematic':
        return _speed_drift(inspection, params)
    if 't_model' not in data:
        return None
    scale = float(data['energy_scale'])
    exact = data['energy_model']
    curves = [(data['t_model'], (exact - exact[0]) / scale,
               'E(u, u̇) at the recorded rolling_state (exact model, tables)',
               dict(color='tab:purple', lw=1.0))]
    if 't_diagnostics' in data and len(data['t_diagnostics']):
        reported = data['energy_diagnostics']
        curves.append((data['t_diagnostics'], (reported - exact[0]) / scale,
                       'E reported in /diagnostics', dict(ls='none', marker='s', ms=3,
                                                            color='tab:red')))
    size = _body_size(params, data)
    unit = f'L = {size:.4g} m: the body size' if size else 'L: the body size'
    return {'curves': curves, 'title': 'energy drift of the recorded state',
            'ylabel': '(E − E₀) / (M g L)', 'symbol': '|E − E₀| / (M g L)',
            'definition': unit, 'check': 'energy'}


def _speed_drift(inspection, params):
    from ..run.description import RunDescription
    run, _ = RunDescription.from_recorded(params)      # any shape, as the node built it
    state = _recorded_state(inspection)
    if run is None or state is None or not abs(run.settings.omega0) > 0:
        return None
    settings = run.settings
    t, phase, rate = state
    body = run.laminae_body         # ω_u(u) does not depend on the body's origin
    target = abs(settings.omega0)
    speed = np.abs(rate) * np.linalg.norm(body.phase_angular_velocity(phase), axis=-1)
    return {'curves': [(t, (speed - target) / target,
                        '|ω| = |u̇| |ω_u(u)| at the recorded rolling_state',
                        dict(color='tab:purple', lw=1.0))],
            'title': 'drift of |ω| (the invariant of kinematic mode)',
            'ylabel': '(|ω| − |ω₀|) / |ω₀|', 'symbol': '||ω| − |ω₀|| / |ω₀|',
            'definition': f'|ω₀| = |omega0| = {target:.4g} rad/s', 'check': 'angular_speed'}


def _recorded_state(inspection):
    """(t, u, u̇) of the recorded rolling_state, t in s like the other series; or None.

    The inspector's plot series do not carry the phase, so ``rolling_state`` is read again
    from the file (only that topic is decoded); any failure gives None (no drift drawn).
    """
    from .series import select_topics, extract_series, topic_role
    from ..recordings.reader import read_recording
    try:
        recording = read_recording(inspection.summary['file'],
                                   decode=lambda topic: topic_role(topic) == 'rolling_state')
        chosen = {role: topic for role, topic in select_topics(recording.topics, []).items()
                  if role == 'rolling_state'}
        series = extract_series(recording, chosen, []).get('rolling_state')
    except Exception:  # noqa: BLE001 - the figure is drawn without the drift
        return None
    if series is None or len(series) < 2:
        return None
    order = np.argsort(series.stamp_ns, kind='stable')
    stamps = series.stamp_ns[order]
    phase = np.unwrap(series.values['position'][order, 2])
    rate = series.values['velocity'][order, 2]
    keep = np.isfinite(rate) & np.isfinite(phase)
    if not np.any(keep):
        return None
    data = inspection.series
    first = float(data['t_model'][0]) if 't_model' in data and len(data['t_model']) else 0.0
    t = (stamps - stamps[0]) * 1e-9 + first
    return t[keep], phase[keep], rate[keep]


def _force_panel(axes, data):
    """N_A/(M g), N_B/(M g) and, on a second axis with the same zero, μ_required and μ."""
    t, weight = data['t_forces'], float(data['weight'])
    axes.plot(t, data['normal_a'] / weight, color=palette.A, lw=1.0,
              label='N_A / W (W = M g)')
    axes.plot(t, data['normal_b'] / weight, color=palette.B, lw=1.0, label='N_B / W')
    axes.axhline(0.0, color='k', lw=0.6)
    axes.set_ylabel('normal force / W')
    axes.set_xlabel('t (s)')
    mu = data['mu_required']
    finite = mu[np.isfinite(mu) & (mu < 1e300)]
    other = axes.twinx()
    axes.set_label('forces')
    other.set_label('mu')
    friction = float(data['friction'])
    peak = float(finite.max()) if finite.size else 0.0
    top = 1.15 * peak if peak > 0 else 1.0
    label = 'μ_required'
    if math.isfinite(friction) and friction > 0:
        top = max(top, 1.25 * friction)
        if peak > MU_CLIP * friction:      # what exceeds 3 μ slips anyway: clipped, and said
            top = MU_CLIP * friction
            where = float(t[np.isfinite(mu) & (mu < 1e300)][int(np.argmax(finite))])
            label += (f' (clipped at {top:.3g} = {MU_CLIP:g} μ; max {peak:.3g} at '
                      f't = {where:.3g} s)')
    if np.any(~np.isfinite(mu) | (mu >= 1e300)):
        label += '; none where a contact lifts off'
    other.plot(t, np.where(mu < 1e300, mu, np.nan), color=palette.MU, lw=0.9, label=label)
    if math.isfinite(friction):
        other.axhline(friction, color=palette.MU, lw=0.8, ls='--', label=f'μ = {friction:g} '
                      '(friction)')
    other.set_ylim(0.0, top)
    other.set_ylabel('μ_required, μ')
    align_zeros(axes, other)
    axes.set_title('contact forces: normal forces (left axis), friction needed and available '
                   '(right axis, same zero)', fontsize='medium')
    lines = axes.get_lines()[:2] + other.get_lines()
    shades = _shade(axes, _invalid_stretches(data), data)
    axes.legend(lines + shades, [item.get_label() for item in lines + shades],
                loc='upper center', bbox_to_anchor=(0.5, 0.0), borderaxespad=BELOW,
                ncol=min(4, len(lines) + len(shades)), fontsize='small', frameon=False)
    return axes


def align_zeros(left, right):
    """Set the limits of two y-axes (twins) so that y = 0 is at the same height on both.

    Each keeps its range of data: the axis whose zero sits higher has its lower limit
    extended downward. Returns the fraction of the height at which both zeros are.
    """
    (l0, l1), (r0, r1) = left.get_ylim(), right.get_ylim()
    l0, r0 = min(l0, 0.0), min(r0, 0.0)
    l1, r1 = max(l1, 0.0), max(r1, 0.0)
    if l1 <= l0 or r1 <= r0:
        return None
    fraction = max(-l0 / (l1 - l0), -r0 / (r1 - r0))
    if fraction >= 1.0:
        return None
    # zero at `fraction` of the height: lower limit = −fraction / (1 − fraction) × upper
    for axes, upper in ((left, l1), (right, r1)):
        axes.set_ylim(-fraction / (1.0 - fraction) * upper, upper)
    return fraction


def _invalid_stretches(data):
    """The stretches outside the rolling model (lift-off, slip) from the recorded forces."""
    if 't_forces' not in data:
        return []
    from .forces import invalid_stretches
    stretches = invalid_stretches(data['t_forces'], data['normal_a'], data['normal_b'],
                                  data['mu_required'], float(data['friction']))
    return stretches


def _runs(flags):
    """(first, last) indices of the runs of True in a boolean array."""
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return list(zip(np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0] - 1))


def _shade(axes, stretches, data):
    """Shade the samples outside the rolling model, half a sample step around each run.

    Lift-off (N_A < 0 or N_B < 0) in one colour, slip with both contacts down (μ_required >
    μ) in another, as :func:`~twodisk_ros.inspector.forces.invalid_stretches` classifies the
    samples. Returns one patch per kind drawn (for a legend).
    """
    if not stretches:
        return []
    t = data['t_forces']
    half = 0.5 * float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    lift = (data['normal_a'] < 0) | (data['normal_b'] < 0)
    flags = {'lift-off': lift, 'slip': ~lift & (data['mu_required'] > float(data['friction']))}
    drawn = []
    for kind, colour, label in SHADES:
        for k, (first, last) in enumerate(_runs(flags[kind])):
            patch = axes.axvspan(t[first] - half, t[last] + half, color=colour, alpha=0.5,
                                 lw=0, zorder=0, label=label)
            if k == 0:
                drawn.append(patch)
    return drawn


# -- helpers -------------------------------------------------------------------------------
def _plain_ticks(axes):
    """Plain tick labels on y: no offset such as '1e-13+7.07e-2' above the axis."""
    axes.ticklabel_format(axis='y', useOffset=False, style='plain')


def _power_in_label(axes, label):
    """y tick labels as plain numbers, their power of ten in the axis label ``label``.

    Matplotlib's own scientific format writes it as '1e-15' above the axis, where it runs
    into the panel's title; here the label reads ``... [×10⁻¹⁵]`` (tick value × 10⁻¹⁵ = the
    quantity). Values within 1e-3 … 1e4 keep plain ticks and the bare label.
    """
    from matplotlib.ticker import FuncFormatter
    low, high = axes.get_ylim()
    peak = max(abs(low), abs(high))
    exponent = math.floor(math.log10(peak)) if math.isfinite(peak) and peak > 0 else 0
    if -3 <= exponent <= 3:
        _plain_ticks(axes)
        axes.set_ylabel(label)
        return
    scale = 10.0 ** exponent
    axes.yaxis.set_major_formatter(FuncFormatter(
        lambda value, _: f'{value / scale:.6g}'.replace('-', '\u2212')))
    axes.set_ylabel(f'{label}  [×10$^{{{exponent}}}$]')


def _number(value):
    """A recorded parameter (text or number) with at most 6 significant digits."""
    try:
        return f'{float(value):.6g}'
    except (TypeError, ValueError):
        return str(value)


def _body_size(params, data):
    """L (m) from M g L and the recorded mass and gravity (None if unknown)."""
    energy_scale = float(data['energy_scale']) if 'energy_scale' in data else None
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

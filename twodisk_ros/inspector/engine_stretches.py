"""Engine stretches of a ``contact_model:=hybrid`` recording (issue 31), checked on their own.

The node publishes an event ``contact_model engine: <reason>`` stamped with the first sample
MuJoCo's free body gives, and ``contact_model rolling: <reason>`` with the first sample of
exact rolling again. The samples between are not the rolling model's: the rolling checks
leave them out (:func:`split_series`), and :func:`engine_check` checks what the free body
with unilateral contacts and Coulomb friction must satisfy, from the recorded wrenches and
contact points:

* unilateral: the ground only pushes, N = F·n ≥ 0 at each disk (n the ground's normal: e_z,
  on a slope β the recorded ``ground_normal`` (sin β, 0, cos β); the forces and points are
  taken to the slope frame, R_y(β)ᵀ p, the tangential part is the rest);
* Coulomb: |F_tangential| ≤ μ N (μ the recorded ``friction``), to 1e-6 of M g (MuJoCo's
  solver meets its elliptic cone to its tolerance; a disk's total of several contact forces
  inside the cone is inside it too);
* no contact point deeper below the ground than its landing allows (:func:`depth_bounds`):
  δ0 + c τ v_max, δ0 = 1e-2 of the body's size (the sink under a sustained load: G 1.4e-5 m at
  rest; a recorded point 1.9e-4 m deep, half the 3.9e-4 m penetration, where the oloid rocked
  on rim A alone after a 3 N m spin-up), τ the soft contact's
  time constant and c = f(ζ) dmax / (2 d0) (:func:`~twodisk_ros.engine.model.
  landing_depth_factor`: a landing at normal speed v sinks by v τ f(ζ); the recorded point is
  MuJoCo's contact point, midway between the surfaces, so half as deep), v_max the fastest
  any body point can move with the kinetic energy the recording holds in the 10 τ before
  the sample (:func:`approach_speed_bound`).

  Why not the approach speed itself: the recording has no velocities, and its samples (100
  Hz) do not resolve a landing that lasts a few τ: the contact point's height differences
  gave 0.12 m/s before a touchdown at 3.5 m/s. The energy bound does hold, loosely (the spin
  about the normal counts too): for the oloid after a 3 N m spin-up v_max was 2.5–4.6 × the
  touchdown's normal speed at the landings deeper than 1 mm (8.7 against 3.5 m/s, 33
  against 9.2), and a landing's deepest sample used 15–25 % of its c τ v_max. The drive's
  work between the last sample and the touchdown is not counted (0.8 J of the 4.6 J at the
  3.5 m/s landing under 3 N m: v_max 9 % short of the energy's, inside that margin).
"""

from dataclasses import replace
import math

import numpy as np

from ..engine.model import IMPEDANCE, ContactParameters, landing_depth_factor
from .results import Check

__all__ = ['ENGINE_EVENT', 'RESTART_EVENTS', 'ROLLING_EVENT', 'approach_speed_bound',
           'contact_parameters', 'depth_bounds', 'engine_check', 'engine_intervals',
           'recorded_energies', 'rolling_starts', 'split_series', 'starts_anew']

ENGINE_EVENT = 'contact_model engine:'
ROLLING_EVENT = 'contact_model rolling:'
#: events after which the motion starts anew from a rolling state (the node's texts)
RESTART_EVENTS = ('reset', 'restart')
#: roles sampled at the node's rate (the rest, e.g. diagnostics and paths, are kept whole)
_PER_SAMPLE = ('pose', 'contact_a', 'contact_b', 'rolling_state', 'wrench_a', 'wrench_b')
CONE_TOLERANCE = 1e-6      #: of M g: the engine's friction cone
DEPTH_TOLERANCE = 1e-2     #: of the body's size: δ0, contact points below the ground
LANDING_WINDOW = 10.0      #: time constants: a landing's depth after them is < 5e-4 v τ


def starts_anew(text):
    """Whether the event ``text`` starts the motion anew from a rolling state: ``reset``
    (scene_control) or ``restart`` (a parameter change that rebuilds the motion, the node's
    roller.py); neither announces its first rolling stretch."""
    return text.split(' ', 1)[0] in RESTART_EVENTS


def rolling_starts(events):
    """Stamps (int ns) where exact rolling starts from a new state: a ``contact_model
    rolling`` event (the engine's state mapped back), ``reset`` or ``restart``: the energy
    check's E0 is taken again there."""
    return [int(stamp) for stamp, text in events
            if text.startswith(ROLLING_EVENT) or starts_anew(text)]


def engine_intervals(events):
    """[(first stamp, end stamp or None)] (int ns) of the engine stretches: from a
    ``contact_model engine`` event to the next ``contact_model rolling``, ``reset`` or
    ``restart`` event (excluded)."""
    intervals, start = [], None
    for stamp, text in events:
        if text.startswith(ENGINE_EVENT) and start is None:
            start = int(stamp)
        elif (text.startswith(ROLLING_EVENT) or starts_anew(text)) and start is not None:
            intervals.append((start, int(stamp)))
            start = None
    if start is not None:
        intervals.append((start, None))
    return intervals


def _inside(stamps, intervals):
    inside = np.zeros(len(stamps), dtype=bool)
    for start, end in intervals:
        inside |= (stamps >= start) & (True if end is None else stamps < end)
    return inside


def _masked(series, keep):
    values = {key: np.asarray(value)[keep] for key, value in series.values.items()}
    return replace(series, stamp_ns=series.stamp_ns[keep], log_ns=series.log_ns[keep],
                   publish_ns=series.publish_ns[keep], values=values)


def split_series(series, intervals):
    """(rolling series, engine series): the per-sample roles' messages outside and inside
    the engine stretches (the other roles whole in the first, absent in the second)."""
    rolling, engine = dict(series), {}
    for role in _PER_SAMPLE:
        if role in series and len(series[role]):
            inside = _inside(series[role].stamp_ns, intervals)
            rolling[role] = _masked(series[role], ~inside)
            engine[role] = _masked(series[role], inside)
    return rolling, engine


def contact_parameters(parameters):
    """(τ s, ζ, d0, dmax, source) of the engine's soft contact from the recording's metadata
    (``engine_time_constant``, ``engine_damping_ratio``, ``engine_impedance``); a recording
    made before they were recorded ran the defaults (the node never set them): source says
    which."""
    default = ContactParameters()
    try:
        impedance = parameters['engine_impedance'].split()
        values = (float(parameters['engine_time_constant']),
                  float(parameters['engine_damping_ratio']),
                  float(impedance[0]), float(impedance[1]))
        if all(math.isfinite(x) and x > 0 for x in values) and values[2] <= values[3] < 1:
            return (*values, 'recorded')
    except (KeyError, ValueError, IndexError, AttributeError):
        pass
    return (default.time_constant, default.damping_ratio, IMPEDANCE[0], IMPEDANCE[1],
            'not recorded: the engine defaults')


def approach_speed_bound(kinetic, mass, inertia, reach):
    """The fastest speed (m/s) any point within ``reach`` (m) of G can have with kinetic
    energy ``kinetic`` (J, array): |v_G + ω × r| ≤ |v_G| + |ω| ρ with ½ M v_G² + ½ I_min ω²
    ≤ T, largest at √(2 T (1/M + ρ²/I_min)) (Cauchy–Schwarz; M kg, I_min the smallest
    principal moment about G, kg m²)."""
    i_min = float(np.min(np.linalg.eigvalsh(np.asarray(inertia, dtype=float))))
    return np.sqrt(2.0 * np.maximum(kinetic, 0.0) * (1.0 / mass + reach * reach / i_min))


def recorded_energies(engine, model, slope, to_slope):
    """(stamps ns, E J, V J) of the engine samples with a pose and a rolling_state: E the
    energy the published nearest rolling state keeps (½ m(u) u̇² + V(u) cos β: the engine's,
    hybrid.py), V = M g cos β × G's height over the ground, so T = E − V."""
    state, pose = engine.get('rolling_state'), engine.get('pose')
    if model is None or state is None or pose is None or not len(state) or not len(pose):
        return None
    stamps, k, j = np.intersect1d(state.stamp_ns, pose.stamp_ns, return_indices=True)
    u = np.asarray(state.values['position'], dtype=float)[k, 2]
    u_dot = np.asarray(state.values['velocity'], dtype=float)[k, 2]
    dynamics, cos = model.dynamics, math.cos(slope)
    potential = dynamics.potential(np.mod(u, 2 * math.pi))
    energy = dynamics.energy(u, u_dot) + (cos - 1.0) * potential
    height = (np.asarray(pose.values['position'], dtype=float)[j] @ to_slope.T)[:, 2]
    ok = np.isfinite(energy) & np.isfinite(height)
    return stamps[ok], energy[ok], dynamics.mass.mass * dynamics.gravity * cos * height[ok]


def depth_bounds(stamps, engine, model, parameters, size, slope, to_slope, energies=None):
    """(bound m per contact sample at ``stamps`` ns, one line on it): δ0 + c τ v_max with
    δ0 = DEPTH_TOLERANCE × size, c = f(ζ) dmax / (2 d0) (module docstring) and v_max of
    :func:`approach_speed_bound` with T ≤ max E − min V over the samples from the last one
    before ``LANDING_WINDOW`` τ ahead of the sample to it (a landing's touchdown in that
    window starts from such a state; gravity's work on the way is in min V). Without the
    rolling_state or poses (or a model) the bound is δ0. ``energies``: what
    :func:`recorded_energies` gives for these arguments, if already computed."""
    tau, zeta, d0, dmax, source = contact_parameters(parameters)
    c = 0.5 * landing_depth_factor(min(max(zeta, 1e-3), 10.0)) * dmax / d0
    floor = DEPTH_TOLERANCE * size
    found = (recorded_energies(engine, model, slope, to_slope) if energies is None
             else energies)
    if found is None or not len(found[0]):
        return np.full(len(stamps), floor), (f'{DEPTH_TOLERANCE:g} of the size (no engine '
                                             f'energies recorded for a landing bound)')
    times, energy, potential = found
    window = int(round(LANDING_WINDOW * tau * 1e9))
    first = np.maximum(np.searchsorted(times, stamps - window) - 1, 0)
    last = np.searchsorted(times, stamps, side='right')
    kinetic = np.array([np.max(energy[a:b]) - np.min(potential[a:b]) if b > a else 0.0
                        for a, b in zip(first, last)])
    mass = model.dynamics.mass
    speed = approach_speed_bound(kinetic, mass.mass, mass.inertia, model.body.size)
    return floor + c * tau * speed, (
        f'{DEPTH_TOLERANCE:g} of the size + c tau v_max (c = f(zeta) dmax / (2 d0) = {c:.4g}, '
        f'tau = {tau:g} s, zeta = {zeta:g}, {source}; v_max from the kinetic energy)')


def engine_check(engine, intervals, parameters, weight, size, model=None):
    """The ``engine_stretches`` check (module docstring): the worst violation / M g or
    / size; None if there are no engine stretches. ``model``: the recording's
    :class:`~twodisk_ros.inspector.model.RecordedModel` (None: the depth bound is δ0 alone)."""
    if not intervals:
        return None
    mu = float(parameters.get('friction', 'inf'))
    slope = float(parameters.get('slope', 0.0))
    c, s = math.cos(slope), math.sin(slope)
    to_slope = np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])    # R_y(β)ᵀ

    def ground(values):
        values = np.asarray(values, dtype=float)
        return values @ to_slope.T if slope else values

    worst, where, count = 0.0, '', 0
    said, closest = f'{DEPTH_TOLERANCE:g} of the size', None
    energies = recorded_energies(engine, model, slope, to_slope)     # both disks' bounds
    for disk in 'ab':
        wrench, point = engine.get('wrench_' + disk), engine.get('contact_' + disk)
        if wrench is not None and len(wrench):
            force = ground(wrench.values['force'])
            normal = force[:, 2]
            tangential = np.linalg.norm(force[:, :2], axis=1)
            cone = tangential - (mu * np.maximum(normal, 0) if math.isfinite(mu) else np.inf)
            for name, excess in ((f'N_{disk.upper()} < 0', -normal / weight),
                                 (f'|F_t| > mu N at {disk.upper()}',
                                  cone / weight - CONE_TOLERANCE)):
                i = int(np.argmax(excess))
                count = max(count, len(excess))
                if excess[i] > worst:
                    worst, where = float(excess[i]), f'{name} at stamp {wrench.stamp_ns[i]}'
        if point is not None and len(point):
            bound, said = depth_bounds(point.stamp_ns, engine, model, parameters, size, slope,
                                       to_slope, energies)
            deep = -ground(point.values['point'])[:, 2]
            depth = (deep - bound) / size
            j = int(np.argmax(deep / bound))
            if deep[j] > 0 and (closest is None or deep[j] / bound[j] > closest[0]):
                closest = (deep[j] / bound[j], f'contact {disk.upper()} {deep[j]:.3g} m deep at '
                                               f'stamp {point.stamp_ns[j]}, {bound[j]:.3g} m allowed')
            i = int(np.argmax(depth))
            if depth[i] > worst:
                worst, where = float(depth[i]), (
                    f'contact {disk.upper()} {deep[i]:.3g} m below the ground at stamp '
                    f'{point.stamp_ns[i]} (its landing allows {bound[i]:.3g} m)')
    spans = ', '.join(f'{start} … {"end" if end is None else end}' for start, end in intervals)
    detail = [f'{len(intervals)} engine stretch(es) (stamps, ns: {spans}), {count} samples, '
              f'left out of the rolling checks',
              f'unilateral N >= 0, Coulomb |F_t| <= mu N (mu = {mu:g}) to {CONE_TOLERANCE:g} '
              f'M g, contact points no deeper than {said}']
    if closest is not None:
        detail.append(f'closest to its depth bound: {closest[1]} ({100 * closest[0]:.0f} %)')
    if where:
        detail.append(f'worst: {where}')
    return Check('engine_stretches', 'MuJoCo stretches: unilateral contacts, Coulomb '
                 'friction, nothing through the ground', worst <= 0.0, max(worst, 0.0), 0.0,
                 '', detail)

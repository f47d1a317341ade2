"""The bodies and initial states of the benchmark.

Every initial state is a (θ0, branch, ω0) triple as taken by ``twodisk_ros.physics.simulate``;
the reference maps it to its own phase with its own formulas.
"""

from dataclasses import dataclass
import math

import numpy as np

from reference import ReferenceBody

MASS = 1.0          # kg (the results are relative, the mass drops out)
GRAVITY = 9.81      # m/s²
TARGET_CYCLE = 1.0  # s: rolling-over and kinematic states take about this long per cycle

#: name -> (a, b, Δ, label)
BODIES = {
    'oloid': (1.0, 1.0, 0.5, 'Oloid (1, 1, 0.5)'),
    'two_circle_roller': (1.0, 1.0, 1.0 / math.sqrt(2.0), 'Two-Circle-Roller (1, 1, 1/√2)'),
    'figure3': (2.0, 1.0, 1.0, "Figure 3's body (2, 1, 1)"),
    'extreme': (1.0, 0.05, 0.02, 'Extreme body (1, 0.05, 0.02)'),
}


@dataclass(frozen=True)
class Scenario:
    body: str        #: key of BODIES
    kind: str        #: 'rolling' (dynamic, over the top), 'oscillating' (dynamic), 'kinematic'
    mode: str        #: simulate's mode
    theta0: float    #: rad
    branch: int
    omega0: float    #: rad/s (signed body angular speed; held constant in kinematic mode)
    phase0: float    #: the reference's phase at t = 0 (rad)
    phase_rate0: float  #: the reference's ṡ at t = 0 (rad/s)
    span: float      #: simulated seconds of the work-precision runs
    note: str = ''

    @property
    def key(self):
        return f'{self.body}/{self.kind}'


def _theta_of_phase(rb, s):
    """θ of phase s (tan θ = (b/a) tan η, η = η_max sin s)."""
    eta = rb.eta_max * math.sin(s)
    return math.atan2(rb.b * math.sin(eta), rb.a * math.cos(eta))


#: simulated seconds of the work-precision runs (the direct method costs ~1-5 ms per RHS call
#: here, so spans are short); 'oscillating': None = ~1.3 small-oscillation periods, 2-5 s
SPANS = {
    'default': {'rolling': 2.0, 'oscillating': None, 'kinematic': 2.0},
    'extreme': {'rolling': 0.6, 'oscillating': 0.5, 'kinematic': 1.0},
}


def scenarios(scale=1.0):
    """All scenarios; ``scale`` multiplies every span (a quick run uses < 1)."""
    result = []
    grid = np.linspace(0.0, 2 * math.pi, 4097)[:-1]
    for name, (a, b, d, _) in BODIES.items():
        spans = SPANS.get(name, SPANS['default'])
        span_rolling, span_kinematic = scale * spans['rolling'], scale * spans['kinematic']
        rb = ReferenceBody(a, b, d, MASS, GRAVITY)
        m_grid, v_grid, w_grid = _mechanics_grid(rb, grid)
        v_min, v_max = float(v_grid.min()), float(v_grid.max())
        # rolling over the top from θ = 0 (branch +1), kinetic margin ≥ the potential range
        s0 = 0.0
        m0, v0, w0 = float(m_grid[0]), float(v_grid[0]), float(w_grid[0])
        mean_rate = 2 * math.pi / TARGET_CYCLE
        margin = max(v_max - v_min, 0.5 * float(np.mean(m_grid)) * mean_rate ** 2)
        sd0 = math.sqrt(2 * (v_max + margin - v0) / m0)
        result.append(Scenario(name, 'rolling', 'dynamic', 0.0, 1, sd0 * w0, s0, sd0,
                               span_rolling))
        # oscillation: at rest halfway (in phase) between the stable equilibrium of the
        # branch-+1 half cycle and the next maximum of V
        if v_max - v_min > 1e-9 * MASS * GRAVITY * a:
            k_min = int(np.argmin(np.where(grid < math.pi / 2, v_grid, np.inf)))
            s_eq = float(grid[k_min])
            s_osc = 0.5 * (s_eq + math.pi / 2)
            theta0 = _theta_of_phase(rb, s_osc)
            s_back = rb.phase_from_theta(theta0, 1)
            v_start = rb.potential(s_back)
            barrier = min(rb.potential(0.0), rb.potential(math.pi / 2))
            assert v_start < barrier, (name, v_start, barrier)
            period = 2 * math.pi * math.sqrt(
                rb.effective_mass(s_eq) / _curvature(rb.potential, s_eq))
            span = scale * (spans['oscillating'] or min(5.0, max(2.0, round(1.3 * period, 1))))
            result.append(Scenario(name, 'oscillating', 'dynamic', theta0, 1, 0.0, s_back, 0.0,
                                   span, f'small-oscillation period {period:.3g} s'))
        # kinematic mode: constant |ω| giving about one cycle per TARGET_CYCLE
        omega = float(np.mean(w_grid)) * mean_rate
        result.append(Scenario(name, 'kinematic', 'kinematic', 0.0, 1, omega, 0.0,
                               omega / w0, span_kinematic))
    return result


def _mechanics_grid(rb, s):
    m, v, omega = rb.mechanics(s, 0)
    w = np.sqrt(sum(x.c[0] ** 2 for x in omega))
    return m.c[0], v.c[0], w


def _curvature(f, x, h=1e-3):
    return (-f(x + 2 * h) + 16 * f(x + h) - 30 * f(x) + 16 * f(x - h) - f(x - 2 * h)) / (
        12 * h * h)

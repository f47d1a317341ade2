"""The names of a sweep's output: its variables with units and descriptions, the flags of
``stable_family`` and the mass models. Plain data (no numpy, no physics), so that the command
line checks a request and a client lays out and reads a sweep without importing what the
workers compute with (:mod:`~twodisk_ros.sweep.quantities`, scipy and the physics).
"""

__all__ = ['VARIABLES', 'FAMILIES', 'MASS_MODELS', 'GENERAL_FAMILIES', 'GENERAL_MEANINGS']

MASS_MODELS = ('laminae', 'solid')

#: name → (units, description), in the order of the output; units with a = g = M = 1.
VARIABLES = {
    'theta_max': ('rad', 'largest contact angle |theta| on a disk (turning point of theta)'),
    'stability_margin': ('a^2', 'b^2 - 2 a^2 + 2 Delta^2: > 0 theta = 0 stable, < 0 '
                                'theta = +-pi/2 stable, 0 neutral'),
    'stable_family': ('1', 'which equilibria are stable: +1 theta = 0 and the turning points, '
                           '-1 theta = +-pi/2, 0 neutral (height of G constant)'),
    'height_min': ('a', 'lowest height of the centre of mass G over a cycle'),
    'height_max': ('a', 'highest height of the centre of mass G over a cycle'),
    'barrier': ('a', 'potential barrier per unit weight: height_max - height_min, the rise '
                     'of G from the stable equilibrium to the highest unstable one'),
    'rollover_speed': ('sqrt(g/a)', 'angular speed |omega| at the stable equilibrium that '
                                    'just carries the body over the barrier: '
                                    '1/2 m(u*) du/dt^2 = M g barrier, |omega| = |omega_u(u*)| '
                                    'du/dt (0 when neutral)'),
    'oscillation_period': ('sqrt(a/g)', 'period of small oscillations about the stable '
                                        'equilibrium, 2 pi sqrt(m(u*) / V\'\'(u*)) '
                                        '(NaN when neutral)'),
    'cycle_advance': ('a', 'distance the body (G) advances per rolling cycle, '
                           '|displacement.shift|'),
    'cycle_heading': ('rad', 'turn of the heading per rolling cycle, displacement.turn '
                             '(2 pi: the body rolls straight on average)'),
    'cycle_time': ('sqrt(a/g)', 'duration of one cycle at the kinematic speed |omega| = 1 '
                                'sqrt(g/a): integral of |omega_u| du over one cycle'),
    'contact_length_min': ('a', 'shortest distance |AB| between the contact points over a '
                                'cycle'),
    'contact_length_max': ('a', 'longest distance |AB| between the contact points over a '
                                'cycle'),
    'liftoff_speed': ('sqrt(g/a)', 'kinematic angular speed |omega| above which a contact '
                                   'lifts off (inf: never; 0: already at rest)'),
    'mu_required': ('1', 'friction coefficient needed to roll without slipping at the '
                         'reference kinematic speed, max over a cycle (inf above the lift-off '
                         'speed)'),
}

#: stable_family value → the stable equilibria.
FAMILIES = {1: 'theta=0 and turning points', -1: 'theta=+-pi/2', 0: 'neutral'}

#: stable_family value → the stable equilibria, on the general path (2: both families).
GENERAL_FAMILIES = {1: 'theta=0 and turning points', -1: 'theta=+-pi/2', 0: 'neutral',
                    2: 'both (flat vertices)'}

#: name → what the variable means on the per-body path (exponent n != 2), where it differs.
GENERAL_MEANINGS = {
    'stability_margin': 'exponent != 2: NaN. b^2 - 2 a^2 + 2 Delta^2 is the ellipse criterion; '
                        'for n > 2 the vertices are flat (zero curvature) and no quadratic '
                        'criterion exists: stable_family says which symmetric equilibria are '
                        'stable',
    'stable_family': 'exponent != 2: from the closed-form stability of the symmetric '
                     'equilibria of any lamina: +1 theta = 0 and the turning points, -1 the '
                     'side vertices (theta = +-pi/2), 2 both (flat vertices, n > 2), 0 neutral, '
                     'NaN neither',
    'barrier': 'exponent != 2: height_max - height_min over every equilibrium of the cycle '
               '(the deepest well to the highest equilibrium)',
    'oscillation_period': 'exponent != 2: the dynamics\' period about the lowest stable '
                          'equilibrium; NaN where it has none: on a flat vertex (n > 2) V is '
                          'not twice differentiable, the period depends on the amplitude',
    'rollover_speed': 'exponent != 2: sqrt(2 M g barrier / I_AB), I_AB the moment of inertia '
                      'about the contact line AB at the lowest stable equilibrium (the n = 2 '
                      'definition without the phase rate omega_u, which vanishes at flat '
                      'vertices)',
}

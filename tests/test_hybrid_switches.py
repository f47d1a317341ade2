"""The switch events and the switch count of contact_model:=hybrid (issue 31,
twodisk_ros/run/hybrid_simulation.py), on stretches laid out by hand at a low sample rate (no
engine, no ROS): the expected indices are read off the layout below.

Samples every 10 ms from 0 s (index k at t = k / 100 s). Stretches: rolling [0, 0.1), engine
[0.1, 0.135) (samples 11-13; 10 is still rolling: the switch is just after it), rolling
[0.135, 0.138) (no sample), engine [0.138, 0.17) (samples 14-16), rolling from 0.17 (17 on).
"""

import math
from types import SimpleNamespace

import numpy as np

from twodisk_ros.run.hybrid import Stretch
from twodisk_ros.run.hybrid_simulation import HybridSimulation

T = np.arange(20) / 100.0
STRETCHES = [Stretch('rolling', 0.0, 0.1, 'r0'), Stretch('engine', 0.1, 0.135, 'e1'),
             Stretch('rolling', 0.135, 0.138, 'r2'), Stretch('engine', 0.138, 0.17, 'e3'),
             Stretch('rolling', 0.17, math.inf, 'r4')]
ENGINE = np.array([11 <= k <= 16 for k in range(len(T))])


def _simulation():
    """A HybridSimulation holding only what switches and the switch count read."""
    simulation = object.__new__(HybridSimulation)
    simulation.hybrid = SimpleNamespace(stretches=STRETCHES)
    simulation.announced = 1
    return simulation


def _sample():
    return SimpleNamespace(t=T, hybrid=SimpleNamespace(engine=ENGINE))


def test_a_stretch_without_samples_is_announced_at_the_next_sample_in_order():
    found = _simulation().switches(_sample(), 0, len(T))
    assert [j for j, _ in found] == [11, 14, 14, 17]
    texts = [text for _, text in found]
    assert texts[0] == 'contact_model engine: e1' and texts[2] == 'contact_model engine: e3'
    assert texts[1].startswith('contact_model rolling: r2 (ended at t = 0.138 s, before any '
                               'sample')
    assert texts[3] == 'contact_model rolling: r4'


def test_switches_split_over_emitted_pieces_publish_each_sample_once():
    """The node's _emit loop: each switch splits the piece; the pieces must tile [0, n)."""
    simulation, sample = _simulation(), _sample()
    published, events = [], []
    for start, stop in ((0, 5), (5, 12), (12, 15), (15, 20)):
        for j, text in simulation.switches(sample, start, stop):
            assert start <= j < stop
            published.extend(range(start, j))
            start = j
            events.append(j)
        published.extend(range(start, stop))
    assert published == list(range(len(T)))
    assert events == [11, 14, 14, 17]


def test_diagnostics_count_the_switches_by_the_sample_time():
    """/diagnostics' ``switches`` at engine samples 12 (t = 0.12 s: one switch so far) and
    15 (t = 0.15 s: three), though all four stretches after the first are known already."""
    simulation = _simulation()
    simulation.settings = SimpleNamespace(friction=0.5)
    n = len(T)
    sample = SimpleNamespace(t=T, hybrid=SimpleNamespace(
        engine=ENGINE, touching=np.ones((n, 2), dtype=bool), normal_a=np.ones(n),
        normal_b=np.ones(n)))
    counts = [dict(simulation.contact_status(sample, i)[2])['switches'] for i in (12, 15)]
    assert counts == [1, 3]


#: a hybrid recording's events (stamps ns): engine stretches ended by a reset, a restart and
#: a return to rolling; a pause is no end
EVENTS = [(10, 'contact_model engine: slip at t = 0.1 s'), (15, 'pause'), (20, 'reset'),
          (30, 'contact_model engine: lift-off of A at t = 0.3 s'), (40, 'restart'),
          (45, 'scene damping 0.0 -> 0.01'), (50, 'contact_model engine: slip at t = 0.5 s'),
          (60, 'contact_model rolling: rolling again at t = 0.6 s'),
          (70, 'contact_model engine: slip at t = 0.7 s')]


def test_a_reset_or_restart_ends_an_engine_stretch_for_the_inspector():
    from twodisk_ros.inspector.engine_stretches import engine_intervals
    assert engine_intervals(EVENTS) == [(10, 20), (30, 40), (50, 60), (70, None)]


def test_the_energy_check_starts_again_at_a_reset_restart_or_return():
    from twodisk_ros.inspector import engine_stretches
    assert engine_stretches.rolling_starts(EVENTS) == [20, 40, 60]      # E0 again at each

"""The one sample schedule of the node and twodisk-view, against exact rational arithmetic.

Sample k at t = k / rate is stamped T0 + round(k × 1e9 / rate) ns; a run of ``duration`` s
ends at tick ⌊duration × rate⌋. References: Python's Fraction of the decimal values as typed
(no float rounding), and the stamps of a real recording (5 s at 100 Hz holds 501 samples).
"""

from fractions import Fraction

import numpy as np
import pytest

from twodisk_ros.run import schedule
from twodisk_ros.run.parameters import DEFAULTS
from twodisk_ros.view.sources import LiveSource

T0 = 1_795_669_634_697_440_220


@pytest.mark.parametrize('rate', ['1', '100', '250', '1000', '1024', '0.5', '1e5'])
def test_stamps_are_the_exact_rounded_times(rate):
    ticks = np.array([0, 1, 2, 7, 999, 123_456, 10**9])
    exact = [T0 + round(Fraction(int(k)) * 10**9 / Fraction(rate)) for k in ticks]
    got = schedule.stamps(T0, ticks, float(rate))
    assert got.dtype == np.int64 and got.tolist() == exact


@pytest.mark.parametrize('duration, rate', [('5', '100'), ('0.29', '100'), ('0.3', '10'),
                                            ('0.7', '10'), ('60', '1000'), ('0.1', '30'),
                                            ('0.001', '1000'), ('1.005', '200')])
def test_last_tick_is_the_floor_of_the_exact_product(duration, rate):
    # 0.29 × 100 is 28.999999999999996 in floats: the run still ends at tick 29
    exact = int(Fraction(duration) * Fraction(rate))
    assert schedule.last_tick(float(duration), float(rate)) == exact


def test_zero_duration_runs_until_stopped():
    assert schedule.last_tick(0.0, 100.0) is None


def test_the_view_samples_on_the_node_schedule():
    settings = DEFAULTS.with_values(rate=1000.0, duration=0.29).checked()
    source = LiveSource(settings)
    source.start(T0)
    ticks = np.arange(source.last_tick + 1)
    assert source.last_tick == 290
    assert source.stamps(ticks).tolist() == [T0 + int(k) * 1_000_000 for k in ticks]

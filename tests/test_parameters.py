"""The parameter contract is the one source: README, descriptors and the inspector agree with it."""

from pathlib import Path
import re

import pytest

from twodisk_ros.run.parameters import (DEFAULTS, PARAMETERS, RollerSettings, markdown_table,
                                         parse_recorded)

README = Path(__file__).resolve().parents[1] / 'README.md'


def test_readme_table_is_the_contract():
    text = README.read_text(encoding='utf-8')
    block = re.search(r'<!-- parameters:begin -->\n(.*?)\n<!-- parameters:end -->', text, re.S)
    assert block, 'README lacks the generated parameter table'
    assert block.group(1).strip() == markdown_table()


def test_settings_fields_are_the_contract_in_order():
    assert [p.name for p in PARAMETERS] == list(DEFAULTS.__dataclass_fields__)
    assert all(getattr(DEFAULTS, p.name) == p.default for p in PARAMETERS)
    assert DEFAULTS.checked() is DEFAULTS


def test_recorded_strings_round_trip():
    settings = DEFAULTS.with_values(a=0.2, b=0.3, delta=0.07, mode='kinematic', branch=-1,
                                    realtime=False, duration=3.5, mass_model='custom',
                                    principal_moments=[0.1, 0.2, 0.1], frame_id='odom')
    parsed, problems = parse_recorded(settings.as_strings())
    assert problems == [] and parsed == settings


@pytest.mark.parametrize('changes, words', [
    (dict(delta=0.2), 'delta/a'),
    (dict(b=0.0005), 'b/a'),
    (dict(theta0=3.0), 'theta_max'),
    (dict(omega0=2000.0), 'omega0'),
    (dict(gravity=1e-300), 'gravity'),
    (dict(realtime=False, duration=0.0), 'duration'),
    (dict(frame_id=''), 'frame_id'),
    (dict(mass_model='custom', principal_moments=[1.0, 1.0, 3.0]), 'triangle'),
])
def test_invalid_combinations_are_one_line_errors(changes, words):
    with pytest.raises(ValueError) as error:
        DEFAULTS.with_values(**changes).checked()
    assert words in str(error.value) and '\n' not in str(error.value)


def test_recorded_parameters_outside_the_contract_are_problems():
    strings = DEFAULTS.as_strings()
    strings['omega0'] = '1e155'
    settings, problems = parse_recorded(strings)
    assert settings is None and any('omega0' in p for p in problems)


def test_descriptors_follow_the_contract():
    pytest.importorskip('rclpy')
    from twodisk_ros.node.descriptors import descriptor as _descriptor
    for p in PARAMETERS:
        d = _descriptor(p)
        assert d.read_only == p.read_only
        assert p.description in d.description and p.rule in d.description
        if p.kind is float and p.high < float('inf'):
            (r,) = d.floating_point_range
            assert (r.from_value, r.to_value) == (p.low, p.high)
    assert isinstance(DEFAULTS, RollerSettings)

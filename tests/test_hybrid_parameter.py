"""contact_model (issue 31): the parameter of the run contract, refused in one line (exit 2)."""

import pytest

from twodisk_ros.run.parameters import DEFAULTS, parse_recorded

from roller_here import run_roller_main

#: ROS domain of the in-process start-ups here (refused before any sample: nothing is sent)
DOMAIN = 81


@pytest.mark.parametrize('params, says', [
    (['-p', 'contact_model:=mujoco'], 'contact_model must be one of rolling, hybrid'),
    (['-p', 'contact_model:=hybrid', '-p', 'mode:=kinematic'],
     'contact_model hybrid needs mode dynamic'),
])
def test_bad_contact_model_exits_2_in_one_line(tmp_path, params, says, monkeypatch, capfd):
    code, err = run_roller_main(('-p', 'realtime:=false', '-p', 'duration:=0.1', *params),
                                monkeypatch, capfd, domain=DOMAIN, cwd=tmp_path)
    lines = err.splitlines()
    assert code == 2, err
    assert len(lines) == 1 and 'Traceback' not in lines[0], err
    assert says in lines[0], lines[0]


def test_contact_model_default_and_recorded():
    assert DEFAULTS.contact_model == 'rolling'
    hybrid = DEFAULTS.with_values(contact_model='hybrid').checked()
    settings, problems = parse_recorded(hybrid.as_strings())
    assert problems == [] and settings.contact_model == 'hybrid'
    settings, problems = parse_recorded({k: v for k, v in hybrid.as_strings().items()
                                         if k != 'contact_model'})   # an older recording
    assert problems == [] and settings.contact_model == 'rolling'
    assert hybrid.with_values(drive='speed').checked().drive == 'speed'   # drives it takes
    with pytest.raises(ValueError, match='rolling_resistance 0'):
        hybrid.with_values(rolling_resistance=0.01).checked()
    with pytest.raises(ValueError, match='mode dynamic'):
        hybrid.with_values(mode='kinematic').checked()


@pytest.mark.parametrize('friction', [0.0, float('inf'), 20.0])
def test_hybrid_friction_outside_the_engines_range_is_refused(friction):
    """The engine's μ is ``friction`` (it was silently 0.5 for .inf and 10 for 20)."""
    with pytest.raises(ValueError, match=r'^friction must be in \(0, 10\] for contact_model '
                                         r'hybrid .*, got ' + repr(friction)):
        DEFAULTS.with_values(contact_model='hybrid', friction=friction).checked()
    DEFAULTS.with_values(friction=friction).checked()     # exact rolling takes them
    DEFAULTS.with_values(contact_model='hybrid', friction=10.0).checked()


def test_hybrid_friction_zero_exits_2_in_one_line(tmp_path, monkeypatch, capfd):
    code, err = run_roller_main(('-p', 'realtime:=false', '-p', 'duration:=0.1', '-p',
                                 'contact_model:=hybrid', '-p', 'friction:=0.0'),
                                monkeypatch, capfd, domain=DOMAIN, cwd=tmp_path)
    lines = err.splitlines()
    assert code == 2 and len(lines) == 1 and 'Traceback' not in lines[0], err
    assert 'friction must be in (0, 10] for contact_model hybrid' in lines[0], lines[0]

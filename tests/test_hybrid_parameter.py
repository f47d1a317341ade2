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
    with pytest.raises(ValueError, match='drive none'):
        hybrid.with_values(drive='speed').checked()

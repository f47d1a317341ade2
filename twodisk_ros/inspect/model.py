"""The body, mass model and mode that a recording's parameters describe."""

from dataclasses import dataclass
import math
import re

from ..physics.body import TwoDiskBody
from ..physics.dynamics import RollingDynamics
from ..physics.mass_models import MODELS, mass_properties
from ..physics.motion import MODES

__all__ = ['RecordedModel', 'build_model']

_NUMBER = re.compile(r'[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?')


@dataclass
class RecordedModel:
    """What the recorded parameters define: body, dynamics, mode, rates and tolerance."""

    body: TwoDiskBody
    dynamics: RollingDynamics
    mode: str
    omega0: float
    rate: float | None
    solver_tolerance: float


def _float_parameter(parameters, name, problems, required=True):
    text = parameters.get(name)
    if text is None:
        if required:
            problems.append(f'parameter {name} is missing')
        return None
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        problems.append(f'parameter {name} = {text!r} is not a finite number')
        return None
    return value


def build_model(parameters, problems):
    """The body, mass model and mode the recorded parameters describe, or None."""
    found = len(problems)
    values = {name: _float_parameter(parameters, name, problems)
              for name in ('a', 'b', 'delta', 'mass', 'gravity', 'omega0')}
    rate = _float_parameter(parameters, 'rate', problems, required=False)
    solver = _float_parameter(parameters, 'tolerance', problems, required=False)
    model_name = parameters.get('mass_model', 'laminae')
    if model_name not in MODELS:
        problems.append(f'parameter mass_model = {model_name!r} is not one of {MODELS}')
    mode = parameters.get('mode', 'dynamic')
    if mode not in MODES:
        problems.append(f'parameter mode = {mode!r} is not one of {MODES}')
    moments = None
    if model_name == 'custom':
        moments = [float(x) for x in _NUMBER.findall(parameters.get('principal_moments', ''))]
        if len(moments) != 3:
            problems.append('parameter principal_moments = '
                            f'{parameters.get("principal_moments")!r} is not 3 numbers')
    if len(problems) > found:
        return None
    try:
        body = TwoDiskBody(values['a'], values['b'], values['delta'])
        mass = mass_properties(model_name, body.a, body.b, body.delta, values['mass'],
                               principal_moments=moments)
        dynamics = RollingDynamics(body, mass, values['gravity'])
    except (ValueError, TypeError, RuntimeError) as error:
        problems.append(f'the recorded parameters define no body: {error}')
        return None
    if rate is not None and rate <= 0:
        problems.append(f'parameter rate = {rate!r} is not positive')
        rate = None
    solver = solver if solver is not None and 0 < solver < 1 else 1e-10
    return RecordedModel(body, dynamics, mode, values['omega0'], rate, solver)

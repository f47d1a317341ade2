"""The ROS ``ParameterDescriptor`` of each entry of the parameter contract (rclpy messages)."""

import math

from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor

__all__ = ['descriptor', 'ros_value']


def descriptor(p):
    """The ROS ParameterDescriptor of a contract entry."""
    unit = f' ({p.unit})' if p.unit else ''
    result = ParameterDescriptor(description=f'{p.description}{unit}; {p.rule}',
                                 read_only=p.read_only)
    if p.kind is int and p.choices is not None:
        low, high = min(p.choices), max(p.choices)
        step = (high - low) if len(p.choices) == 2 else 1
        result.integer_range = [IntegerRange(from_value=low, to_value=high, step=step)]
    elif p.kind is int:
        result.integer_range = [IntegerRange(from_value=int(p.low), to_value=int(p.high),
                                              step=1)]
    elif p.kind is float and math.isfinite(p.high):
        result.floating_point_range = [FloatingPointRange(from_value=float(p.low),
                                                          to_value=float(p.high))]
    if p.choices is not None and p.kind is str:
        result.additional_constraints = f'one of {", ".join(p.choices)}'
    return result


def ros_value(p):
    """The value rclpy declares for a contract entry's default (a list for tuples)."""
    return [float(x) for x in p.default] if p.kind is tuple else p.default

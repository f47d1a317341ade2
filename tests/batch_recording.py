"""A batch recording (``realtime:=false``) by the roller node, made in this process.

The same node class, parameters and recorder as ``python -m twodisk_ros.roller --ros-args
[--params-file FILE] -p realtime:=false -p record:=PATH ...``, without a new interpreter
(each one pays ~2 s of imports): for tests whose claim is about the recording, not about the
process (the process is covered by test_roller, test_node_arguments, test_node_reliability).
A context of its own in ``domain`` (loopback discovery: ROS_AUTOMATIC_DISCOVERY_RANGE is set
by the caller's module or environment), shut down afterwards.
"""

import os


def record(path, params_file=None, domain=None, **values):
    """Record the node's batch run with ``params_file`` then ``values`` (name -> value, the
    node's parameter types: float, int, str, bool) to ``path``; returns ``path``."""
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    import rclpy
    from rclpy.parameter import Parameter
    from rclpy.signals import SignalHandlerOptions
    from twodisk_ros.node.roller import Roller
    context = rclpy.Context()
    args = ['--ros-args', '--params-file', str(params_file)] if params_file else None
    domain = int(domain if domain is not None else os.environ.get('ROS_DOMAIN_ID', '0'))
    rclpy.init(args=args, context=context, domain_id=domain,
               signal_handler_options=SignalHandlerOptions.NO)   # pytest keeps its own
    try:
        overrides = [Parameter('realtime', value=False), Parameter('record', value=str(path))]
        overrides += [Parameter(name, value=value) for name, value in values.items()]
        node = Roller(context=context, parameter_overrides=overrides)
        try:
            node.run_batch()
        finally:
            node.close()
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    return path

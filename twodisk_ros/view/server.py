"""The Foxglove WebSocket server of ``twodisk-view`` and its channels (``foxglove-sdk``).

The server speaks the WebSocket subprotocol :data:`SUBPROTOCOL` (``foxglove.sdk.v1``, the
only one foxglove-sdk 0.30 serves; a client asking for the older ``foxglove.websocket.v1``
is refused with HTTP 400). It advertises the capabilities ``time`` (the clock follows the
samples' stamps) and ``parameters`` (the node's parameters, read-only), and the channels of
:data:`TOPICS`, every message logged with its sample's stamp as log time. No rclpy here.

Static content (the body's mesh and rims, the parameters) is logged again whenever a client
subscribes to its channel, so a client that connects at any time sees it at once.
"""

import math
import threading

import foxglove
from foxglove import Capability, Parameter, ParameterType
from foxglove.channels import FrameTransformsChannel, SceneUpdateChannel
from foxglove.websocket import ServerListener

from ..run.parameters import PARAMETERS

__all__ = ['SUBPROTOCOL', 'TOPICS', 'ServeError', 'ViewServer', 'parameter_values']

#: The WebSocket subprotocol the server speaks.
SUBPROTOCOL = 'foxglove.sdk.v1'
#: topic: (schema, what it carries)
TOPICS = {
    '/tf': ('foxglove.FrameTransforms', 'world → body frame at every sample, body → disk '
            'frames'),
    '/body': ('foxglove.SceneUpdate', "the body's mesh (body frame) and the two rims (disk "
              'frames), frame-locked'),
    '/contact_segment': ('foxglove.SceneUpdate', 'the contact segment AB (world frame)'),
    '/contact_forces': ('foxglove.SceneUpdate', "the ground's forces at A and B as arrows "
                        '(length |F| / (M g) × body size)'),
    '/traces': ('foxglove.SceneUpdate', 'the traces of A, B and G: the last path_length '
                'samples'),
    '/parameters': ('JSON', 'the parameters of the run and where it comes from'),
}
#: JSON schema of the /parameters channel.
PARAMETERS_SCHEMA = {
    'type': 'object', 'title': 'twodisk_ros parameters',
    'properties': {
        'parameters': {'type': 'object', 'description': "the roller node's parameters "
                       '(SI units; non-finite numbers as strings)'},
        'run': {'type': 'object', 'description': 'source, frames, rate, speed, start stamp'},
    },
}


class ServeError(RuntimeError):
    """The server cannot start (the port is taken, the host cannot be bound); one line."""


def _json_number(value):
    return value if math.isfinite(value) else str(value)


def parameter_values(settings):
    """{name: value} of every parameter of the node's contract (JSON-ready)."""
    values = {}
    for p in PARAMETERS:
        value = getattr(settings, p.name)
        if isinstance(value, tuple):
            value = [_json_number(float(x)) for x in value]
        elif isinstance(value, float):
            value = _json_number(value)
        values[p.name] = value
    return values


def _foxglove_parameter(name, value):
    if isinstance(value, float):
        return Parameter(name, value=value, type=ParameterType.Float64)
    if isinstance(value, list) and all(isinstance(x, float) for x in value):
        return Parameter(name, value=value, type=ParameterType.Float64Array)
    if isinstance(value, list):
        return Parameter(name, value=[str(x) for x in value])
    return Parameter(name, value=value)


class _Listener(ServerListener):
    """Marks a channel's static content to be logged again when a client subscribes; answers
    the parameters (read-only: a set request gets the current values back)."""

    def __init__(self, parameters):
        self.parameters = parameters
        self.lock = threading.Lock()
        self.subscribed = set()

    def on_subscribe(self, client, channel):
        with self.lock:
            self.subscribed.add(channel.topic)

    def take_subscribed(self):
        with self.lock:
            topics, self.subscribed = self.subscribed, set()
        return topics

    def on_get_parameters(self, client, param_names, request_id=None):
        return [_foxglove_parameter(name, value) for name, value in self.parameters.items()
                if not param_names or name in param_names]

    def on_set_parameters(self, client, parameters, request_id=None):
        return self.on_get_parameters(client, [p.name for p in parameters], request_id)


class ViewServer:
    """A running server with the channels of :data:`TOPICS` on a context of its own.

    Parameters
    ----------
    host : str
        The address to bind (the command allows loopback only unless told otherwise).
    port : int
        The port; 0 picks a free one (:attr:`port` tells which).
    parameters : dict
        :func:`parameter_values` of the run (shown by the ``parameters`` capability).

    Raises
    ------
    ServeError
        If the server cannot bind ``host:port``.
    """

    def __init__(self, host, port, parameters):
        self.context = foxglove.Context()
        self.listener = _Listener(parameters)
        try:
            self.server = foxglove.start_server(
                name='twodisk-view', host=host, port=port, context=self.context,
                capabilities=[Capability.Time, Capability.Parameters],
                server_listener=self.listener)
        except RuntimeError as error:
            reason = str(error).removeprefix('FoxgloveError: ')
            raise ServeError(f'cannot serve on {host}:{port}: {reason}') from None
        self.port = self.server.port
        self.tf = FrameTransformsChannel('/tf', context=self.context)
        self.scenes = {topic: SceneUpdateChannel(topic, context=self.context)
                       for topic in ('/body', '/contact_segment', '/contact_forces', '/traces')}
        self.parameters = foxglove.Channel('/parameters', schema=PARAMETERS_SCHEMA,
                                           context=self.context)

    def newly_subscribed(self):
        """Topics a client subscribed to since the last call."""
        return self.listener.take_subscribed()

    def log_transforms(self, message, stamp_ns):
        self.tf.log(message, log_time=int(stamp_ns))

    def log_scene(self, topic, message, stamp_ns):
        self.scenes[topic].log(message, log_time=int(stamp_ns))

    def log_parameters(self, document, stamp_ns):
        self.parameters.log(document, log_time=int(stamp_ns))

    def broadcast_time(self, stamp_ns):
        """Tell the clients the current time (ns): the stamp of the sample just shown."""
        self.server.broadcast_time(int(stamp_ns))

    def stop(self):
        """Stop serving and free the port (the clients see the connection close)."""
        self.server.stop()
